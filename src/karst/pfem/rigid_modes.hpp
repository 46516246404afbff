#pragma once
// Whether a body's displacement constraints hold all six rigid-body modes (docs/method.md §5.3): a
// piece held at one node, or along one line, can still turn, and its elasticity matrix is then
// singular. Fracture uses it to tell which pieces stay anchored; the Biot setup to know when the
// rigid-mode spring is needed and which rigid motions no constraint touches at all.
#include "karst/core/types.hpp"

#include <Eigen/Eigenvalues>

#include <cstdint>
#include <span>

namespace karst {

/// The rigid motions t + theta x (x - c) of nodes `x`, with c their centre and lengths made
/// dimensionless by their extent.
struct RigidFrame {
    Vec3 centre = Vec3::Zero();
    Real extent = 1;
    explicit RigidFrame(std::span<const Vec3> x) {
        if (x.empty()) return;
        Vec3 lo = x[0], hi = x[0];
        for (const Vec3& p : x) centre += p, lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
        centre /= Real(x.size());
        extent = std::max((hi - lo).norm(), Real(1e-30));
    }
    /// Component k of the six modes (t, theta) at x: e_k . (t + theta x (x - c) / extent).
    Eigen::Matrix<Real, 1, 6> row(const Vec3& x, int k) const {
        Eigen::Matrix<Real, 1, 6> r;
        r << Vec3::Unit(k).transpose(), ((x - centre) / extent).cross(Vec3::Unit(k)).transpose();
        return r;
    }
    /// Sum of row^T row over the fixed components `fixed[a]` (FixedAxes bits) at the nodes x.
    Eigen::Matrix<Real, 6, 6> constraint_matrix(std::span<const Vec3> x,
                                                std::span<const std::uint8_t> fixed) const {
        Eigen::Matrix<Real, 6, 6> A = Eigen::Matrix<Real, 6, 6>::Zero();
        for (size_t a = 0; a < x.size(); ++a)
            for (int k = 0; k < 3; ++k)
                if (fixed[a] & (1u << k)) {
                    const auto r = row(x[a], k);
                    A += r.transpose() * r;
                }
        return A;
    }
};

/// True when the constraints `fixed[a]` (FixedAxes bits) at the nodes `x` admit no rigid motion:
/// the constraint matrix has no eigenvalue below 1e-2 of its largest. [D] A body held along a
/// strip a spacing or two wide (eigenvalue ~ (dx / extent)^2) is a hinge: its elasticity is
/// invertible, but its small-strain solution under a load swings kilometres.
inline bool holds_rigid_modes(std::span<const Vec3> x, std::span<const std::uint8_t> fixed) {
    if (x.empty()) return false;
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<Real, 6, 6>> eigen(
        RigidFrame(x).constraint_matrix(x, fixed));
    const auto& values = eigen.eigenvalues();  // ascending
    return values[5] > 0 && values[0] > 1e-2 * values[5];
}

/// The rigid motions (t, theta) in RigidFrame(x)'s units that no fixed component touches at all,
/// as the columns of a 6 x k orthonormal basis: all six for a piece without anchors, the three
/// turns about a single fixed node, none for a held piece.
inline Eigen::Matrix<Real, 6, Eigen::Dynamic> free_rigid_modes(
    std::span<const Vec3> x, std::span<const std::uint8_t> fixed) {
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<Real, 6, 6>> eigen(
        RigidFrame(x).constraint_matrix(x, fixed));
    const auto& values = eigen.eigenvalues();  // ascending
    int k = 0;
    while (k < 6 && values[k] <= 1e-12 * std::max(values[5], Real(1))) ++k;
    return eigen.eigenvectors().leftCols(k);
}

}  // namespace karst
