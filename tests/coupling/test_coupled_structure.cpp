// The Biot step inside a coupled run (docs/method.md §5.3-5.4, §4.10, issue 4): a water layer
// resting on an anchored soil block loads it through the fluid reactions, the block settles as a
// Biot solve with the equivalent uniform traction on its top says, and its particles follow; a
// block soft enough to distort its mesh is remeshed; with the Biot pressure carried, a sealed block
// holds the undrained pressure of its load.
#include "support/simulate.hpp"

#include "karst/core/parallel.hpp"
#include "karst/pfem/biot_setup.hpp"
#include "karst/pfem/structure_stages.hpp"

#include <gtest/gtest.h>

namespace karst {
namespace {

// A 0.4 x 0.4 x 0.06 m block of soft soil (E = 100 kPa) fills the floor of a tank under 0.1 m of
// water, q = rho0 g H = 981 Pa. Its sides touch the tank walls, so they are anchored with its
// base; the top is free. (On a 0.2 m tank the side walls carried 6 % of the water's weight
// through the fluid along their foot.)
/// `poroelastic` adds keys to /poroelastic.
std::string loaded_block_scene(Real youngs_modulus, const std::string& poroelastic = "") {
    return R"({
  "name": "loaded_block", "particle_spacing": 0.02,
  "time": { "fixed_dt": 0.002 },
  "fluid": { "artificial_viscosity": 0.02 },
  "fluid_blocks": [ { "shape": { "type": "box", "min": [0, 0, 0.06], "max": [0.4, 0.4, 0.16] } } ],
  "walls": [ { "kind": "container", "shape": { "type": "box", "min": [0, 0, 0], "max": [0.4, 0.4, 0.4] } } ],
  "porous_solids": [ { "shape": { "type": "box", "min": [0, 0, 0], "max": [0.4, 0.4, 0.06] },
                       "material": { "porosity": 0.3, "permeability": 1e-9, "initial_saturation": 1,
                                     "youngs_modulus": )" +
           std::to_string(youngs_modulus) +
           R"(, "poisson_ratio": 0.25, "absorption_factor": 0.01 } } ],
  "poroelastic": { "time_step": 0.02, "permeability_feedback": false)" +
           poroelastic + R"( }
})";
}

/// Mean height change of the particles whose rest height is at least `z`, m.
Real mean_sinking(const PorousParticles& p, const std::vector<Vec3>& rest_by_id, Real z) {
    Real sum = 0;
    int count = 0;
    for (Index i = 0; i < p.size(); ++i)
        if (rest_by_id[p.id[i]][2] >= z) sum += p.x[i][2] - rest_by_id[p.id[i]][2], ++count;
    return sum / count;
}

/// Steps to `end` with dt = 2 ms and the Biot step; returns the mean downward force of the fluid
/// on the porous particles after `from`, N.
Real run_and_mean_load(test::Simulation& sim, Real from, Real end) {
    Real sum = 0;
    int samples = 0;
    while (sim.state.time < end - 1e-9) {
        step(sim.model, sim.state, 0.002, sim.profile);
        if (sim.state.time > from) {
            for (const Vec3& f : sim.state.porous_scratch.force) sum -= f[2];
            ++samples;
        }
    }
    return sum / samples;
}

std::vector<Vec3> positions_by_id(const PorousParticles& p) {
    std::vector<Vec3> x(p.size());
    for (Index i = 0; i < p.size(); ++i) x[p.id[i]] = p.x[i];
    return x;
}

const PointArray& array(const PointSet& set, const std::string& name) {
    for (const PointArray& a : set.arrays)
        if (a.name == name) return a;
    throw std::runtime_error("no array " + name);
}

TEST(CoupledStructure, WaterLayerLoadsAnAnchoredBlockAndItSettlesAsUnderTheEquivalentTraction) {
    ThreadLimit one(1);
    test::Simulation sim(loaded_block_scene(1e5));
    ASSERT_FALSE(sim.state.structures.empty());
    const std::vector<Vec3> rest = positions_by_id(sim.state.porous.particles);
    const Real g = 9.81, fluid_weight = g * sim.model.particle_mass * Real(sim.state.fluid.size());
    const Real load = run_and_mean_load(sim, 0.6, 1.0);
    // 1. The block carries the water's weight (less the little it absorbed): the loads are right.
    const Real water_weight = fluid_weight - g * sim.state.porous.absorbed;
    EXPECT_NEAR(load, water_weight, 0.05 * water_weight)
        << "mean vertical fluid load over 0.6-1 s, N";
    EXPECT_EQ(sim.state.structures.timings.biot_calls, 50);

    // 2. Its top settles as a drained Biot solve of the same mesh under the same mean load as a
    //    uniform traction q on the top facets.
    MeshFrame coupled;
    append_structure_meshes(sim.model, sim.state, coupled);
    PfemTimings timings;
    const TetMesh mesh = mesh_points(sim.model, coupled.nodes.x, timings);
    ASSERT_EQ(mesh.node_count(), Index(coupled.nodes.x.size()));
    BiotProblem reference =
        biot_problem(sim.model, sim.model.scene.porous_solids[0], mesh,
                     std::vector<Mat3>(mesh.node_count(), 1e-9 * Mat3::Identity()));
    reference.gravity = Vec3::Zero();
    reference.drained.assign(mesh.node_count(), 1);
    const Real top = 0.05, q = load / (0.4 * 0.4);
    reference.nodal_force =
        traction_loads(mesh, Vec3(0, 0, -q), [&](const Vec3& x) { return x[2] > top - 1e-9; });
    BiotFields drained{std::vector<Vec3>(mesh.node_count(), Vec3::Zero()),
                       std::vector<Real>(mesh.node_count(), 0)};
    BiotSolver(mesh, reference).advance(1.0, drained);
    const PointArray& u = array(coupled.nodes, "displacement");
    Real coupled_top = 0, reference_top = 0;
    int top_nodes = 0;
    for (Index a = 0; a < mesh.node_count(); ++a) {
        if (mesh.nodes[a][2] < top - 1e-9) continue;
        coupled_top += u.values[3 * a + 2], reference_top += drained.u[a][2], ++top_nodes;
    }
    coupled_top /= top_nodes, reference_top /= top_nodes;
    ASSERT_LT(reference_top, -1e-4) << "the reference settles, m";
    // Measured 0.221 against 0.237 mm (7 % less; the mean load was 152 N against 157 N of water).
    // The rest: the boundary forces reach h = 2 dx, so the second particle layer takes part of
    // the load and less soil is compressed, and P^p > 0 where water pressed in pushes back.
    EXPECT_NEAR(coupled_top, reference_top, 0.12 * std::abs(reference_top))
        << "mean top settlement, m";

    // 3. The particles follow: the top layer sits at X + u of the call before the last (they move
    //    toward the last call's u over the next interval, and the run ends on a call). Not against
    //    the last call's u: the water above still moves (issue 11), so consecutive calls differ by
    //    a few per cent, and by how much depends on the round-off of the fluid's sums.
    const Structure& block = sim.state.structures.structures[0];
    Real from_top = 0;
    int from_nodes = 0;
    for (Index a = 0; a < block.mesh.node_count(); ++a)
        if (block.mesh.nodes[a][2] >= top - 1e-9) from_top += block.u_from[a][2], ++from_nodes;
    from_top /= from_nodes;
    EXPECT_NEAR(mean_sinking(sim.state.porous.particles, rest, top - 1e-9), from_top,
                1e-6 * std::abs(from_top))
        << "m";
}

TEST(CoupledStructure, AJellySoftBlockDistortsItsMeshAndIsRemeshedOnItsDeformedShape) {
    // E = 1 kPa: the water's 981 Pa would compress it by 80 % in linear theory, so the first calls
    // flatten elements below 2 degrees and it is remeshed on its deformed positions (§4.10).
    ThreadLimit one(1);
    test::Simulation sim(loaded_block_scene(1e3));
    const std::vector<Vec3> rest = positions_by_id(sim.state.porous.particles);
    const Real dx = sim.model.dx;
    while (sim.state.time < 0.3 - 1e-9) step(sim.model, sim.state, 0.002, sim.profile);
    EXPECT_GE(sim.state.structures.timings.remeshes, 1);
    // The remeshes carry the deformation on: the top has sunk by over a quarter of a spacing, and
    // no particle left the tank (the block fills its footprint). Before members stopped at the
    // walls, a top member held by slivers of the first remesh was carried 7 cm down in one call,
    // through the floor.
    EXPECT_LT(mean_sinking(sim.state.porous.particles, rest, 0.05 - 1e-9), -0.25 * dx);
    for (const Vec3& x : sim.state.porous.particles.x) {
        ASSERT_TRUE(x.allFinite());
        EXPECT_GT(x.minCoeff(), 0);
        EXPECT_LT(x.head<2>().maxCoeff(), 0.4);
    }
    EXPECT_EQ(sim.state.porous.particles.size(), Index(rest.size()));
}

TEST(CoupledStructure, WithTheBiotPressureCarriedTheSealedBlockHoldsTheUndrainedPressure) {
    // pressure_source biot: the Biot pressure carries from call to call. The block is sealed (no
    // drained nodes) and laterally confined by the tank, so the water's load q is taken undrained:
    // eps_v = -q / (E_oed + B^2 M) and p = B M q / (E_oed + B^2 M) throughout (Skempton's
    // one-dimensional loading efficiency).
    // tau = B^2 M / K_dr = 5 here: the fixed-stress split contracts by about 0.45 per iteration,
    // so reaching the 1e-3 test takes about 11 plain iterations, or 6.5 with Anderson mixing (the
    // default); M22's default of 5 leaves about 2e-2.
    ThreadLimit one(1);
    test::Simulation sim(
        loaded_block_scene(1e5, R"(, "pressure_source": "biot", "max_iterations": 20)"));
    // The water sloshes, so the load and the pressure are both averaged over the same steps:
    // one call's pressure follows its load within +-20 %.
    // The middle of the block, a block height and more from the side walls, which anchor its
    // edges and so take part of the load there.
    const auto middle_pressure = [&] {
        const Structure& s = sim.state.structures.structures.at(0);
        Real sum = 0;
        int count = 0;
        for (Index a = 0; a < s.mesh.node_count(); ++a) {
            const Vec3& x = s.mesh.nodes[a];
            if (std::min({x[0], x[1], 0.4 - x[0], 0.4 - x[1]}) < 0.1) continue;
            sum += s.fields.p[a], ++count;
        }
        return sum / count;
    };
    Real load = 0, mean = 0;
    int samples = 0;
    while (sim.state.time < 0.8 - 1e-9) {
        step(sim.model, sim.state, 0.002, sim.profile);
        if (sim.state.time <= 0.5) continue;
        for (const Vec3& f : sim.state.porous_scratch.force) load -= f[2];
        mean += middle_pressure(), ++samples;
    }
    load /= samples, mean /= samples;
    EXPECT_EQ(sim.state.structures.timings.unconverged_calls, 0);
    const BiotMaterial m = biot_material(sim.model, sim.model.scene.porous_solids[0].material);
    const Real M = 1 / m.storage, E_oed = m.lame_lambda() + 2 * m.shear_modulus();
    const Real q = load / (0.4 * 0.4);
    const Real undrained =
        m.biot_coefficient * M * q / (E_oed + m.biot_coefficient * m.biot_coefficient * M);
    ASSERT_GT(undrained, 100) << "Pa";
    EXPECT_NEAR(mean, undrained, 0.05 * undrained) << "mean pore pressure in the middle, Pa";
}

TEST(CoupledStructure, AFragmentRestingOnAnAnchoredBlockLoadsItsBiotProblemThroughTheContacts) {
    // A free impermeable block (8 kg) lies on an anchored soil block, with no water: the only
    // load on the soil is the contact force, so the Biot call's mean load is the block's weight
    // and the soil settles under it.
    ThreadLimit one(1);
    test::Simulation sim(R"({
      "name": "pushed", "particle_spacing": 0.02, "time": { "fixed_dt": 0.002 },
      "walls": [ { "kind": "container", "shape": { "type": "box", "min": [0, 0, 0], "max": [0.4, 0.4, 0.4] } } ],
      "porous_solids": [
        { "shape": { "type": "box", "min": [0, 0, 0], "max": [0.4, 0.4, 0.1] },
          "material": { "porosity": 0.3, "permeability": 1e-10, "initial_saturation": 0, "youngs_modulus": 1e5, "poisson_ratio": 0.25 } },
        { "shape": { "type": "box", "min": [0.1, 0.1, 0.1], "max": [0.3, 0.3, 0.2] }, "anchored": false,
          "material": { "porosity": 0, "permeability": 1e-12, "solid_density": 2000 } } ],
      "poroelastic": { "time_step": 0.02, "permeability_feedback": false }
    })");
    ASSERT_EQ(sim.state.structures.structures.size(), 1u);
    const StructureState& st = sim.state.structures;
    const Real weight = 9.81 * sim.state.porous.fragments[1].mass;
    ASSERT_NEAR(weight, 9.81 * 8, 0.1);
    Real load = 0;
    int calls = 0;
    while (sim.state.time < 1.0 - 1e-9) {
        sim.advance();
        // The loads the next call will take: the mean force since the last call, summed over the
        // soil.
        if (sim.state.time > 0.5 && st.elapsed > 0.017) {  // the last step before a call
            Vec3 sum = Vec3::Zero();
            for (Index id : st.structures[0].node_id) sum += st.impulse[id];
            load -= sum[2] / st.elapsed, ++calls;
        }
    }
    ASSERT_GE(calls, 20);
    EXPECT_NEAR(load / calls, weight, 0.05 * weight) << "mean downward Biot load on the soil, N";
    // The soil under the block settles; far from it, it hardly moves.
    const Structure& s = st.structures[0];
    Real under = 0, far = 0;
    for (Index a = 0; a < s.mesh.node_count(); ++a) {
        const Vec3& X = s.mesh.nodes[a];
        if (X[2] < 0.08) continue;
        if (std::max(std::abs(X[0] - 0.2), std::abs(X[1] - 0.2)) < 0.05)
            under = std::min(under, s.fields.u[a][2]);
        if (std::max(std::abs(X[0] - 0.2), std::abs(X[1] - 0.2)) > 0.15)
            far = std::min(far, s.fields.u[a][2]);
    }
    // A 78 N load on 0.04 m^2 of a 0.1 m layer with E = 100 kPa: about 2 kPa over an oedometric
    // modulus of 120 kPa, 1.6 mm.
    EXPECT_LT(under, -5e-4) << "m";
    EXPECT_GT(far, 0.5 * under) << "m";
}

// An anchored block held in the air (no wall, no fixed constraint: the scene says it is held) with
// water poured on it: its Biot problem has no fixed node, so the fluid's net load is taken by the
// anchor (pfem/load_balance.hpp) and the block only deforms. With the rigid-mode spring alone the
// load moved it 6.6 m in one call and the run stopped.
TEST(CoupledStructure, ABlockAnchoredInTheAirHoldsTheWaterPouredOnItInPlace) {
    ThreadLimit one(1);
    test::Simulation sim(R"({
      "name": "ledge", "particle_spacing": 0.02, "time": { "end": 0.3 },
      "fluid_blocks": [ { "shape": { "type": "box", "min": [0.2, 0.04, 0.32], "max": [0.3, 0.16, 0.42] } } ],
      "walls": [ { "kind": "container", "shape": { "type": "box", "min": [0, 0, 0], "max": [0.4, 0.2, 0.5] } } ],
      "porous_solids": [ { "shape": { "type": "box", "min": [0.2, 0.04, 0.2], "max": [0.3, 0.16, 0.3] },
                           "material": { "porosity": 0.3, "permeability": 1e-10 } } ]
    })");
    ASSERT_EQ(sim.state.structures.structures.size(), 1u);
    const std::vector<Vec3> rest = positions_by_id(sim.state.porous.particles);
    Real largest_move = 0, largest_u = 0;
    sim.run_until(0.3, [&] {
        const PorousParticles& p = sim.state.porous.particles;
        for (Index i = 0; i < p.size(); ++i)
            largest_move = std::max(largest_move, (p.x[i] - rest[p.id[i]]).norm());
        for (const Vec3& u : sim.state.structures.structures[0].fields.u)
            largest_u = std::max(largest_u, u.norm());
    });
    ASSERT_GE(sim.state.structures.timings.biot_calls, 8);
    EXPECT_GT(largest_u, 0) << "the water's load deforms the block";
    EXPECT_LT(largest_u, 1e-3) << "m";
    EXPECT_LT(largest_move, 1e-3) << "m";
}

TEST(CoupledStructure, ACopiedStateRebuildsItsBiotSolversAndContinuesIdentically) {
    // The factorisations are a cache, not state: a copy of the State has none, rebuilds them from
    // its meshes at its next call, and runs on bit for bit with the original.
    ThreadLimit one(1);
    test::Simulation sim(loaded_block_scene(1e5));
    while (sim.state.time < 0.1 - 1e-9) step(sim.model, sim.state, 0.002, sim.profile);
    State copy = sim.state;
    const Index calls_before = sim.state.structures.timings.biot_calls;
    ASSERT_GT(calls_before, 0);
    const Structure& s = copy.structures.structures.at(0);
    EXPECT_EQ(copy.biot_cache.find(0, s.mesh_version), nullptr) << "a copy holds no solver";
    StepProfile profile;
    while (sim.state.time < 0.2 - 1e-9) {
        step(sim.model, sim.state, 0.002, sim.profile);
        step(sim.model, copy, 0.002, profile);
    }
    EXPECT_NE(copy.biot_cache.find(0, s.mesh_version), nullptr) << "rebuilt at its first call";
    EXPECT_EQ(copy.structures.timings.biot_calls, sim.state.structures.timings.biot_calls);
    const Structure& a = sim.state.structures.structures.at(0);
    EXPECT_EQ(a.fields.u, s.fields.u);
    EXPECT_EQ(a.fields.p, s.fields.p);
    EXPECT_EQ(sim.state.porous.particles.x, copy.porous.particles.x);
    EXPECT_EQ(sim.state.fluid.x, copy.fluid.x);
}

}  // namespace
}  // namespace karst
