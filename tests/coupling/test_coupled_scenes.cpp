// Fluid and porous fragments in one step (docs/method.md §4.1-4.8, issue 3): Archimedes, a porous
// box that soaks and sinks, a free fragment in vacuum, exact momentum exchange between fluid and
// fragment, and exact water and grain balance through absorption, draining and dissolution.
#include "support/files.hpp"
#include "support/simulate.hpp"

#include "karst/core/parallel.hpp"
#include "karst/sim/energy.hpp"
#include "karst/sim/run.hpp"

#include <nlohmann/json.hpp>

#include <gtest/gtest.h>

#include <filesystem>

namespace karst {
namespace {

constexpr Real k_dx = 0.02;

/// Height where the SPH colour field sum_j V_j W falls to 1/2 above (x, y): the free surface.
Real free_surface(const Model& model, const FluidParticles& f, Real x, Real y, Real lo, Real hi) {
    std::vector<Vec3> column;
    for (const Vec3& p : f.x)
        if (std::abs(p[0] - x) < model.h && std::abs(p[1] - y) < model.h) column.push_back(p);
    auto colour = [&](Real z) {
        Real c = 0;
        for (const Vec3& p : column)
            c += model.lattice_volume * model.kernel.w((Vec3(x, y, z) - p).norm());
        return c;
    };
    for (int it = 0; it < 40; ++it) (colour(0.5 * (lo + hi)) > 0.5 ? lo : hi) = 0.5 * (lo + hi);
    return 0.5 * (lo + hi);
}

Real lowest(const std::vector<Vec3>& x) {
    Real z = 1e9;
    for (const Vec3& p : x) z = std::min(z, p[2]);
    return z;
}

// A 0.16 x 0.16 x 0.12 m impermeable box of density 500 kg/m^3 released 2 cm above its
// equilibrium in a 0.4 x 0.4 m tank: it settles at the draft rho_s / rho0 H = 0.06 m.
TEST(Coupling, ImpermeableBoxFloatsAtTheArchimedesDraft) {
    ThreadLimit one(1);
    test::Simulation sim(R"({
      "name": "float", "particle_spacing": 0.02,
      "fluid": { "artificial_viscosity": 0.02 },
      "fluid_blocks": [ { "shape": { "type": "difference", "shapes": [
          { "type": "box", "min": [0, 0, 0], "max": [0.4, 0.4, 0.2] },
          { "type": "box", "min": [0.12, 0.12, 0.16], "max": [0.28, 0.28, 0.28] } ] } } ],
      "walls": [ { "kind": "container", "shape": { "type": "box", "min": [0, 0, 0], "max": [0.4, 0.4, 0.5] } } ],
      "porous_solids": [ { "shape": { "type": "box", "min": [0.12, 0.12, 0.16], "max": [0.28, 0.28, 0.28] },
                           "anchored": false, "material": { "porosity": 0, "solid_density": 500 } } ]
    })");
    sim.run_until(2.0);
    Real draft_sum = 0;
    int samples = 0;
    sim.run_until(3.0, [&] {
        if (sim.state.steps % 5) return;
        Real surface = 0;
        for (const auto& [x, y] : {std::pair{0.06, 0.2}, {0.2, 0.06}, {0.34, 0.2}, {0.2, 0.34}})
            surface += 0.25 * free_surface(sim.model, sim.state.fluid, x, y, 0.1, 0.3);
        draft_sum += surface - (lowest(sim.state.porous.particles.x) - 0.5 * k_dx), ++samples;
    });
    const Real draft = draft_sum / samples;
    EXPECT_NEAR(draft, 0.06, 0.05 * 0.06) << "mean draft over 2-3 s, m";
    const Fragment& box = sim.state.porous.fragments[0];
    EXPECT_LT((box.centre.head<2>() - Vec3(0.2, 0.2, 0).head<2>()).norm(), 0.5 * k_dx)
        << "it stays in the middle";
    EXPECT_EQ(sim.state.porous.absorbed, 0) << "an impermeable box takes no water";
}

// A box of dry bulk density (1 - 0.5) 1500 = 750 kg/m^3 would float with its bottom near
// z = 0.15 m; soaking up water (to 1250 kg/m^3) it sinks to the floor.
TEST(Coupling, LightPorousBoxSoaksUpWaterAndSinks) {
    ThreadLimit one(1);
    test::Simulation sim(R"({
      "name": "sink", "particle_spacing": 0.02,
      "fluid": { "artificial_viscosity": 0.02 },
      "fluid_blocks": [ { "shape": { "type": "difference", "shapes": [
          { "type": "box", "min": [0, 0, 0], "max": [0.4, 0.4, 0.24] },
          { "type": "box", "min": [0.12, 0.12, 0.18], "max": [0.28, 0.28, 0.3] } ] } } ],
      "walls": [ { "kind": "container", "shape": { "type": "box", "min": [0, 0, 0], "max": [0.4, 0.4, 0.5] } } ],
      "porous_solids": [ { "shape": { "type": "box", "min": [0.12, 0.12, 0.18], "max": [0.28, 0.28, 0.3] },
                           "anchored": false,
                           "material": { "porosity": 0.5, "solid_density": 1500, "permeability": 2e-7,
                                         "capillary_pressure": 5000, "dissolution_porosity": 1 } } ]
    })");
    const Real capacity = 1000 * 0.5 * 0.16 * 0.16 * 0.12;  // pore volume of the box, kg of water
    sim.run_until(2.5);
    Real absorbed = 0;
    for (Real m : sim.state.porous.particles.absorbed_mass) absorbed += m;
    EXPECT_GT(absorbed, 0.9 * capacity) << "kg";
    EXPECT_LT(lowest(sim.state.porous.particles.x) - 0.5 * k_dx, k_dx)
        << "the box rests on the floor";
}

// Issue 11's sinking block: an impermeable box of density 1500 kg/m^3 sinks through 0.12 m of
// water onto the floor and comes to rest there, the water settling around it. The fluid
// pressure and the box's answer are solved together (coupling/fragment_response.hpp); solved
// apart, the water under a landing box was squeezed without the box slowing, and was still
// moving at 0.4 m/s after 2 s.
TEST(Coupling, AHeavyBoxSinksToTheFloorAndTheWaterSettles) {
    ThreadLimit one(1);
    test::Simulation sim(R"({
      "name": "heavy", "particle_spacing": 0.02,
      "fluid_blocks": [ { "shape": { "type": "difference", "shapes": [
          { "type": "box", "min": [0, 0, 0], "max": [0.4, 0.4, 0.24] },
          { "type": "box", "min": [0.14, 0.14, 0.12], "max": [0.26, 0.26, 0.3] } ] } } ],
      "walls": [ { "kind": "container", "shape": { "type": "box", "min": [0, 0, 0], "max": [0.4, 0.4, 0.5] } } ],
      "porous_solids": [ { "shape": { "type": "box", "min": [0.14, 0.14, 0.12], "max": [0.26, 0.26, 0.24] },
                           "anchored": false, "material": { "porosity": 0, "solid_density": 1500 } } ]
    })");
    const Index n0 = sim.state.fluid.size();
    sim.run_until(2.0);
    EXPECT_LT(lowest(sim.state.porous.particles.x) - 0.5 * k_dx, 0.5 * k_dx)
        << "the box rests on the floor";
    const auto [p99, fastest] = fluid_speed_p99_and_max(sim.state.fluid);
    EXPECT_LT(p99, 0.1) << "m/s: the water has settled";
    EXPECT_LT(fastest, 0.3) << "m/s";
    EXPECT_EQ(sim.state.fluid.size(), n0) << "no water lost";
}

// A thin plate (8 x 8 x 1 members) dropped 4 cm onto the floor at a fixed 5 ms step: its 64
// contact springs are four times as stiff and damped as the contact law's one face of N^(2/3)
// members, so one explicit step per 5 ms rang up and threw it out of the tank. The contacts
// take sub-steps below their stiffest mode: it lands and rests, and never gains energy.
TEST(Coupling, AThinPlateDroppedOnTheFloorRestsWithoutGainingEnergy) {
    test::Simulation sim(R"({
      "name": "plate", "particle_spacing": 0.02, "time": { "fixed_dt": 0.005 },
      "walls": [ { "kind": "container", "shape": { "type": "box", "min": [0, 0, 0], "max": [0.4, 0.4, 0.3] } } ],
      "porous_solids": [ { "shape": { "type": "box", "min": [0.12, 0.12, 0.06], "max": [0.28, 0.28, 0.08] },
                           "anchored": false, "material": { "porosity": 0, "solid_density": 2000 } } ]
    })");
    const Real e0 = mechanical_energy(sim.model, sim.state).total();
    Real highest = e0;
    sim.run_until(
        1.0, [&] { highest = std::max(highest, mechanical_energy(sim.model, sim.state).total()); });
    EXPECT_LE(highest, e0) << "J";
    ASSERT_EQ(sim.state.porous.size(), 64) << "the plate stays in the tank";
    EXPECT_LT(sim.state.porous.fragments[0].velocity.norm(), 1e-3) << "m/s: at rest";
    EXPECT_NEAR(lowest(sim.state.porous.particles.x), 0.5 * k_dx, 0.05 * k_dx)
        << "on the floor (its members rest a spacing above the wall particles at -dx/2)";
}

// A 1000-member block dropped 4 cm beside a one-member crumb: the contact law of the lightest
// fragment (the crumb's, ten times softer per face) let the block sink a tenth of a spacing into
// the floor at rest, and through it on a harder landing. Each fragment has its own law: the block
// rests where the plate does, and nothing gains energy beyond the contact sub-steps' own error:
// with the springs' energy in the total, a landing measured between explicit sub-steps reads a
// few tenths of a per cent of the energy released above its start.
TEST(Coupling, ABlockBesideACrumbRestsOnTheFloorAtItsOwnContactStiffness) {
    test::Simulation sim(R"({
      "name": "block_and_crumb", "particle_spacing": 0.02, "time": { "fixed_dt": 0.002 },
      "walls": [ { "kind": "container", "shape": { "type": "box", "min": [0, 0, 0], "max": [0.4, 0.4, 0.4] } } ],
      "porous_solids": [
        { "shape": { "type": "box", "min": [0.04, 0.04, 0.04], "max": [0.24, 0.24, 0.24] },
          "anchored": false, "material": { "porosity": 0, "solid_density": 2000 } },
        { "shape": { "type": "box", "min": [0.32, 0.32, 0.0], "max": [0.34, 0.34, 0.02] },
          "anchored": false, "material": { "porosity": 0, "solid_density": 2000 } } ]
    })");
    ASSERT_EQ(sim.state.porous.size(), 1001);
    const Real e0 = mechanical_energy(sim.model, sim.state).total();
    Real highest = e0, lowest_e = e0;
    sim.run_until(1.0, [&] {
        const Real e = mechanical_energy(sim.model, sim.state).total();
        highest = std::max(highest, e), lowest_e = std::min(lowest_e, e);
    });
    EXPECT_LE(highest, e0 + 0.005 * (e0 - lowest_e)) << "J";
    const PorousParticles& p = sim.state.porous.particles;
    std::vector<Vec3> block;
    for (Index i = 0; i < p.size(); ++i)
        if (p.fragment[i] == 0) block.push_back(p.x[i]);
    ASSERT_EQ(block.size(), 1000u);
    EXPECT_LT(sim.state.porous.fragments[0].velocity.norm(), 1e-3) << "m/s: at rest";
    EXPECT_NEAR(lowest(block), 0.5 * k_dx, 0.05 * k_dx) << "m: on the floor, not in it";
}

// No gravity, no fluid: a free fragment keeps its momentum, its angular momentum and its shape,
// and its quaternion stays unit (docs/method.md §4.5).
TEST(Coupling, FreeFragmentInVacuumConservesMomentumAndKeepsItsShape) {
    test::Simulation sim(R"({
      "name": "vacuum", "particle_spacing": 0.02, "gravity": [0, 0, 0],
      "domain": { "min": [-0.2, -0.3, -0.2], "max": [0.5, 0.3, 0.4] },
      "time": { "fixed_dt": 0.001 },
      "porous_solids": [ { "shape": { "type": "box", "min": [0, 0, 0], "max": [0.1, 0.08, 0.06] },
                           "anchored": false, "velocity": [0.3, -0.1, 0.2], "angular_velocity": [2, -5, 7] } ]
    })");
    // Linear momentum from the members; angular momentum about the origin from the fragment,
    // c x M v + L (L includes each member's own spin, m s^2 / 6 omega).
    auto totals = [&] {
        const PorousParticles& p = sim.state.porous.particles;
        Vec3 momentum = Vec3::Zero();
        for (Index k = 0; k < p.size(); ++k)
            momentum += (p.solid_mass[k] + p.absorbed_mass[k]) * p.v[k];
        const Fragment& f = sim.state.porous.fragments[0];
        return std::pair{momentum, Vec3(f.centre.cross(f.mass * f.velocity) + f.angular_momentum)};
    };
    const auto [p0, l0] = totals();
    const Vec3 a0 = sim.state.porous.particles.x[0], b0 = sim.state.porous.particles.x.back();
    sim.run_until(1.0);
    const auto [p1, l1] = totals();
    EXPECT_LT((p1 - p0).norm(), 1e-12 * p0.norm());
    EXPECT_LT((l1 - l0).norm(), 1e-12 * l0.norm()) << "about the origin";
    EXPECT_NEAR(sim.state.porous.fragments[0].rotation.norm(), 1.0, 1e-14);
    const std::vector<Vec3>& x = sim.state.porous.particles.x;
    EXPECT_NEAR((x.back() - x[0]).norm(), (b0 - a0).norm(), 1e-12) << "rigid";
    EXPECT_GT(sim.state.porous.fragments[0].rotation.vec().norm(), 0.1) << "it did turn";
}

// No gravity, no walls: a blob of water hits a free impermeable box. Pressure, friction and
// adhesion reactions go to the fragment pair by pair, so the total momentum is kept to round-off.
TEST(Coupling, FluidAndFragmentExchangeMomentumExactly) {
    ThreadLimit one(1);
    test::Simulation sim(R"({
      "name": "impact", "particle_spacing": 0.02, "gravity": [0, 0, 0],
      "domain": { "min": [-1, -1, -1], "max": [1, 1, 1] },
      "fluid": { "wall_friction": 0.2, "adhesion": 0.5, "viscosity": 1e-4 },
      "fluid_blocks": [ { "shape": { "type": "sphere", "center": [0, 0, 0], "radius": 0.08 }, "velocity": [1.5, 0.2, 0] } ],
      "porous_solids": [ { "shape": { "type": "box", "min": [0.12, -0.1, -0.06], "max": [0.18, 0.1, 0.06] },
                           "anchored": false, "material": { "porosity": 0, "solid_density": 800 } } ]
    })");
    auto momentum = [&] {
        Vec3 sum = Vec3::Zero();
        for (Index i = 0; i < sim.state.fluid.size(); ++i)
            sum += sim.state.fluid.mass[i] * sim.state.fluid.v[i];
        for (const Fragment& f : sim.state.porous.fragments) sum += f.mass * f.velocity;
        return sum;
    };
    const Vec3 p0 = momentum();
    sim.run_until(0.2);
    EXPECT_GT(sim.state.porous.fragments[0].velocity[0], 0.1) << "m/s: the box was hit";
    EXPECT_LT((momentum() - p0).norm(), 1e-12 * p0.norm());
}

// Water poured on a highly porous block for 2 s: it soaks in, drained fluid particles are
// deleted and saturated surface particles dissolve, and stats.json shows water (fluid less solute
// and drained water, plus pore water) and grains (solute plus solid) conserved to 1e-12.
TEST(Coupling, SoakKeepsWaterAndGrainsThroughAbsorptionDrainingAndDissolution) {
    const std::filesystem::path out = std::filesystem::temp_directory_path() / "karst_test_soak";
    RunOptions options;
    options.out_dir = out, options.quiet = true;
    const RunResult r = run_simulation(parse_scene(R"({
      "name": "soak", "particle_spacing": 0.02, "time": { "end": 2.0 },
      "fluid_blocks": [ { "shape": { "type": "box", "min": [0.04, 0.04, 0.12], "max": [0.24, 0.24, 0.2] } } ],
      "walls": [ { "kind": "container", "shape": { "type": "box", "min": [0, 0, 0], "max": [0.28, 0.28, 0.4] } } ],
      "porous_solids": [ { "shape": { "type": "box", "min": [0.04, 0.04, 0], "max": [0.24, 0.24, 0.1] },
                           "material": { "porosity": 0.7 } } ],
      "output": { "fps": 5 }
    })"),
                                       options);
    ASSERT_TRUE(r.ok) << r.failure;
    const auto stats = nlohmann::json::parse(test::read_text(out / "stats.json"));
    const auto& mass = stats["mass"];
    EXPECT_GT(mass["absorbed"].get<double>(), 0.5) << "kg soaked in";
    EXPECT_GT(stats["counts"]["fluid_drained"].get<int>(), 10);
    EXPECT_GT(stats["counts"]["dissolved"].get<int>(), 10);
    EXPECT_GT(mass["solute_final"].get<double>(), 0.1) << "kg of grains in the muddy water";
    const double water0 = mass["water_initial"], water1 = mass["water_final"];
    const double grains0 = mass["grains_initial"], grains1 = mass["grains_final"];
    EXPECT_NEAR(water1, water0, 1e-12 * water0);
    EXPECT_NEAR(grains1, grains0, 1e-12 * grains0);
    EXPECT_EQ(stats["counts"]["fragments"], 1);
    EXPECT_TRUE(std::filesystem::exists(out / "porous_0010.vtp"));
    EXPECT_NE(test::read_text(out / "run.pvd").find("part=\"3\" file=\"porous_0010.vtp\""),
              std::string::npos);
    std::filesystem::remove_all(out);
}

// Absorption, draining and dissolution give the same particles on one thread and on two: every
// scatter over pairs runs in a fixed order.
TEST(Coupling, SoakIsIdenticalOnOneAndTwoThreads) {
    const std::string scene = R"({
      "name": "soak", "particle_spacing": 0.02,
      "fluid_blocks": [ { "shape": { "type": "box", "min": [0.04, 0.04, 0.12], "max": [0.24, 0.24, 0.2] } } ],
      "walls": [ { "kind": "container", "shape": { "type": "box", "min": [0, 0, 0], "max": [0.28, 0.28, 0.4] } } ],
      "porous_solids": [ { "shape": { "type": "box", "min": [0.04, 0.04, 0], "max": [0.24, 0.24, 0.1] },
                           "material": { "porosity": 0.7 }, "layering": { "ratio": 4 } } ]
    })";
    auto run = [&](int threads) {
        ThreadLimit limit(threads);
        test::Simulation sim(scene);
        sim.run_until(0.8);
        return std::pair{sim.state.fluid, sim.state.porous.particles};
    };
    const auto [fluid1, porous1] = run(1);
    const auto [fluid2, porous2] = run(2);
    ASSERT_EQ(fluid1.size(), fluid2.size());
    EXPECT_EQ(fluid1.x, fluid2.x);
    EXPECT_EQ(fluid1.drained, fluid2.drained);
    ASSERT_EQ(porous1.size(), porous2.size());
    EXPECT_EQ(porous1.absorbed_mass, porous2.absorbed_mass);
}

// The shipped demo (scenes/cave_soak.json) runs, soaks and keeps its water; its anisotropy is
// measured in issue 3's closing note (a pour is too chaotic for a tight test of it).
TEST(Coupling, CaveSoakDemoSoaksAndKeepsItsWater) {
    test::Simulation sim(test::read_text(std::string(KARST_SOURCE_DIR) + "/scenes/cave_soak.json"));
    auto water = [&] {
        Real sum = 0;
        const FluidParticles& f = sim.state.fluid;
        for (Index i = 0; i < f.size(); ++i) sum += f.water(i);
        for (Real m : sim.state.porous.particles.absorbed_mass) sum += m;
        return sum;
    };
    const Real w0 = water();
    sim.run_until(0.6);
    EXPECT_GT(sim.state.porous.absorbed, 0.5) << "kg soaked in";
    EXPECT_NEAR(water(), w0, 1e-12 * w0);
}

// The shipped dissolution demo (scenes/dissolving_mound.json): a dam break soaks a loose,
// porosity-0.75 mound past its dissolution saturation and washes most of it into muddy water,
// with the grains conserved and no energy made.
TEST(Coupling, DissolvingMoundDemoTurnsMostOfTheMoundIntoMud) {
    const std::filesystem::path out = std::filesystem::temp_directory_path() / "karst_test_mound";
    RunOptions options;
    options.out_dir = out, options.quiet = true;
    const RunResult r =
        run_simulation(parse_scene(test::read_text(std::string(KARST_SOURCE_DIR) +
                                                   "/scenes/dissolving_mound.json")),
                       options);
    ASSERT_TRUE(r.ok) << r.failure;
    const auto& stats = r.stats;
    const int porous0 = 432;  // 8 x 9 x 6 lattice sites
    EXPECT_GT(stats["counts"]["dissolved"].get<int>(), porous0 / 2);
    const double grains0 = stats["mass"]["grains_initial"], grains1 = stats["mass"]["grains_final"];
    EXPECT_NEAR(grains1, grains0, 1e-12 * grains0);
    EXPECT_GT(stats["mass"]["solute_final"].get<double>(), 0.5 * grains0);
    EXPECT_LT(stats["energy"]["largest_gain"].get<double>(),
              0.05 * stats["energy"]["released"].get<double>());
    std::filesystem::remove_all(out);
}

// The same mound anchored: dissolution leaves islands that no wall holds; their Biot problem
// has no fixed node, so the fluid's net load on them is taken by the anchor (pfem/load_balance.hpp)
// instead of moving them metres (the run stopped at 0.70 s with fluid at 190 m/s).
TEST(Coupling, AnAnchoredMoundDissolvesWithoutItsLastIslandsFlyingOff) {
    const std::filesystem::path out =
        std::filesystem::temp_directory_path() / "karst_test_anchored";
    std::string text =
        test::read_text(std::string(KARST_SOURCE_DIR) + "/scenes/dissolving_mound.json");
    const std::string loose = "\"anchored\": false";
    const size_t at = text.find(loose);
    ASSERT_NE(at, std::string::npos);
    text.replace(at, loose.size(), "\"anchored\": true");
    RunOptions options;
    options.out_dir = out, options.quiet = true;
    const RunResult r = run_simulation(parse_scene(text), options);
    ASSERT_TRUE(r.ok) << r.failure;
    EXPECT_GT(r.stats["counts"]["dissolved"].get<int>(), 432 / 2);
    EXPECT_GT(r.stats["biot"]["remeshes"].get<int>(), 3);
    EXPECT_LT(r.stats["energy"]["largest_gain"].get<double>(),
              0.05 * r.stats["energy"]["released"].get<double>());
    std::filesystem::remove_all(out);
}

}  // namespace
}  // namespace karst
