// Unanchored pieces of a Biot mesh (docs/method.md §5.3): a net load on a body that no fixed node
// holds is taken by its anchor (pfem/load_balance.hpp), so it deforms under the rest of its loads
// instead of moving |f| / (eps K) with the rigid-mode spring; an island beside an anchored block
// leaves the block's solution as it is alone; the deformation of an unheld body moves neither its
// centre of mass nor its mean turn.
#include "karst/pfem/biot.hpp"
#include "karst/pfem/biot_setup.hpp"
#include "karst/pfem/box_nodes.hpp"
#include "karst/pfem/load_balance.hpp"

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

/// Mean displacement and mean turn sum (x - c) x u / sum |x - c|^2 of the nodes `of`, every node
/// alike (the particles of a structure weigh alike).
std::pair<Vec3, Vec3> rigid_part(const TetMesh& mesh, const std::vector<Vec3>& u,
                                 const std::vector<Index>& of) {
    Real spread = 0;
    Vec3 centre = Vec3::Zero(), mean = Vec3::Zero(), turn = Vec3::Zero();
    for (Index a : of) centre += mesh.nodes[a];
    centre /= Real(of.size());
    for (Index a : of) {
        const Vec3 r = mesh.nodes[a] - centre;
        mean += u[a], turn += r.cross(u[a]), spread += r.squaredNorm();
    }
    return {mean / Real(of.size()), turn / spread};
}

Real largest(const std::vector<Vec3>& u) {
    Real m = 0;
    for (const Vec3& v : u) m = std::max(m, v.norm());
    return m;
}

// A free bar pulled by sigma on its ends stretches by sigma / E; adding on every node the force
// of a rigid acceleration of equal nodal masses (as a run's particles have; a problem without
// gravity is balanced so) changes nothing: the anchor takes it. With the spring alone the extra
// load moved the bar by |f| / (1e-8 K), some 1e3 m.
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
// block's displacement is what it is alone, and the island, whose weight its anchor takes
// through the acceleration of each node's share, neither moves nor strains.
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
    EXPECT_LT(island, 1e-9 * weight_strain) << "m: the island's own weight strained or moved it";
}

// A block that nothing holds (a poroelastic solid without constraints): its own weight strains
// nothing, since the anchor's acceleration balances each node's share; a load on half its top
// face does, and its deformation moves neither the block's centre of mass nor its mean turn. The
// spring's own weighting diag(K) let the centre rise by a few per cent of the deformation per
// call, potential energy that the run's account reported as gained.
TEST(LoadBalance, AnUnheldBlockDeformsAboutItsCentreOfMassAndItsWeightStrainsNothing) {
    const Real H = 0.4, load = 2e3;
    const TetMesh mesh = box_mesh(box_lattice_nodes(Vec3::Zero(), Vec3(0.3, 0.2, H), k_dx));
    BiotProblem p = elastic_problem(mesh);
    p.material.bulk_density = 2000, p.gravity = Vec3(0.5, 0, -9.81);
    p.unheld_pieces = unheld_pieces(mesh, p.fixed);
    p.free_body = true;
    ASSERT_EQ(p.unheld_pieces.size(), 1u);
    const Real weight_strain = 2000 * 9.81 * H * H / k_E;  // rho g H^2 / E, m
    EXPECT_LT(largest(solve(mesh, p)), 1e-9 * weight_strain) << "m under its weight alone";

    p.nodal_force = traction_loads(mesh, -load * Vec3::UnitZ(), [&](const Vec3& x) {
        return x[2] > H - 1e-9 && x[0] < 0.15 + 1e-9;
    });
    const std::vector<Vec3> u = solve(mesh, p);
    const Real load_strain = load * H / k_E;
    EXPECT_GT(largest(u), 0.1 * load_strain) << "m: the load does not deform it";
    EXPECT_LT(largest(u), 2 * load_strain) << "m";
    const auto [mean, turn] = rigid_part(mesh, u, p.unheld_pieces[0]);
    EXPECT_LT(mean.norm(), 1e-9 * largest(u)) << "m: the centre of mass moved";
    EXPECT_LT(turn.norm() * H, 1e-9 * largest(u)) << "the block turned";
}

// A block hanging from an anchored one by an edge (no face shared: an unheld piece). The rigid
// motion removed from its solution (LoadBalance::remove_rigid_motion) is a turn about that edge:
// it never moves the edge's nodes, which the anchored block's tets share. Removing the piece's
// fitted translation there instead sheared the anchored block's top tets by u / dx.
TEST(LoadBalance, TheRigidMotionRemovedFromAPieceHangingByAnEdgeTurnsItAboutTheEdge) {
    const TetMesh block = box_mesh(box_lattice_nodes(Vec3::Zero(), Vec3(0.3, 0.3, 0.3), k_dx));
    const TetMesh hanging =
        box_mesh(box_lattice_nodes(Vec3(0.3, 0, 0.3), Vec3(0.6, 0.3, 0.6), k_dx));
    TetMesh mesh = block;  // the two, the edge x = z = 0.3 once
    std::vector<Index> map(hanging.node_count());
    for (Index b = 0; b < hanging.node_count(); ++b) {
        map[b] = mesh.node_count();
        for (Index a = 0; a < block.node_count(); ++a)
            if ((block.nodes[a] - hanging.nodes[b]).norm() < 1e-9) map[b] = a;
        if (map[b] == mesh.node_count()) mesh.nodes.push_back(hanging.nodes[b]);
    }
    for (Tet t : hanging.tets) {
        for (Index& a : t) a = map[a];
        mesh.tets.push_back(t);
    }
    BiotProblem p = elastic_problem(mesh);
    std::vector<char> prescribed(3 * mesh.node_count(), 0);
    for (Index a = 0; a < mesh.node_count(); ++a)
        if (mesh.nodes[a][2] < 1e-9)
            p.fixed[a] = FixAll, prescribed[3 * a] = 1, prescribed[3 * a + 1] = 1,
            prescribed[3 * a + 2] = 1;
    p.unheld_pieces = unheld_pieces(mesh, p.fixed);
    ASSERT_EQ(p.unheld_pieces.size(), 1u);
    const DofSplit dofs(prescribed);
    const LoadBalance balance(mesh, p, dofs, Vector::Ones(mesh.node_count()));
    const auto on_edge = [](const Vec3& x) {
        return std::abs(x[0] - 0.3) < 1e-9 && std::abs(x[2] - 0.3) < 1e-9;
    };
    std::vector<char> in_piece(mesh.node_count(), 0);
    for (Index a : p.unheld_pieces[0]) in_piece[a] = 1;

    // Every free node moved by t: the edge keeps t, and so does the anchored block.
    const Vec3 t(1e-3, -2e-3, 3e-3);
    Vector u(dofs.free_count);
    for (Index a = 0; a < mesh.node_count(); ++a)
        for (int d = 0; d < 3; ++d)
            if (const int row = dofs.free_index[3 * a + d]; row >= 0) u[row] = t[d];
    balance.remove_rigid_motion(u);
    Real moved = 0, piece_change = 0;
    for (Index a = 0; a < mesh.node_count(); ++a)
        for (int d = 0; d < 3; ++d)
            if (const int row = dofs.free_index[3 * a + d]; row >= 0) {
                const Real change = std::abs(u[row] - t[d]);
                if (!in_piece[a] || on_edge(mesh.nodes[a]))
                    moved = std::max(moved, change);
                else
                    piece_change = std::max(piece_change, change);
            }
    EXPECT_LT(moved, 1e-15) << "m: the edge or the anchored block moved";
    EXPECT_GT(piece_change, 0.1 * t.norm()) << "m: no turn about the edge was fitted";

    // A turn of the piece about the edge is removed whole.
    const Vec3 theta(0, 2e-3, 0), pivot(0.3, 0, 0.3);
    u.setZero();
    for (Index a : p.unheld_pieces[0]) {
        const Vec3 turn = theta.cross(mesh.nodes[a] - pivot);
        for (int d = 0; d < 3; ++d)
            if (const int row = dofs.free_index[3 * a + d]; row >= 0) u[row] = turn[d];
    }
    balance.remove_rigid_motion(u);
    EXPECT_LT(u.lpNorm<Eigen::Infinity>(), 1e-15) << "m left of a turn about the edge";
}

}  // namespace
}  // namespace karst
