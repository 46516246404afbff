// The porous surface (docs/method.md §7, issue 14): each fragment's alpha-shape boundary on its
// particles, closed, manifold and free of self-intersections even where two pieces touch along
// an edge, darker where wet (M29), following its particles and rebuilt when members go.
#include "support/simulate.hpp"
#include "support/surfaces.hpp"

#include "karst/surface/porous_surface.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>

namespace karst {
namespace {

/// Free porous boxes (spacing 0.02 m) of the given corners, no fluid.
std::string boxes(const std::vector<std::pair<Vec3, Vec3>>& corners) {
    std::string solids;
    for (const auto& [lo, hi] : corners)
        solids += fmt::format(
            R"({}{{ "shape": {{ "type": "box", "min": [{}, {}, {}], "max": [{}, {}, {}] }},
                "anchored": false, "material": {{ "porosity": 0.3, "permeability": 1e-12 }} }})",
            solids.empty() ? "" : ",", lo.x(), lo.y(), lo.z(), hi.x(), hi.y(), hi.z());
    return fmt::format(
        R"({{ "name": "blocks", "particle_spacing": 0.02, "time": {{ "fixed_dt": 0.002 }},
        "walls": [ {{ "kind": "container", "shape": {{ "type": "box", "min": [-1, -1, -1], "max": [1, 1, 1] }} }} ],
        "porous_solids": [ {} ] }})",
        solids);
}

TEST(PorousSurface, ABlocksSurfaceIsItsAlphaShapeAndDarkerWhereWet) {
    test::Simulation sim(boxes({{Vec3(0, 0, 0), Vec3(0.2, 0.2, 0.1)}}));
    const PorousParticles& p = sim.state.porous.particles;
    std::vector<Real> saturation(p.size());
    for (Index i = 0; i < p.size(); ++i) saturation[i] = p.x[i].x() < 0.1 ? 0 : 1;
    PorousSurfaces surfaces;
    const SurfaceMesh mesh = surfaces.build(sim.model, p, saturation);
    test::expect_clean(mesh);
    // The lattice's hull: sites from dx/2 to the far side less dx/2.
    const SurfaceMeasures m = surface_measures(mesh);
    EXPECT_NEAR(m.volume, 0.18 * 0.18 * 0.08, 1e-9);
    // Wet is darker (M29): the wet half's vertices have the lower lightness.
    Real dry = 0, wet = 0;
    for (Index v = 0; v < mesh.vertex_count(); ++v) {
        const Real sum = mesh.colour[v][0] + mesh.colour[v][1] + mesh.colour[v][2];
        (mesh.vertices.x[v].x() < 0.1 ? dry : wet) = sum;
    }
    EXPECT_LT(wet, 0.5 * dry);
}

TEST(PorousSurface, TwoTetsSharingOnlyAnEdgeAreSplitIntoTwoClosedManifoldPieces) {
    // Tets (0 1 2 3) and (0 1 4 5) share the edge 0-1: four faces on it.
    std::vector<Vec3> x{{0, 0, 0}, {0, 0, 1}, {1, 0, 0}, {0.5, 1, 0}, {-1, 0, 0}, {-0.5, -1, 0}};
    std::vector<std::array<Index, 3>> triangles;
    for (const std::array<Index, 4>& t : {std::array<Index, 4>{0, 1, 2, 3}, {0, 1, 4, 5}}) {
        // Outward faces of a tet (a b c d) with (b - a, c - a, d - a) right-handed.
        const Real volume = (x[t[1]] - x[t[0]]).dot((x[t[2]] - x[t[0]]).cross(x[t[3]] - x[t[0]]));
        const std::array<Index, 4> v =
            volume > 0 ? t : std::array<Index, 4>{t[0], t[2], t[1], t[3]};
        for (const auto& f : {std::array<int, 3>{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}})
            triangles.push_back({v[f[0]], v[f[1]], v[f[2]]});
    }
    SurfaceMesh soup;
    soup.vertices.x = x, soup.triangles = triangles;
    EXPECT_FALSE(check_surface(soup, false).closed_manifold);
    std::vector<Index> source;
    split_non_manifold(soup.vertices.x, soup.triangles, source);
    EXPECT_TRUE(check_surface(soup, false).closed_manifold);
    EXPECT_EQ(soup.vertex_count(), 8);  // 0 and 1 once per tet
    for (Index v = 0; v < soup.vertex_count(); ++v) EXPECT_EQ(soup.vertices.x[v], x[source[v]]);
    EXPECT_NEAR(surface_measures(soup).volume, 2.0 / 6, 1e-12);  // two tets of 1/6
}

TEST(PorousSurface, TwoBlocksMeetingAtAnEdgeMakeAManifoldSurface) {
    test::Simulation sim(
        boxes({{Vec3(0, 0, 0), Vec3(0.1, 0.1, 0.1)}, {Vec3(0.1, 0.1, 0), Vec3(0.2, 0.2, 0.1)}}));
    const PorousParticles& p = sim.state.porous.particles;
    PorousSurfaces surfaces;
    // Both blocks as one fragment: the alpha shape meets itself along the shared edge.
    PorousParticles one = p;
    std::fill(one.fragment.begin(), one.fragment.end(), 0);
    for (Real offset : {0.0, 0.02}) {
        for (Index i = 0; i < one.size(); ++i)
            one.rest[i] = one.x[i] =
                p.x[i] + (p.fragment[i] == 0 ? Vec3::Zero() : Vec3(offset, 0, 0));
        const SurfaceMesh mesh = surfaces.build(sim.model, one, std::vector<Real>(one.size(), 0));
        SCOPED_TRACE(offset);
        test::expect_clean(mesh);
    }
}

TEST(PorousSurface, FollowsItsParticlesAndIsRebuiltWhenMembersGo) {
    test::Simulation sim(
        boxes({{Vec3(0, 0, 0), Vec3(0.2, 0.2, 0.1)}, {Vec3(0, 0, 0.2), Vec3(0.1, 0.1, 0.3)}}));
    PorousParticles p = sim.state.porous.particles;
    PorousSurfaces surfaces;
    const std::vector<Real> dry(p.size(), 0);
    const SurfaceMesh before = surfaces.build(sim.model, p, dry);
    EXPECT_EQ(check_surface(before, false).closed_manifold, true);
    // A rigid motion moves the surface with the particles.
    for (Vec3& x : p.x) x += Vec3(0.05, -0.02, 0.01);
    const SurfaceMesh moved = surfaces.build(sim.model, p, dry);
    ASSERT_EQ(moved.triangles, before.triangles);
    for (Index v = 0; v < moved.vertex_count(); ++v)
        EXPECT_NEAR((moved.vertices.x[v] - before.vertices.x[v] - Vec3(0.05, -0.02, 0.01)).norm(),
                    0, 1e-12);
    // A corner particle dissolves: the surface is rebuilt without it.
    Index corner = 0;
    for (Index i = 1; i < p.size(); ++i)
        if (p.x[i].sum() < p.x[corner].sum()) corner = i;
    const Vec3 gone = p.x[corner];
    p.x.erase(p.x.begin() + corner), p.fragment.erase(p.fragment.begin() + corner),
        p.id.erase(p.id.begin() + corner), p.porosity.erase(p.porosity.begin() + corner),
        p.rest.erase(p.rest.begin() + corner);
    const SurfaceMesh after = surfaces.build(sim.model, p, std::vector<Real>(p.size(), 0));
    test::expect_clean(after);
    for (const Vec3& x : after.vertices.x) EXPECT_GT((x - gone).norm(), 1e-9);
    EXPECT_LT(surface_measures(after).volume, surface_measures(moved).volume);
}

}  // namespace
}  // namespace karst
