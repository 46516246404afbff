// The same arrays, bit for bit, on 1 and 2 threads (style.md P5): a fluid run of 100 steps, and
// a coupled run with Biot calls and a remesh. An observer checks that two threads really ran.
#include "support/simulate.hpp"

#include "karst/core/parallel.hpp"

#include <gtest/gtest.h>
#include <tbb/task_scheduler_observer.h>

#include <cstring>
#include <mutex>
#include <set>
#include <thread>

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

/// Counts the threads that run karst's parallel loops while it lives.
class ThreadCounter : public tbb::task_scheduler_observer {
public:
    ThreadCounter() { observe(true); }
    ~ThreadCounter() override { observe(false); }
    void on_scheduler_entry(bool) override {
        std::lock_guard lock(m_mutex);
        m_ids.insert(std::this_thread::get_id());
    }
    size_t count() {
        std::lock_guard lock(m_mutex);
        return m_ids.size();
    }

private:
    std::mutex m_mutex;
    std::set<std::thread::id> m_ids;
};

struct Outcome {
    State state;
    size_t threads_seen = 0;
};

Outcome run(const std::string& scene, int threads, int steps) {
    ThreadLimit limit(threads);
    ThreadCounter counter;
    test::Simulation sim(scene);
    for (int k = 0; k < steps; ++k) sim.advance();
    return {std::move(sim.state), counter.count()};
}

template <class T>
bool same_bits(const std::vector<T>& a, const std::vector<T>& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0;
}

TEST(Determinism, OneAndTwoThreadsGiveIdenticalArrays) {
    const Outcome a = run(k_scene, 1, 100), b = run(k_scene, 2, 100);
    EXPECT_GE(b.threads_seen, 2u) << "the parallel runtime used one thread";
    const FluidParticles &one = a.state.fluid, &two = b.state.fluid;
    ASSERT_GT(one.size(), 1000);
    ASSERT_EQ(a.state.steps, b.state.steps);
    EXPECT_TRUE(same_bits(one.id, two.id));
    EXPECT_TRUE(same_bits(one.x, two.x));
    EXPECT_TRUE(same_bits(one.v, two.v));
    EXPECT_TRUE(same_bits(one.p, two.p));
    EXPECT_TRUE(same_bits(one.rho, two.rho));
}

TEST(Determinism, ACoupledRunWithBiotCallsAndARemeshIsIdenticalOnOneAndTwoThreads) {
    // Water on a jelly-soft anchored block (E = 1 kPa): the Biot calls flatten its elements and
    // it is remeshed on its deformed shape (§4.10).
    const std::string scene = R"({
      "name": "coupled_determinism", "particle_spacing": 0.02, "time": { "fixed_dt": 0.002 },
      "fluid": { "artificial_viscosity": 0.02 },
      "fluid_blocks": [ { "shape": { "type": "box", "min": [0, 0, 0.06], "max": [0.4, 0.4, 0.16] } } ],
      "walls": [ { "kind": "container", "shape": { "type": "box", "min": [0, 0, 0], "max": [0.4, 0.4, 0.4] } } ],
      "porous_solids": [ { "shape": { "type": "box", "min": [0, 0, 0], "max": [0.4, 0.4, 0.06] },
                           "material": { "porosity": 0.3, "permeability": 1e-9, "initial_saturation": 1,
                                         "youngs_modulus": 1e3, "poisson_ratio": 0.25, "absorption_factor": 0.01 } } ],
      "poroelastic": { "time_step": 0.02, "permeability_feedback": false }
    })";
    const Outcome a = run(scene, 1, 150), b = run(scene, 2, 150);
    EXPECT_GE(b.threads_seen, 2u) << "the parallel runtime used one thread";
    const PfemTimings& t = a.state.structures.timings;
    EXPECT_EQ(t.biot_calls, 15);
    EXPECT_GE(t.remeshes, 1);
    EXPECT_EQ(b.state.structures.timings.remeshes, t.remeshes);
    EXPECT_TRUE(same_bits(a.state.fluid.x, b.state.fluid.x));
    EXPECT_TRUE(same_bits(a.state.fluid.p, b.state.fluid.p));
    const PorousParticles &p = a.state.porous.particles, &q = b.state.porous.particles;
    EXPECT_TRUE(same_bits(p.x, q.x));
    EXPECT_TRUE(same_bits(p.absorbed_mass, q.absorbed_mass));
    EXPECT_TRUE(same_bits(p.porosity, q.porosity));
    const Structure &s = a.state.structures.structures.at(0),
                    &r = b.state.structures.structures.at(0);
    EXPECT_TRUE(same_bits(s.fields.u, r.fields.u));
    EXPECT_TRUE(same_bits(s.fields.p, r.fields.p));
    EXPECT_TRUE(same_bits(s.mesh.tets, r.mesh.tets));
}

// A free stone sphere entering water, with each pressure solve: the fragments' reactions inside
// the solves (coupling/fragment_response.hpp) are summed in member order.
TEST(Determinism, AFragmentFallingIntoWaterIsIdenticalOnOneAndTwoThreads) {
    for (const char* solver : {"dfsph", "pcisph"}) {
        SCOPED_TRACE(solver);
        const std::string scene = R"({ "name": "stone", "particle_spacing": 0.02,
      "fluid": { "solver": ")" + std::string(solver) +
                                  R"(" },
      "fluid_blocks": [ { "shape": { "type": "box", "min": [0, 0, 0], "max": [0.4, 0.4, 0.2] } } ],
      "walls": [ { "kind": "container", "shape": { "type": "box", "min": [0, 0, 0], "max": [0.4, 0.4, 0.5] } } ],
      "porous_solids": [ { "anchored": false, "shape": { "type": "sphere", "center": [0.2, 0.2, 0.28], "radius": 0.07 },
                           "material": { "porosity": 0, "solid_density": 2600 } } ] })";
        const Outcome a = run(scene, 1, 30), b = run(scene, 2, 30);
        EXPECT_GE(b.threads_seen, 2u) << "the parallel runtime used one thread";
        ASSERT_EQ(a.state.steps, b.state.steps);
        EXPECT_LT(a.state.porous.fragments[0].centre[2], 0.26) << "m: the sphere enters the water";
        EXPECT_TRUE(same_bits(a.state.fluid.x, b.state.fluid.x));
        EXPECT_TRUE(same_bits(a.state.fluid.p, b.state.fluid.p));
        EXPECT_TRUE(same_bits(a.state.porous.particles.x, b.state.porous.particles.x));
        EXPECT_TRUE(same_bits(a.state.porous.particles.v, b.state.porous.particles.v));
    }
}

}  // namespace
}  // namespace karst
