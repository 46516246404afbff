// Merging (docs/method.md §5.6, the paper's Fig. 7): a dry block resting on another stays apart;
// a saturated one pressed on it by its weight merges, keeping mass and linear momentum, and a
// saturated block resting on an anchored soil joins its PFEM structure.
#include "support/simulate.hpp"

#include "karst/pfem/merge_stage.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>

namespace karst {
namespace {

/// A 0.12 m block resting on a 0.2 x 0.2 x 0.1 m block on the floor of a box, both porous with
/// `saturation` and free unless `anchored_base`; merging as `merge`.
std::string stacked_blocks(Real saturation, bool anchored_base, bool merge = true) {
    return fmt::format(R"({{
      "name": "stack", "particle_spacing": 0.02, "time": {{ "fixed_dt": 0.002 }},
      "walls": [ {{ "kind": "container", "shape": {{ "type": "box", "min": [0, 0, 0], "max": [0.2, 0.2, 0.4] }} }} ],
      "porous_solids": [
        {{ "shape": {{ "type": "box", "min": [0, 0, 0], "max": [0.2, 0.2, 0.1] }}, "anchored": {},
           "material": {{ "porosity": 0.3, "permeability": 1e-12, "initial_saturation": {}, "youngs_modulus": 1e7 }} }},
        {{ "shape": {{ "type": "box", "min": [0.04, 0.04, 0.1], "max": [0.16, 0.16, 0.16] }}, "anchored": false,
           "material": {{ "porosity": 0.3, "permeability": 1e-12, "initial_saturation": {} }} }} ],
      "fracture": {{ "merge": {} }},
      "poroelastic": {{ "time_step": 0.02, "permeability_feedback": false }}
    }})",
                       anchored_base, saturation, saturation, merge);
}

Index live_fragments(const State& s) {
    Index n = 0;
    for (const Fragment& f : s.porous.fragments) n += f.mass > 0;
    return n;
}

Vec3 fragment_momentum(const State& s) {
    Vec3 m = Vec3::Zero();
    for (const Fragment& f : s.porous.fragments) m += f.mass * f.velocity;
    return m;
}

Real fragment_mass(const State& s) {
    Real m = 0;
    for (const Fragment& f : s.porous.fragments) m += f.mass;
    return m;
}

TEST(Merging, ADryBlockRestingOnAnotherStaysApart) {
    test::Simulation sim(stacked_blocks(0.0, false));
    ASSERT_EQ(live_fragments(sim.state), 2);
    sim.run_until(0.6);
    EXPECT_EQ(live_fragments(sim.state), 2);
    EXPECT_EQ(sim.state.structures.fracture.merges, 0);
}

TEST(Merging, ASaturatedBlockPressedOnAnotherMergesKeepingMassAndMomentum) {
    // Without merging, to find the state just before they would merge: settled, in contact.
    test::Simulation sim(stacked_blocks(1.0, false, false));
    sim.run_until(0.3);
    ASSERT_EQ(live_fragments(sim.state), 2);
    const Real mass = fragment_mass(sim.state);
    const Vec3 momentum = fragment_momentum(sim.state);
    sim.model.scene.fracture.merge = true;
    ASSERT_TRUE(merge_fragments(sim.model, sim.state));
    EXPECT_EQ(live_fragments(sim.state), 1);
    EXPECT_EQ(sim.state.structures.fracture.merges, 1);
    EXPECT_NEAR(fragment_mass(sim.state), mass, 1e-12 * mass);
    EXPECT_LT((fragment_momentum(sim.state) - momentum).norm(), 1e-12 * mass + 1e-12);
    // The merged body keeps resting: it neither jumps nor sinks through the floor.
    const Index merged = sim.state.porous.particles.fragment[0];
    for (Index k = 0; k < sim.state.porous.size(); ++k)
        ASSERT_EQ(sim.state.porous.particles.fragment[k], merged);
    sim.run_until(0.6);
    EXPECT_LT(sim.state.porous.fragments[merged].velocity.norm(), 0.05) << "m/s";
}

TEST(Merging, ASaturatedBlockOnAnAnchoredSoilJoinsItsStructure) {
    test::Simulation sim(stacked_blocks(1.0, true));
    ASSERT_EQ(sim.state.structures.structures.size(), 1u);
    const Index soil_nodes = sim.state.structures.structures[0].mesh.node_count();
    sim.run_until(0.6);
    EXPECT_EQ(live_fragments(sim.state), 1);
    EXPECT_EQ(sim.state.structures.fracture.merges, 1);
    EXPECT_EQ(sim.state.structures.structures[0].mesh.node_count(), sim.state.porous.size());
    EXPECT_GT(sim.state.porous.size(), soil_nodes);
    for (Index k = 0; k < sim.state.porous.size(); ++k)
        EXPECT_LT(sim.state.porous.particles.v[k].norm(), 1e-3) << "particle " << k;
}

}  // namespace
}  // namespace karst
