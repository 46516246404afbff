// Unanchored pieces of a Biot mesh (docs/method.md §5.3): a net load on a body that no fixed node
// holds is taken by its anchor (pfem/load_balance.hpp), so it deforms under the rest of its loads
// instead of moving |f| / (eps K) with the rigid-mode spring; an island beside an anchored block
// leaves the block's solution as it is alone.
#include "karst/pfem/biot.hpp"
#include "karst/pfem/biot_setup.hpp"
#include "karst/pfem/box_nodes.hpp"

#include <gtest/gtest.h>

namespace karst {
namespace {

constexpr Real k_dx = 0.1, k_E = 1e6;

TetMesh box_mesh(const std::vector<Vec3>& nodes) {
    return build_tet_mesh(nodes, std::vector<Real>(nodes.size(), k_dx), MeshOptions{});
}

BiotProblem elastic_problem(const TetMesh& mesh) {
    BiotProblem p;
    p.material.youngs_modulus = k_E, p.material.poisson_ratio = 0.25, p.material.bulk_density = 0;
    p.mobility.assign(mesh.tet_count(), Mat3::Identity());
    p.drained.assign(mesh.node_count(), 1);
    p.fixed.assign(mesh.node_count(), 0);
    p.nodal_force.assign(mesh.node_count(), Vec3::Zero());
    return p;
}

std::vector<Vec3> solve(const TetMesh& mesh, const BiotProblem& problem) {
    BiotSolver solver(mesh, problem);
    BiotFields fields{std::vector<Vec3>(mesh.node_count(), Vec3::Zero()),
                      std::vector<Real>(mesh.node_count(), 0)};
    solver.advance(1.0, fields);
    return fields.u;
}

Real largest(const std::vector<Vec3>& u) {
    Real m = 0;
    for (const Vec3& v : u) m = std::max(m, v.norm());
    return m;
}

// A free bar pulled by sigma on its ends stretches by sigma / E; adding on every node the force
// of a rigid motion (a net force and moment that strain nothing) changes nothing: the anchor
// takes it. With the spring alone the extra load moved the bar by |f| / (1e-8 K), some 1e3 m.
TEST(LoadBalance, ANetLoadOnAnUnanchoredBarIsTakenByItsAnchor) {
    const Real L = 0.6, sigma = 1e3;
    const TetMesh mesh = box_mesh(box_lattice_nodes(Vec3::Zero(), Vec3(L, 0.2, 0.2), k_dx));
    BiotProblem pulled = elastic_problem(mesh);
    for (int side = 0; side < 2; ++side) {
        const auto loads =
            traction_loads(mesh, (side ? sigma : -sigma) * Vec3::UnitX(),
                           [&](const Vec3& x) { return std::abs(x[0] - side * L) < 1e-9; });
        for (Index a = 0; a < mesh.node_count(); ++a) pulled.nodal_force[a] += loads[a];
    }
    pulled.unheld_pieces = unheld_pieces(mesh, pulled.fixed);
    pulled.free_body = true;
    ASSERT_EQ(pulled.unheld_pieces.size(), 1u);
    EXPECT_EQ(pulled.unheld_pieces[0].size(), size_t(mesh.node_count()));

    BiotProblem pushed = pulled;
    for (Index a = 0; a < mesh.node_count(); ++a)
        pushed.nodal_force[a] +=
            Vec3(3, -2, 5) + 40 * Vec3(0.5, -1, 2).cross(mesh.nodes[a] - Vec3(0.3, 0.1, 0.1));
    const std::vector<Vec3> u = solve(mesh, pulled), u_pushed = solve(mesh, pushed);

    Real right = 0, left = 0;
    int n_right = 0, n_left = 0;
    for (Index a = 0; a < mesh.node_count(); ++a) {
        if (mesh.nodes[a][0] > L - 1e-9) right += u[a][0], ++n_right;
        if (mesh.nodes[a][0] < 1e-9) left += u[a][0], ++n_left;
    }
    EXPECT_NEAR((right / n_right - left / n_left) / L, sigma / k_E, 0.02 * sigma / k_E)
        << "mean strain along the bar";
    Real change = 0;
    for (Index a = 0; a < mesh.node_count(); ++a)
        change = std::max(change, (u_pushed[a] - u[a]).norm());
    EXPECT_LT(change, 1e-6 * largest(u)) << "m: the net load moved the bar";
}

// An unanchored block beside one fixed at its base, in one mesh, under gravity: the anchored
// block's displacement is what it is alone, and the island moves by no more than its own weight
// could strain it.
TEST(LoadBalance, AnIslandBesideAnAnchoredBlockLeavesItsSolutionAsItIsAlone) {
    std::vector<Vec3> nodes = box_lattice_nodes(Vec3::Zero(), Vec3(0.3, 0.3, 0.3), k_dx);
    const size_t block_nodes = nodes.size();
    const TetMesh block = box_mesh(nodes);
    for (const Vec3& x : box_lattice_nodes(Vec3(0.6, 0, 0.1), Vec3(0.9, 0.3, 0.4), k_dx))
        nodes.push_back(x);
    const TetMesh both = box_mesh(nodes);
    ASSERT_EQ(both.node_count(), Index(nodes.size()));

    const auto weighted = [&](const TetMesh& mesh) {
        BiotProblem p = elastic_problem(mesh);
        p.material.bulk_density = 2000, p.gravity = Vec3(0, 0, -9.81);
        for (Index a = 0; a < mesh.node_count(); ++a)
            if (mesh.nodes[a][2] < 1e-9 && mesh.nodes[a][0] < 0.45) p.fixed[a] = FixAll;
        p.unheld_pieces = unheld_pieces(mesh, p.fixed);
        p.free_body = !p.unheld_pieces.empty();
        return p;
    };
    const BiotProblem alone = weighted(block), together = weighted(both);
    EXPECT_TRUE(alone.unheld_pieces.empty());
    ASSERT_EQ(together.unheld_pieces.size(), 1u);
    EXPECT_EQ(together.unheld_pieces[0].size(), nodes.size() - block_nodes);

    const std::vector<Vec3> u_alone = solve(block, alone), u = solve(both, together);
    // Both meshes number the block's nodes first, in the same order.
    Real change = 0;
    for (size_t a = 0; a < block_nodes; ++a) change = std::max(change, (u[a] - u_alone[a]).norm());
    const Real sag = largest(u_alone);
    EXPECT_GT(sag, 0);
    EXPECT_LT(change, 1e-6 * sag) << "m, largest change of the anchored block";
    Real island = 0;
    for (size_t a = block_nodes; a < nodes.size(); ++a) island = std::max(island, u[a].norm());
    const Real weight_strain = 2000 * 9.81 * 0.3 * 0.3 / k_E;  // rho g H^2 / E, m
    EXPECT_LT(island, weight_strain) << "m";
}

}  // namespace
}  // namespace karst
