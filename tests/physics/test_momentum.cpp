// A free blob (no gravity, no walls) keeps its linear momentum to round-off: every pair force
// (pressure, viscosity, cohesion, curvature) is exactly antisymmetric.
#include "support/simulate.hpp"

#include "karst/core/parallel.hpp"

#include <gtest/gtest.h>

namespace karst {
namespace {

TEST(Momentum, FreeBlobConservesLinearMomentum) {
    test::Simulation sim(R"({
      "name": "blob", "particle_spacing": 0.02, "gravity": [0, 0, 0],
      "domain": { "min": [-2, -2, -2], "max": [2, 2, 2] },
      "fluid": { "viscosity": 1e-3, "surface_tension": 0.5 },
      "fluid_blocks": [ { "shape": { "type": "sphere", "center": [0, 0, 0], "radius": 0.12 },
                          "velocity": [0.3, -0.2, 0.1] } ]
    })");
    // Add a swirl and a squeeze so pressure, viscosity and surface tension all act.
    FluidParticles& f = sim.state.fluid;
    for (Index i = 0; i < f.size(); ++i) {
        const Vec3 x = f.x[i];
        f.v[i] += Vec3(-x[1], x[0], 0) * 5.0 + x * -3.0 +
                  Vec3(std::sin(40 * x[2]), 0, std::cos(30 * x[0])) * 0.1;
    }
    auto momentum = [&] {
        Vec3 p = Vec3::Zero();
        for (Index i = 0; i < f.size(); ++i) p += f.mass[i] * f.v[i];
        return p;
    };
    auto scale = [&] {
        Real s = 0;
        for (Index i = 0; i < f.size(); ++i) s += f.mass[i] * f.v[i].norm();
        return s;
    };
    const Vec3 p0 = momentum();
    const Real s0 = scale();
    for (int k = 0; k < 60; ++k) sim.advance();
    EXPECT_EQ(sim.state.removed, 0);
    EXPECT_GT(sim.max_density_error, 0.0);  // the squeeze made the pressure solve work
    EXPECT_LT((momentum() - p0).norm(), 1e-13 * s0)
        << "momentum drift " << (momentum() - p0).transpose();
}

}  // namespace
}  // namespace karst
