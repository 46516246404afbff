#include "karst/scene/geometry.hpp"

#include "karst/core/parallel.hpp"

#include <algorithm>
#include <cmath>

namespace karst {

namespace {

Real box_distance(const Vec3& x, const Vec3& lo, const Vec3& hi) {
    const Vec3 c = 0.5 * (lo + hi), half = 0.5 * (hi - lo);
    const Vec3 q = (x - c).cwiseAbs() - half;
    return q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), Real(0));
}

Real cylinder_distance(const Vec3& x, const Vec3& base, const Vec3& top, Real r) {
    const Vec3 axis = top - base;
    const Real len = axis.norm();
    const Vec3 dir = axis / len;
    const Real along = (x - base).dot(dir);
    const Real radial = ((x - base) - along * dir).norm();
    // Distance in the (radial, axial) half-plane to the rectangle [0, r] x [0, len].
    const Real dr = radial - r;
    const Real da = std::max(-along, along - len);
    const Real outside = std::hypot(std::max(dr, Real(0)), std::max(da, Real(0)));
    return outside + std::min(std::max(dr, da), Real(0));
}

}  // namespace

Real Shape::signed_distance(const Vec3& x) const {
    switch (kind) {
        case Kind::Box:
            return box_distance(x, a, b);
        case Kind::Sphere:
            return (x - a).norm() - radius;
        case Kind::Cylinder:
            return cylinder_distance(x, a, b, radius);
        case Kind::Union: {
            Real d = std::numeric_limits<Real>::infinity();
            for (const Shape& c : children) d = std::min(d, c.signed_distance(x));
            return d;
        }
        case Kind::Difference: {
            Real d = children.front().signed_distance(x);
            for (size_t i = 1; i < children.size(); ++i)
                d = std::max(d, -children[i].signed_distance(x));
            return d;
        }
    }
    return 0;
}

Aabb Shape::bounds() const {
    Aabb box;
    switch (kind) {
        case Kind::Box:
            box = {a.cwiseMin(b), a.cwiseMax(b)};
            break;
        case Kind::Sphere:
            box = {a.array() - radius, a.array() + radius};
            break;
        case Kind::Cylinder:
            box = {a.cwiseMin(b).array() - radius, a.cwiseMax(b).array() + radius};
            break;
        case Kind::Union:
            for (const Shape& c : children) box.extend(c.bounds());
            break;
        case Kind::Difference:
            box = children.front().bounds();
            break;
    }
    return box;
}

namespace {

/// Lattice index range covering `box` grown by `reach`.
void lattice_range(const Aabb& box, Real reach, Real dx, LatticeIndex& lo, LatticeIndex& hi) {
    for (int d = 0; d < 3; ++d) {
        lo[d] = static_cast<std::int64_t>(std::floor((box.min[d] - reach) / dx - 0.5));
        hi[d] = static_cast<std::int64_t>(std::ceil((box.max[d] + reach) / dx - 0.5));
    }
}

/// Lattice points of [a, b] in the band (lo, hi] of `shape`, appended in (k, j, i) order.
void sample_range(const Shape& shape, Real dx, Real lo, Real hi, const LatticeIndex& a,
                  const LatticeIndex& b, std::vector<LatticeIndex>& out) {
    for (std::int64_t k = a[2]; k <= b[2]; ++k)
        for (std::int64_t j = a[1]; j <= b[1]; ++j)
            for (std::int64_t i = a[0]; i <= b[0]; ++i) {
                const LatticeIndex idx{i, j, k};
                const Real d = shape.signed_distance(lattice_point(idx, dx));
                if (d > lo && d <= hi) out.push_back(idx);
            }
}

double range_points(const LatticeIndex& a, const LatticeIndex& b) {
    double n = 1;
    for (int d = 0; d < 3; ++d) n *= double(b[d] - a[d] + 1);
    return n;
}

/// Boxes that hold every point of `shape`: a union's parts' boxes, a difference's first shape's
/// (the shapes it subtracts only remove points), and any other shape's own box.
void part_boxes(const Shape& shape, std::vector<Aabb>& boxes) {
    if (shape.kind == Shape::Kind::Union)
        for (const Shape& c : shape.children) part_boxes(c, boxes);
    else if (shape.kind == Shape::Kind::Difference)
        part_boxes(shape.children.front(), boxes);
    else
        boxes.push_back(shape.bounds());
}

}  // namespace

std::vector<LatticeIndex> sample_lattice(const Shape& shape, Real dx, Real lo, Real hi) {
    const Real reach = std::isfinite(hi) ? std::max(hi, Real(0)) : 0;
    LatticeIndex a, b;
    lattice_range(shape.bounds(), reach, dx, a, b);
    std::vector<LatticeIndex> out;
    // Parts that lie far apart (a union's, also inside a difference): visit only each part's
    // box, grown by the band's reach (every point of the band lies within reach of the shape's
    // surface, so of some part's box), then drop the points two boxes share. Sorted in (k, j, i)
    // order, the result is that of the single box.
    std::vector<Aabb> boxes;
    part_boxes(shape, boxes);
    if (boxes.size() > 1) {
        std::vector<std::pair<LatticeIndex, LatticeIndex>> parts;
        double part_points = 0;
        for (const Aabb& box : boxes) {
            LatticeIndex ca, cb;
            lattice_range(box, reach, dx, ca, cb);
            parts.push_back({ca, cb});
            part_points += range_points(ca, cb);
        }
        if (part_points < 0.5 * range_points(a, b)) {
            for (const auto& [ca, cb] : parts) sample_range(shape, dx, lo, hi, ca, cb, out);
            const auto zyx = [](const LatticeIndex& p) {
                return std::array<std::int64_t, 3>{p[2], p[1], p[0]};
            };
            std::sort(out.begin(), out.end(), [&](const LatticeIndex& p, const LatticeIndex& q) {
                return zyx(p) < zyx(q);
            });
            out.erase(std::unique(out.begin(), out.end()), out.end());
            return out;
        }
    }
    sample_range(shape, dx, lo, hi, a, b, out);
    return out;
}

namespace {

/// Lattice points in the band on a coarse 128^3 grid over the shape's box: every coarse cell
/// that comes within its half-diagonal of the band counts in full (`upper`), or only cells
/// wholly inside it do (!upper).
double coarse_lattice_count(const Shape& shape, Real reach, Real lo, Real hi, double lattice_points,
                            bool upper) {
    constexpr int n = 128;
    const Aabb box = shape.bounds().padded(reach);
    const Vec3 cell = (box.max - box.min) / n;
    const Real half_diag = 0.5 * cell.norm();
    const double hits = deterministic_sum(Index(n), 0.0, [&](Index k) {
        double c = 0;
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i) {
                const Vec3 x = box.min + cell.cwiseProduct(Vec3(i + 0.5, j + 0.5, k + 0.5));
                const Real d = shape.signed_distance(x);
                c += upper ? (d + half_diag > lo && d - half_diag <= hi)
                           : (d - half_diag > lo && d + half_diag <= hi);
            }
        return c;
    });
    return hits * lattice_points / (double(n) * n * n);
}

}  // namespace

double estimate_lattice_count(const Shape& shape, Real dx, Real lo, Real hi, double enough) {
    const Real reach = std::isfinite(hi) ? std::max(hi, Real(0)) : 0;
    LatticeIndex a, b;
    lattice_range(shape.bounds(), reach, dx, a, b);
    const double lattice_points = range_points(a, b);
    if (lattice_points > 2e8)
        return coarse_lattice_count(shape, reach, lo, hi, lattice_points, true);
    // A large box whose coarse lower bound already exceeds `enough` needs no exact count.
    if (lattice_points > 1e7) {
        const double at_least = coarse_lattice_count(shape, reach, lo, hi, lattice_points, false);
        if (at_least > enough) return at_least;
    }
    // Exact count, streaming (no storage), one z-slice per task.
    const Index slices = b[2] - a[2] + 1;
    return deterministic_sum(slices, 0.0, [&](Index s) {
        double n = 0;
        for (std::int64_t j = a[1]; j <= b[1]; ++j)
            for (std::int64_t i = a[0]; i <= b[0]; ++i) {
                const Real d = shape.signed_distance(lattice_point({i, j, a[2] + s}, dx));
                n += (d > lo && d <= hi);
            }
        return n;
    });
}

}  // namespace karst
