// Issue 11: water that hits things without gaining energy, and is never lost through a wall.
// Drops at default settings (DFSPH, CFL step up to dt_max 5 ms, free-slip walls): kinetic +
// potential energy never rises above its start by more than 2 % of the energy released, the
// fastest 1 % of the water stays below 3 sqrt(2 g H) + 1 m/s, and no particle leaves.
#include "support/simulate.hpp"

#include "karst/core/parallel.hpp"
#include "karst/sim/energy.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace karst {
namespace {

struct ImpactFigures {
    Real worst_rise = 0;   ///< max over steps of (E - E0) / released
    Real fastest_p99 = 0;  ///< m/s
    Index removed = 0;
    Index particles_lost = 0;
    Real compression_p99 = 0;  ///< max over steps of the 99th percentile of rho / rho0 - 1
};

/// The 99th percentile of the fluid's rho / rho0 - 1 (the densities of the last step).
Real compression_p99(const test::Simulation& sim) {
    std::vector<Real> rho = sim.state.fluid.rho;
    if (rho.empty()) return 0;
    auto at = rho.begin() + std::ptrdiff_t(0.99 * Real(rho.size() - 1));
    std::nth_element(rho.begin(), at, rho.end());
    return *at / sim.model.rho0 - 1;
}

ImpactFigures drop(const std::string& scene, Real end) {
    ThreadLimit one(1);
    test::Simulation sim(scene);
    const Index n0 = sim.state.fluid.size();
    EnergyAccount account(mechanical_energy(sim.model, sim.state));
    const Real e0 = mechanical_energy(sim.model, sim.state).total();
    ImpactFigures r;
    sim.run_until(end, [&] {
        const Energy e = mechanical_energy(sim.model, sim.state);
        account.add(e);
        if (account.released() > 0)
            r.worst_rise = std::max(r.worst_rise, (e.total() - e0) / account.released());
        r.fastest_p99 = std::max(r.fastest_p99, fluid_speed_p99_and_max(sim.state.fluid).first);
        r.compression_p99 = std::max(r.compression_p99, compression_p99(sim));
    });
    r.removed = sim.state.removed;
    r.particles_lost = n0 - sim.state.fluid.size();
    return r;
}

const std::vector<std::string> k_solvers{"dfsph", "pcisph"};

/// An 8 x 8 x 8 block (dx 0.02) dropped 12 cm onto a flat floor; `fluid` adds /fluid keys,
/// `time` /time keys.
std::string block_on_floor(const std::string& fluid, const std::string& time) {
    return R"({ "name": "drop", "particle_spacing": 0.02, "fluid": { )" + fluid +
           R"( }, "time": { )" + time + R"( },
      "fluid_blocks": [ { "shape": { "type": "box", "min": [0.32, 0.32, 0.12], "max": [0.48, 0.48, 0.28] } } ],
      "walls": [ { "kind": "container", "shape": { "type": "box", "min": [0, 0, 0], "max": [0.8, 0.8, 0.6] } } ] })";
}

// At the default step (CFL up to dt_max 5 ms) and tolerance, the strictest tolerance, and a
// 1 ms dt_max: a stricter tolerance or a shorter step must not make the impact worse.
TEST(Impacts, BlockDroppedOnAFloorGainsNoEnergy) {
    const Real H = 0.28, limit = 3 * std::sqrt(2 * 9.81 * H) + 1;
    for (const std::string& solver : k_solvers)
        for (const auto& [tolerance, dt_max] :
             {std::pair{"0.01", "0.005"}, {"1e-5", "0.005"}, {"0.01", "0.001"}}) {
            const std::string fluid =
                R"("solver": ")" + solver + R"(", "max_density_error": )" + tolerance;
            const std::string settings = fluid + ", dt_max " + dt_max;
            const ImpactFigures r =
                drop(block_on_floor(fluid, std::string(R"("dt_max": )") + dt_max), 0.8);
            EXPECT_LE(r.worst_rise, 0.02) << settings;
            EXPECT_LT(r.fastest_p99, limit) << settings;
            EXPECT_GT(r.fastest_p99, 0.5 * std::sqrt(2 * 9.81 * 0.12))
                << "the block must fall and splash";
            EXPECT_EQ(r.particles_lost, 0) << settings;
        }
}

// A shorter step never makes the impact worse: fixed steps far below the sound's crossing time
// dx / c_s (1 ms here), where a band read per step let the density solve release a whole
// compression in one step. Before the rate form (sph/integrate.hpp, solve_rate_fraction) a fixed
// 50 us step gained 104 % (DFSPH) and 180 % (PCISPH) of the energy released, 0.2 ms 11 % (PCISPH).
TEST(Impacts, BlockDroppedAtAShortFixedStepGainsNoEnergy) {
    const Real H = 0.28, limit = 3 * std::sqrt(2 * 9.81 * H) + 1;
    for (const std::string& solver : k_solvers)
        for (const char* dt : {"2e-4", "5e-5"}) {
            const std::string fluid = R"("solver": ")" + solver + R"(")";
            SCOPED_TRACE(solver + ", fixed_dt " + dt);
            const ImpactFigures r =
                drop(block_on_floor(fluid, std::string(R"("fixed_dt": )") + dt), 0.5);
            EXPECT_LE(r.worst_rise, 0.02);
            EXPECT_LT(r.fastest_p99, limit);
            EXPECT_GT(r.fastest_p99, 0.5 * std::sqrt(2 * 9.81 * 0.12));
            EXPECT_EQ(r.particles_lost, 0);
            // The compression is still removed (measured: 99th percentile 3.4-4.5 % at worst).
            EXPECT_LT(r.compression_p99, 0.06);
        }
}

// A viscous fluid steps at its viscous bound (0.1 ms for nu = 0.2 m^2/s at dx 0.02), far below
// the sound's crossing time: a 0.2 m block collapsing in a tank. DFSPH gained 48 % of the energy
// released before the rate form.
TEST(Impacts, AViscousCollapseGainsNoEnergy) {
    for (const std::string& solver : k_solvers) {
        SCOPED_TRACE(solver);
        const ImpactFigures r = drop(
            R"({ "name": "viscous", "particle_spacing": 0.02,
      "fluid": { "solver": ")" +
                solver + R"(", "viscosity": 0.2 },
      "fluid_blocks": [ { "shape": { "type": "box", "min": [0, 0, 0], "max": [0.2, 0.2, 0.2] } } ],
      "walls": [ { "kind": "container", "shape": { "type": "box", "min": [0, 0, 0], "max": [0.5, 0.2, 0.4] } } ] })",
            0.35);
        EXPECT_LE(r.worst_rise, 0.02);
        EXPECT_GT(r.fastest_p99, 0.1) << "the block must collapse";
        EXPECT_EQ(r.particles_lost, 0);
        EXPECT_LT(r.compression_p99, 0.03);  // measured 0.85 % (DFSPH), 0.03 % (PCISPH)
    }
}

/// A 10 x 10 x 8 block falling 0.4 m into a hemispherical bowl of radius 0.4 m.
TEST(Impacts, BlockDroppedIntoABowlGainsNoEnergy) {
    for (const std::string& solver : k_solvers)
        for (const char* tolerance : {"0.01", "1e-5"}) {
            SCOPED_TRACE(solver + " " + tolerance);
            const ImpactFigures r = drop(R"({ "name": "bowl", "particle_spacing": 0.02,
      "fluid": { "solver": ")" + solver + R"(", "max_density_error": )" +
                                             tolerance + R"( },
      "fluid_blocks": [ { "shape": { "type": "box", "min": [0.3, 0.3, 0.40], "max": [0.5, 0.5, 0.56] } } ],
      "walls": [ { "kind": "container", "shape": { "type": "union", "shapes": [
         { "type": "sphere", "center": [0.4, 0.4, 0.4], "radius": 0.4 },
         { "type": "box", "min": [0.0, 0.0, 0.4], "max": [0.8, 0.8, 0.8] } ] } } ] })",
                                         0.8);
            EXPECT_LE(r.worst_rise, 0.02);
            EXPECT_LT(r.fastest_p99, 3 * std::sqrt(2 * 9.81 * 0.56) + 1);
            EXPECT_EQ(r.particles_lost, 0);
        }
}

/// A 20 x 6 x 6 jet at 4 m/s against a side wall: the head of the limit is the jet's kinetic head
/// plus its height, H = v^2 / 2g + z.
TEST(Impacts, JetAgainstAWallGainsNoEnergy) {
    for (const std::string& solver : k_solvers) {
        SCOPED_TRACE(solver);
        const ImpactFigures r =
            drop(R"({ "name": "jet", "particle_spacing": 0.02, "fluid": { "solver": ")" + solver +
                     R"(" },
      "fluid_blocks": [ { "shape": { "type": "box", "min": [0.1, 0.3, 0.2], "max": [0.5, 0.42, 0.32] }, "velocity": [4, 0, 0] } ],
      "walls": [ { "kind": "container", "shape": { "type": "box", "min": [0, 0, 0], "max": [1.0, 0.8, 0.8] } } ] })",
                 0.5);
        const Real H = 16.0 / (2 * 9.81) + 0.32;
        EXPECT_LE(r.worst_rise, 0.02);
        EXPECT_LT(r.fastest_p99, 3 * std::sqrt(2 * 9.81 * H) + 1);
        EXPECT_EQ(r.particles_lost, 0);
    }
}

/// A stone sphere (2600 kg/m^3, radius 0.07 m) dropped 3 cm onto 0.2 m of water sinks and lands
/// on the floor, squeezing the water out from under it. Both solvers take the sphere's inertia
/// into their pressure solve (coupling/fragment_response.hpp); PCISPH without it gained 47-54 %
/// of the energy released as the sphere entered the water. Not yet at PCISPH's strictest
/// tolerance: there the water squeezed under the landing sphere is launched at 15 m/s (its 50
/// Jacobi iterations over-shoot the sphere's answer, which every squeezed particle pushes).
TEST(Impacts, ASinkingSphereLandsOnTheFloorGainingNoEnergy) {
    for (const auto& [solver, tolerance] :
         {std::pair{"dfsph", "0.01"}, {"dfsph", "1e-5"}, {"pcisph", "0.01"}}) {
        SCOPED_TRACE(std::string(solver) + " " + tolerance);
        const std::string scene = R"({ "name": "stone", "particle_spacing": 0.02,
      "fluid": { "solver": ")" + std::string(solver) +
                                  R"(", "max_density_error": )" + tolerance + R"( },
      "fluid_blocks": [ { "shape": { "type": "box", "min": [0, 0, 0], "max": [0.4, 0.4, 0.2] } } ],
      "walls": [ { "kind": "container", "shape": { "type": "box", "min": [0, 0, 0], "max": [0.4, 0.4, 0.5] } } ],
      "porous_solids": [ { "anchored": false, "shape": { "type": "sphere", "center": [0.2, 0.2, 0.3], "radius": 0.07 },
                           "material": { "porosity": 0, "solid_density": 2600 } } ] })";
        const ImpactFigures r = drop(scene, 0.6);
        EXPECT_LE(r.worst_rise, 0.02);
        EXPECT_LT(r.fastest_p99, 3 * std::sqrt(2 * 9.81 * 0.3) + 1);
        EXPECT_GT(r.fastest_p99, 0.2) << "m/s: the sphere must stir the water";
        EXPECT_EQ(r.particles_lost, 0);
    }
}

// A particle thrown at a wall with a step long enough to carry it through the wall skin is put
// back inside, with no outward velocity, and counted; nothing is deleted.
TEST(Impacts, AParticleThatCrossesAWallIsPutBackNotLost) {
    test::Simulation sim(
        R"({ "name": "throw", "particle_spacing": 0.02, "time": { "fixed_dt": 0.01 },
      "fluid_blocks": [ { "shape": { "type": "box", "min": [0.2, 0.2, 0.2], "max": [0.22, 0.22, 0.22] }, "velocity": [-30, 0, 0] } ],
      "walls": [ { "kind": "container", "shape": { "type": "box", "min": [0, 0, 0], "max": [0.4, 0.4, 0.4] } } ] })");
    sim.advance();
    ASSERT_EQ(sim.state.fluid.size(), 1);
    EXPECT_EQ(sim.state.pushed_back, 1);
    EXPECT_NEAR(sim.state.fluid.x[0][0], 0.25 * 0.02, 1e-12);
    EXPECT_GE(sim.state.fluid.v[0][0], 0.0);
    EXPECT_EQ(sim.state.removed, 0);
}

TEST(EnergyAccount, ReleasedIsStartingKineticPlusLargestPotentialDrop) {
    EnergyAccount a({2, 10});
    a.add({5, 6});  // fell 4 J, 1 J lost
    EXPECT_DOUBLE_EQ(a.released(), 6);
    EXPECT_FALSE(a.gained_more_than(0.05));
    a.add({6, 6});  // 1 J made from nothing: 1/6 of what was released
    EXPECT_DOUBLE_EQ(a.largest_gain(), 1);
    EXPECT_NEAR(a.worst_ratio(), 1.0 / 6, 1e-15);
    EXPECT_TRUE(a.gained_more_than(0.05));
    EXPECT_DOUBLE_EQ(a.largest_rise_over_start(), 0);
}

TEST(EnergyAccount, AGainWithNothingReleasedIsReported) {
    EnergyAccount a({0, 80});
    a.add({0, 80});
    a.add({1e-7, 80});  // round-off of an 80 J account
    EXPECT_FALSE(a.gained_more_than(0.05));
    a.add({3.9, 80});  // a dissolving block that made 3.9 J while nothing fell
    EXPECT_DOUBLE_EQ(a.released(), 0);
    EXPECT_TRUE(a.gained_more_than(0.05));
    // Water at z = 0 in zero gravity: nothing to scale round-off by; under 1 mJ is not
    // reported.
    EnergyAccount b({0, 0});
    b.add({5e-4, 0});
    EXPECT_FALSE(b.gained_more_than(0.05));
    b.add({2e-3, 0});
    EXPECT_TRUE(b.gained_more_than(0.05));
}

// A solid at rest whose potential energy moves by round-off both ways (568 J, 1e-15 of it): what
// it "releases" is round-off too, and the gain that follows is no share of it.
TEST(EnergyAccount, RoundOffAfterARoundOffReleaseIsNoGain) {
    EnergyAccount a({0, 568.673438});
    a.add({0, 568.673438 - 6.8e-13});
    a.add({0, 568.673438 - 3.4e-13});
    EXPECT_GT(a.released(), 0);
    EXPECT_FALSE(a.gained_more_than(0.05));
    a.add({0, 568.673438 + 1e-5});  // a real gain, above the sum's round-off
    EXPECT_TRUE(a.gained_more_than(0.05));
}

}  // namespace
}  // namespace karst
