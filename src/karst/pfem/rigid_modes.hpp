#pragma once
// Whether a body's displacement constraints hold all six rigid-body modes (docs/method.md §5.3): a
// piece held at one node, or along one line, can still turn, and its elasticity matrix is then
// singular. Fracture uses it to tell which pieces stay anchored; the Biot setup to know when the
// rigid-mode spring is needed.
#include "karst/core/types.hpp"

#include <Eigen/Eigenvalues>

#include <cstdint>
#include <span>

namespace karst {

/// True when the constraints `fixed[a]` (FixedAxes bits) at the nodes `x` admit no rigid motion
/// t + theta x (x - c): the 6 x 6 sum of the constraint rows, made dimensionless by the nodes'
/// extent, has no eigenvalue below 1e-2 of its largest. [D] A body held along a strip a spacing
/// or two wide (eigenvalue ~ (dx / extent)^2) is a hinge: its elasticity is invertible, but its
/// small-strain solution under a load swings kilometres.
inline bool holds_rigid_modes(std::span<const Vec3> x, std::span<const std::uint8_t> fixed) {
    if (x.empty()) return false;
    Vec3 centre = Vec3::Zero(), lo = x[0], hi = x[0];
    for (const Vec3& p : x) centre += p, lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
    centre /= Real(x.size());
    const Real extent = std::max((hi - lo).norm(), Real(1e-30));
    Eigen::Matrix<Real, 6, 6> A = Eigen::Matrix<Real, 6, 6>::Zero();
    for (size_t a = 0; a < x.size(); ++a)
        for (int k = 0; k < 3; ++k) {
            if (!(fixed[a] & (1u << k))) continue;
            Eigen::Matrix<Real, 6, 1> row;
            row << Vec3::Unit(k), ((x[a] - centre) / extent).cross(Vec3::Unit(k));
            A += row * row.transpose();
        }
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<Real, 6, 6>> eigen(A);
    const auto& values = eigen.eigenvalues();  // ascending
    return values[5] > 0 && values[0] > 1e-2 * values[5];
}

}  // namespace karst
