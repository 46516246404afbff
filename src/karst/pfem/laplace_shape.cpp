#include "karst/pfem/laplace_shape.hpp"

#include "karst/core/check.hpp"

#include <Eigen/Geometry>

namespace karst {

namespace {

/// Area of the Voronoi facet between x and nodes[i], clipped from a square of half-width
/// `extent`; returns a negative value when the facet reaches the square (too small a start).
Real clipped_facet_area(std::span<const Vec3> nodes, const Vec3& x, size_t i, Real extent) {
    const Vec3 normal = (nodes[i] - x).normalized();
    const Vec3 centre = 0.5 * (x + nodes[i]);
    // A square on the bisector plane, large enough to hold the bounded facet.
    const Vec3 u = normal.unitOrthogonal(), v = normal.cross(u);
    std::vector<Vec3> polygon{centre + extent * (u + v), centre + extent * (-u + v),
                              centre + extent * (-u - v), centre + extent * (u - v)};
    std::vector<Vec3> clipped;
    for (size_t j = 0; j < nodes.size() && !polygon.empty(); ++j) {
        if (j == i) continue;
        // Keep the side nearer x than nodes[j]: (y - m_j) . d_j <= 0.
        const Vec3 d = nodes[j] - x, m = 0.5 * (x + nodes[j]);
        clipped.clear();
        for (size_t k = 0; k < polygon.size(); ++k) {
            const Vec3 &a = polygon[k], &b = polygon[(k + 1) % polygon.size()];
            const Real fa = (a - m).dot(d), fb = (b - m).dot(d);
            if (fa <= 0) clipped.push_back(a);
            if ((fa < 0) != (fb < 0) && fa != fb) clipped.push_back(a + (fa / (fa - fb)) * (b - a));
        }
        polygon.swap(clipped);
    }
    if (polygon.size() < 3) return 0;
    for (const Vec3& p : polygon)
        if (std::max(std::abs((p - centre).dot(u)), std::abs((p - centre).dot(v))) > 0.999 * extent)
            return -1;
    Vec3 twice_area = Vec3::Zero();
    for (size_t k = 1; k + 1 < polygon.size(); ++k)
        twice_area += (polygon[k] - polygon[0]).cross(polygon[k + 1] - polygon[0]);
    return 0.5 * twice_area.norm();
}

/// The facet area, growing the starting square until the facet fits: near a face of a tet the
/// Voronoi cell of x reaches far outside the tet.
Real facet_area(std::span<const Vec3> nodes, const Vec3& x, size_t i, Real extent) {
    for (int attempt = 0; attempt < 40; ++attempt, extent *= 4) {
        const Real area = clipped_facet_area(nodes, x, i, extent);
        if (area >= 0) return area;
    }
    KARST_CHECK(false);  // an unbounded facet: x is outside the nodes' hull
    return 0;
}

}  // namespace

void laplace_shape(std::span<const Vec3> nodes, const Vec3& x, std::span<Real> N) {
    KARST_CHECK(N.size() == nodes.size() && nodes.size() >= 4);
    Real extent = 0;
    for (const Vec3& n : nodes) extent = std::max(extent, (n - x).norm());
    extent *= 4;
    Real sum = 0;
    for (size_t i = 0; i < nodes.size(); ++i) {
        const Real h = (nodes[i] - x).norm();
        KARST_CHECK(h > 0);  // x on a node: the caller evaluates at interior quadrature points
        N[i] = facet_area(nodes, x, i, extent) / h;
        sum += N[i];
    }
    KARST_CHECK(sum > 0);
    for (Real& n : N) n /= sum;
}

void laplace_shape_and_gradient(std::span<const Vec3> nodes, const Vec3& x, Real step,
                                std::span<Real> N, std::span<Vec3> gradient) {
    laplace_shape(nodes, x, N);
    std::vector<Real> plus(nodes.size()), minus(nodes.size());
    for (int c = 0; c < 3; ++c) {
        Vec3 dx = Vec3::Zero();
        dx[c] = step;
        laplace_shape(nodes, x + dx, plus);
        laplace_shape(nodes, x - dx, minus);
        for (size_t i = 0; i < nodes.size(); ++i)
            gradient[i][c] = (plus[i] - minus[i]) / (2 * step);
    }
}

}  // namespace karst
