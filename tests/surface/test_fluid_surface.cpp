// The fluid surface (docs/method.md §7, issue 14): a ball of particles meshes to a sphere's area
// and volume, a resting tank to its water level, every mesh is closed, manifold and free of
// self-intersections, the same bits on 1 and 2 threads, and the anisotropic kernels keep a sheet
// one particle thick whole where the isotropic ones bead it.
#include "support/surfaces.hpp"

#include "karst/core/disjoint_sets.hpp"
#include "karst/core/parallel.hpp"
#include "karst/surface/fluid_surface.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

namespace karst {
namespace {

constexpr Real dx = 0.01, h = 2 * dx;

struct Particles {
    std::vector<Vec3> x;
    std::vector<Real> volume;
    void add(const Vec3& p) { x.push_back(p), volume.push_back(dx * dx * dx); }
};

/// Lattice sites (i + 1/2) dx inside |x| < radius.
Particles ball(Real radius) {
    Particles p;
    const int n = int(std::ceil(radius / dx));
    for (int i = -n; i < n; ++i)
        for (int j = -n; j < n; ++j)
            for (int k = -n; k < n; ++k) {
                const Vec3 x = dx * Vec3(i + 0.5, j + 0.5, k + 0.5);
                if (x.norm() < radius) p.add(x);
            }
    return p;
}

SurfaceMesh mesh_of(const Particles& p, bool anisotropic = false) {
    FluidSurfaceOptions options;
    options.voxel = 0.5 * dx;
    options.anisotropic = anisotropic;
    return colour_field_surface(p.x, p.volume, h, options);
}

Index components(const SurfaceMesh& mesh) {
    DisjointSets sets(mesh.vertex_count());
    for (const auto& t : mesh.triangles) sets.join(t[0], t[1]), sets.join(t[1], t[2]);
    Index n = 0;
    for (Index v = 0; v < mesh.vertex_count(); ++v) n += sets.find(v) == v;
    return n;
}

TEST(FluidSurface, ABallOfRadiusTenSpacingsMeshesToItsSphere) {
    const Real radius = 10 * dx;
    const Particles p = ball(radius);
    const SurfaceMesh mesh = mesh_of(p);
    const SurfaceMeasures m = surface_measures(mesh);
    const Real area = 4 * std::numbers::pi * radius * radius,
               volume = 4 * std::numbers::pi * radius * radius * radius / 3;
    std::printf("sphere area %.4f volume %.4f\n", m.area / area, m.volume / volume);
    EXPECT_NEAR(m.area / area, 1, 0.03);
    EXPECT_NEAR(m.volume / volume, 1, 0.03);
    EXPECT_EQ(components(mesh), 1);
    test::expect_clean(mesh);
}

TEST(FluidSurface, ARestingTanksSurfaceLiesAtTheWaterLevel) {
    // Water 0.2 x 0.2 x 0.1 m: lattice sites (i + 1/2) dx below the level.
    const Real level = 0.1;
    Particles p;
    for (int i = 0; i < 20; ++i)
        for (int j = 0; j < 20; ++j)
            for (int k = 0; k < 10; ++k) p.add(dx * Vec3(i + 0.5, j + 0.5, k + 0.5));
    const SurfaceMesh mesh = mesh_of(p);
    const std::vector<Vec3>& x = mesh.vertices.x;
    Real worst = 0;
    Index top = 0;
    for (const Vec3& v : x)
        if (v.z() > 0.05 && v.x() > 0.05 && v.x() < 0.15 && v.y() > 0.05 && v.y() < 0.15)
            worst = std::max(worst, std::abs(v.z() - level)), ++top;
    EXPECT_GT(top, 100);
    std::printf("tank worst %.4f dx\n", worst / dx);
    EXPECT_LT(worst, dx / 4);
    test::expect_clean(mesh);
}

/// A ball of water with its particles jittered by 0.3 dx and a splash of loose drops.
Particles splash() {
    Particles p = ball(8 * dx);
    std::mt19937 rng(3);
    std::uniform_real_distribution<Real> jitter(-0.3 * dx, 0.3 * dx), drop(-0.15, 0.15);
    for (Vec3& x : p.x) x += Vec3(jitter(rng), jitter(rng), jitter(rng));
    for (int d = 0; d < 200; ++d) p.add(Vec3(drop(rng), drop(rng), 0.1 + drop(rng)));
    return p;
}

TEST(FluidSurface, AJitteredSplashIsClosedManifoldAndTheSameOnOneAndTwoThreads) {
    for (bool anisotropic : {false, true}) {
        SCOPED_TRACE(anisotropic ? "anisotropic" : "isotropic");
        const Particles p = splash();
        SurfaceMesh one, two;
        {
            ThreadLimit limit(1);
            one = mesh_of(p, anisotropic);
        }
        {
            ThreadLimit limit(2);
            two = mesh_of(p, anisotropic);
        }
        ASSERT_GT(one.triangle_count(), 1000);
        EXPECT_EQ(one.triangles, two.triangles);
        EXPECT_EQ(one.vertices.x, two.vertices.x);
        test::expect_clean(one);
    }
}

TEST(FluidSurface, AnisotropicKernelsKeepAThinSheetWholeWhereIsotropicOnesBeadIt) {
    // One particle thick, 1.3 dx apart in its plane (a stretched sheet), tilted.
    Particles p;
    const Vec3 a = Vec3(1, 0, 0.3).normalized(), b = Vec3(0, 1, 0);
    for (int i = 0; i < 24; ++i)
        for (int j = 0; j < 24; ++j) p.add(1.3 * dx * (i * a + j * b));
    const SurfaceMesh isotropic = mesh_of(p, false), anisotropic = mesh_of(p, true);
    // Isotropic kernels leave beads or nothing: a colour below 1/2 between the particles.
    EXPECT_NE(components(isotropic), 1);
    EXPECT_EQ(components(anisotropic), 1);
    test::expect_clean(anisotropic);
    // The anisotropic sheet keeps its extent: its two sides span the particles' plane.
    const Real side = 23 * 1.3 * dx;
    const Real area = surface_measures(anisotropic).area;
    EXPECT_GT(area, 1.6 * side * side);
    EXPECT_LT(area, 2.6 * side * side);
    EXPECT_LT(surface_measures(isotropic).area, 0.5 * area);
}

TEST(FluidSurface, ShepardInterpolationReproducesALinearFieldInside) {
    const Particles p = ball(6 * dx);
    std::vector<Real> field(p.x.size());
    for (size_t i = 0; i < p.x.size(); ++i) field[i] = 2 + 3 * p.x[i].x();
    const std::vector<Vec3> at{Vec3::Zero(), Vec3(0.01, 0.005, 0), Vec3(1, 1, 1)};
    const auto values = shepard_interpolate(at, p.x, p.volume, h, {field});
    EXPECT_NEAR(values[0][0], 2, 1e-9);  // symmetric around the centre
    EXPECT_NEAR(values[0][1], 2.03, 1e-3);
    EXPECT_EQ(values[0][2], 0);  // no particle within reach
}

}  // namespace
}  // namespace karst
