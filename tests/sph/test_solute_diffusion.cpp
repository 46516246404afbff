// Solute diffusion among fluid particles (docs/method.md §4.9, M18): two half-spaces follow the erf
// profile, and solute is conserved to round-off, also in a moving flow.
#include "support/simulate.hpp"

#include "karst/core/parallel.hpp"
#include "karst/sph/density.hpp"
#include "karst/sph/fluid_neighbours.hpp"
#include "karst/sph/solute_diffusion.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <map>

namespace karst {
namespace {

Real total_solute(const FluidParticles& f) {
    return deterministic_sum(f.size(), Real(0), [&](Index i) { return f.solute[i]; });
}

/// Two halves of a 0.4 x 0.1 x 0.1 m box at C = 1 and 0, without gravity, diffusing with D: the
/// operator alone, on particles at rest (neighbour lists and densities once).
test::Simulation two_halves(Real dx, Real D) {
    test::Simulation sim(fmt::format(R"({{
      "name": "halves", "particle_spacing": {}, "gravity": [0, 0, 0],
      "fluid": {{ "solute_diffusivity": {} }},
      "fluid_blocks": [
        {{ "shape": {{ "type": "box", "min": [0, 0, 0], "max": [0.2, 0.1, 0.1] }}, "concentration": 1 }},
        {{ "shape": {{ "type": "box", "min": [0.2, 0, 0], "max": [0.4, 0.1, 0.1] }} }} ]
    }})",
                                     dx, D));
    update_fluid_neighbours(sim.model, sim.state);
    update_density(sim.model, sim.state);
    return sim;
}

TEST(SoluteDiffusion, TwoHalfSpacesFollowTheErfProfile) {
    ThreadLimit one(1);
    const Real D = 1e-4, t = 10;
    test::Simulation sim = two_halves(0.01, D);
    const Real before = total_solute(sim.state.fluid);
    for (int k = 0; k < 10; ++k) diffuse_solute(sim.model, sim.state, t / 10);
    const FluidParticles& f = sim.state.fluid;
    EXPECT_LT(std::abs(total_solute(f) - before) / before, 1e-12);
    // Mean C per lattice column in x against C = erfc((x - 0.2) / (2 sqrt(D t))) / 2.
    std::map<int, std::pair<Real, int>> columns;
    for (Index i = 0; i < f.size(); ++i) {
        auto& [sum, count] = columns[int(std::floor(f.x[i][0] / 0.01))];
        sum += f.solute[i] / f.mass[i], ++count;
    }
    Real worst = 0;
    for (const auto& [column, acc] : columns) {
        const Real x = (column + 0.5) * 0.01,
                   exact = 0.5 * std::erfc((x - 0.2) / (2 * std::sqrt(D * t)));
        worst = std::max(worst, std::abs(acc.first / acc.second - exact));
    }
    EXPECT_LT(worst, 0.01) << "largest deviation from the erf profile (of a unit jump)";
    EXPECT_GT(columns.at(22).first / columns.at(22).second, 0.1) << "solute crossed the interface";
}

TEST(SoluteDiffusion, TheLargestDiffusivityKeepsEveryConcentrationWithinItsStartingRange) {
    // D = 1 m^2/s, the scene's upper limit, over 5 ms steps at dx 0.02: the explicit operator
    // needs sub-steps below about 0.35 dx^2 / D, and the old 0.4 dx^2 / D diverged to infinities.
    ThreadLimit one(1);
    test::Simulation sim = two_halves(0.02, 1);
    const Real before = total_solute(sim.state.fluid);
    for (int k = 0; k < 10; ++k) diffuse_solute(sim.model, sim.state, 0.005);
    const FluidParticles& f = sim.state.fluid;
    EXPECT_LT(std::abs(total_solute(f) - before) / before, 1e-12);
    Real lowest = 1, highest = 0;
    for (Index i = 0; i < f.size(); ++i) {
        lowest = std::min(lowest, f.solute[i] / f.mass[i]);
        highest = std::max(highest, f.solute[i] / f.mass[i]);
    }
    EXPECT_GE(lowest, 0.0);
    EXPECT_LE(highest, 1.0);
    EXPECT_GT(lowest, 0.1) << "at D t = 0.05 m^2 the two halves have nearly mixed";
    // A step that would need more than k_max_diffusion_substeps is not taken (the run stops).
    const std::vector<Real> kept = f.solute;
    EXPECT_GT(diffuse_solute(sim.model, sim.state, 1.0), k_max_diffusion_substeps);
    EXPECT_EQ(f.solute, kept);
}

TEST(SoluteDiffusion, SoluteIsConservedInAMovingFlow) {
    ThreadLimit one(1);
    test::Simulation sim(R"({
      "name": "muddy_dam", "particle_spacing": 0.02,
      "fluid": { "solute_diffusivity": 1e-3 },
      "fluid_blocks": [
        { "shape": { "type": "box", "min": [0, 0, 0], "max": [0.1, 0.2, 0.3] }, "concentration": 0.3 },
        { "shape": { "type": "box", "min": [0.1, 0, 0], "max": [0.2, 0.2, 0.3] } } ],
      "walls": [ { "kind": "container", "shape": { "type": "box", "min": [0, 0, 0], "max": [0.6, 0.2, 0.5] } } ]
    })");
    const Real before = total_solute(sim.state.fluid);
    sim.run_until(0.3);
    const FluidParticles& f = sim.state.fluid;
    EXPECT_LT(std::abs(total_solute(f) - before) / before, 1e-12);
    for (Index i = 0; i < f.size(); ++i) {
        ASSERT_GE(f.solute[i] / f.mass[i], -1e-12);
        ASSERT_LE(f.solute[i] / f.mass[i], 0.3 + 1e-12);
    }
}

}  // namespace
}  // namespace karst
