#pragma once
// Constructive solid geometry shared by every kind of object (fluid blocks, walls, and later
// porous solids): primitives and set operations, evaluated through a signed distance
// (negative inside), and sampled on the scene's one particle lattice (i + 1/2) dx.
#include "karst/core/types.hpp"

#include <array>
#include <limits>
#include <vector>

namespace karst {

struct Aabb {
    Vec3 min = Vec3::Constant(std::numeric_limits<Real>::infinity());
    Vec3 max = Vec3::Constant(-std::numeric_limits<Real>::infinity());
    bool empty() const { return (max.array() < min.array()).any(); }
    void extend(const Vec3& p) { min = min.cwiseMin(p), max = max.cwiseMax(p); }
    void extend(const Aabb& b) { min = min.cwiseMin(b.min), max = max.cwiseMax(b.max); }
    Aabb padded(Real d) const { return {min.array() - d, max.array() + d}; }
    bool contains(const Vec3& p) const {
        return (p.array() >= min.array()).all() && (p.array() <= max.array()).all();
    }
};

struct Shape {
    enum class Kind { Box, Sphere, Cylinder, Union, Difference };
    Kind kind = Kind::Box;
    Vec3 a = Vec3::Zero();        ///< box min, sphere centre, cylinder base centre (m)
    Vec3 b = Vec3::Zero();        ///< box max, cylinder top centre (m)
    Real radius = 0;              ///< sphere and cylinder radius (m)
    std::vector<Shape> children;  ///< union members; difference: first minus the rest

    /// Signed distance (m), negative inside. Exact for primitives; union/difference use min/max,
    /// which is exact in sign and a bound on the distance (enough for sampling skins).
    Real signed_distance(const Vec3& x) const;
    /// Bounds of the inside (a difference keeps the bounds of its first shape).
    Aabb bounds() const;
};

/// Lattice index of a sample point: x = (i + 1/2) dx per axis.
using LatticeIndex = std::array<std::int64_t, 3>;

inline Vec3 lattice_point(const LatticeIndex& i, Real dx) {
    return {(Real(i[0]) + 0.5) * dx, (Real(i[1]) + 0.5) * dx, (Real(i[2]) + 0.5) * dx};
}

/// Lattice points with lo < signed_distance <= hi inside `box` (clipped to the shape's
/// reach), in lexicographic (z, y, x) order. (-inf, 0] gives the solid; (0, t] a skin of
/// thickness t outside; (-t, 0] a skin inside.
std::vector<LatticeIndex> sample_lattice(const Shape& shape, Real dx, Real lo, Real hi);

/// The number of lattice points sample_lattice would return, computed without storing them
/// (used to refuse scenes with too many particles): exact up to 2e8 points in the shape's box, an
/// upper estimate beyond; a lower bound above `enough` when that settles it without counting.
double estimate_lattice_count(const Shape& shape, Real dx, Real lo, Real hi,
                              double enough = std::numeric_limits<double>::infinity());

}  // namespace karst
