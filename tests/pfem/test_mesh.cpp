// The PFEM mesh (docs/method.md §5.1): alpha shape volume, EDT joining of lattice cells, slivers.
#include "karst/pfem/box_nodes.hpp"
#include "karst/pfem/tet_mesh.hpp"

#include <gtest/gtest.h>

#include <map>
#include <set>

namespace karst {
namespace {

TetMesh lattice_cube_mesh(Real dx, MeshOptions options = {}) {
    const auto nodes = box_lattice_nodes(Vec3::Zero(), Vec3::Ones(), dx, 1e-3);
    const std::vector<Real> size(nodes.size(), dx);
    std::vector<Real> weights;
    if (options.weighted) weights.assign(nodes.size(), 0.25 * dx * dx * 0.5);
    return build_tet_mesh(nodes, size, options, weights);
}

TEST(TetMesh, AlphaShapeOfJitteredLatticeCubeRecoversItsVolumeWithinOnePercent) {
    const TetMesh mesh = lattice_cube_mesh(0.1);
    EXPECT_NEAR(mesh.quality.volume, 1.0, 0.01);
    // The assembled tets (slivers dropped) still fill the cube: slivers have next to no volume.
    Real assembled = 0;
    for (Index e = 0; e < mesh.tet_count(); ++e) {
        ASSERT_GT(mesh.tet_volume(e), 0) << "tet " << e << " is not positively oriented";
        assembled += mesh.tet_volume(e);
    }
    EXPECT_NEAR(assembled, 1.0, 0.01);
    // The boundary is closed and encloses the same volume (divergence theorem: V = 1/3 sum x.n dA).
    Real enclosed = 0;
    for (const Triangle& t : mesh.boundary)
        enclosed += mesh.nodes[t[0]].dot(mesh.area_vector(t)) / 3;
    EXPECT_NEAR(enclosed, mesh.quality.volume, 1e-9);
}

TEST(TetMesh, AlphaShapeKeepsAGapBetweenTwoCubesOpen) {
    // Two unit-spacing lattice cubes 3 dx apart: the convex hull would bridge them, M19 must not.
    const Real dx = 0.1;
    auto nodes = box_lattice_nodes(Vec3::Zero(), Vec3(0.5, 0.5, 0.5), dx, 1e-3, 1);
    const auto right = box_lattice_nodes(Vec3(0.8, 0, 0), Vec3(1.3, 0.5, 0.5), dx, 1e-3, 2);
    nodes.insert(nodes.end(), right.begin(), right.end());
    const TetMesh mesh = build_tet_mesh(nodes, std::vector<Real>(nodes.size(), dx), MeshOptions{});
    EXPECT_NEAR(mesh.quality.volume, 2 * 0.125, 0.01 * 0.25);
}

TEST(TetMesh, JoiningGroupsTheCosphericalCornersOfEachLatticeCell) {
    const Real dx = 0.1;
    const TetMesh mesh = lattice_cube_mesh(dx);
    // Every cell of the jittered 10^3 lattice is one EDT polyhedron: its (non-sliver) tets share
    // nearly one circumsphere. Interior slivers are their own polyhedra (ill-conditioned centres).
    std::map<Index, std::set<Index>> corners;
    for (Index e = 0; e < mesh.tet_count(); ++e)
        if (mesh.tet_volume(e) >= 1e-3 * dx * dx * dx)
            for (Index a : mesh.tets[e]) corners[mesh.tet_polyhedron[e]].insert(a);
    EXPECT_EQ(corners.size(), 1000u);
    for (const auto& [id, nodes] : corners) {
        ASSERT_EQ(nodes.size(), 8u) << "polyhedron " << id;
        // ... and the eight are the corners of one lattice cell: they span one spacing per axis.
        Vec3 lo = Vec3::Constant(1e9), hi = -lo;
        for (Index a : nodes) lo = lo.cwiseMin(mesh.nodes[a]), hi = hi.cwiseMax(mesh.nodes[a]);
        ASSERT_LT(((hi - lo) - Vec3::Constant(dx)).cwiseAbs().maxCoeff(), 0.01 * dx);
    }
    // Unjittered, CGAL splits each cell into 6 tets with one circumcentre and no sliver.
    const auto exact = box_lattice_nodes(Vec3::Zero(), Vec3::Ones(), dx);
    const TetMesh lattice =
        build_tet_mesh(exact, std::vector<Real>(exact.size(), dx), MeshOptions{});
    EXPECT_EQ(lattice.quality.polyhedra, 1000);
    EXPECT_EQ(lattice.quality.elements, 6000);
    EXPECT_EQ(lattice.quality.interior_slivers + lattice.quality.slivers_dropped, 0);
    EXPECT_GT(lattice.quality.min_dihedral_deg, 35.0);
}

// Slivers on the surface are dropped; interior ones stay, because dropping them breaks
// conformity (Biot.PatchTestReproducesUniformStrainExactly fails by 20 % without them).
TEST(TetMesh, NoSurfaceSliverEntersAssembly) {
    const Real dx = 0.1;
    MeshOptions options;
    const TetMesh mesh = lattice_cube_mesh(dx, options);
    std::vector<char> on_surface(mesh.node_count(), 0);
    for (const Triangle& t : mesh.boundary)
        for (Index a : t) on_surface[a] = 1;
    Index interior_slivers = 0;
    for (Index e = 0; e < mesh.tet_count(); ++e) {
        if (mesh.tet_volume(e) >= options.sliver_volume * dx * dx * dx) continue;
        ++interior_slivers;
        const Tet& t = mesh.tets[e];
        ASSERT_FALSE(on_surface[t[0]] && on_surface[t[1]] && on_surface[t[2]] && on_surface[t[3]])
            << "sliver " << e << " lies on the surface";
    }
    EXPECT_EQ(interior_slivers, mesh.quality.interior_slivers);
    EXPECT_EQ(mesh.quality.elements + mesh.quality.slivers_dropped, mesh.quality.kept);
    EXPECT_GT(mesh.quality.min_dihedral_deg, 1.0);
    // Remove the top layer of cells by shaving the alpha: a stricter alpha drops more.
    options.alpha = 0.5;
    EXPECT_EQ(lattice_cube_mesh(dx, options).quality.kept, 0) << "no lattice cell has R < 0.5 dx";
}

TEST(TetMesh, WeightedAlphaShapeWithEqualWeightsMatchesTheUnweightedOne) {
    MeshOptions weighted;
    weighted.weighted = true;
    const TetMesh plain = lattice_cube_mesh(0.1), power = lattice_cube_mesh(0.1, weighted);
    EXPECT_NEAR(power.quality.volume, plain.quality.volume, 1e-9);
    EXPECT_EQ(power.quality.kept, plain.quality.kept);
}

}  // namespace
}  // namespace karst
