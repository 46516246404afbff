// The same particle arrays, bit for bit, after 100 steps on 1 and 2 threads (style.md P5).
#include "support/simulate.hpp"

#include "karst/core/parallel.hpp"

#include <gtest/gtest.h>

#include <cstring>

namespace karst {
namespace {

const char* k_scene = R"({
  "name": "determinism", "particle_spacing": 0.025,
  "fluid": { "viscosity": 1e-4, "surface_tension": 0.1, "adhesion": 0.1, "wall_friction": 0.05 },
  "fluid_blocks": [ { "shape": { "type": "box", "min": [0, 0, 0], "max": [0.3, 0.3, 0.4] } } ],
  "walls": [ { "kind": "container", "shape": { "type": "box", "min": [0, 0, 0], "max": [0.8, 0.3, 0.5] } },
             { "shape": { "type": "sphere", "center": [0.55, 0.15, 0.0], "radius": 0.1 } } ],
  "numerics": { "sort_interval": 7 }
})";

FluidParticles run(int threads) {
    ThreadLimit limit(threads);
    test::Simulation sim(k_scene);
    for (int k = 0; k < 100; ++k) sim.advance();
    return sim.state.fluid;
}

template <class T>
bool same_bits(const std::vector<T>& a, const std::vector<T>& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0;
}

TEST(Determinism, OneAndTwoThreadsGiveIdenticalArrays) {
    const FluidParticles one = run(1), two = run(2);
    ASSERT_GT(one.size(), 1000);
    EXPECT_TRUE(same_bits(one.id, two.id));
    EXPECT_TRUE(same_bits(one.x, two.x));
    EXPECT_TRUE(same_bits(one.v, two.v));
    EXPECT_TRUE(same_bits(one.p, two.p));
    EXPECT_TRUE(same_bits(one.rho, two.rho));
}

}  // namespace
}  // namespace karst
