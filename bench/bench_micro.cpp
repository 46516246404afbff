// Micro benchmarks of the neighbour search and one density pass on a resting 40^3 block.
#include "karst/scene/scene.hpp"
#include "karst/sim/model.hpp"
#include "karst/sim/state.hpp"
#include "karst/sph/density.hpp"
#include "karst/sph/fluid_neighbours.hpp"

#include <benchmark/benchmark.h>

using namespace karst;

namespace {
const Model& block_model() {
    static const Model model = build_model(parse_scene(R"({
      "name": "micro", "particle_spacing": 0.02,
      "fluid_blocks": [ { "shape": { "type": "box", "min": [0, 0, 0], "max": [0.8, 0.8, 0.8] } } ],
      "walls": [ { "kind": "container", "shape": { "type": "box", "min": [0, 0, 0], "max": [1.2, 0.8, 1.0] } } ]
    })"));
    return model;
}
}  // namespace

static void NeighbourSearch(benchmark::State& bs) {
    const Model& m = block_model();
    State s = make_initial_state(m);
    s.steps = 1;  // skip the Morton reorder: time the grid and lists only
    for (auto _ : bs) update_fluid_neighbours(m, s);
    bs.SetItemsProcessed(bs.iterations() * s.fluid.size());
}
BENCHMARK(NeighbourSearch)->Unit(benchmark::kMillisecond);

static void DensityPass(benchmark::State& bs) {
    const Model& m = block_model();
    State s = make_initial_state(m);
    update_fluid_neighbours(m, s);
    for (auto _ : bs) update_density(m, s);
    bs.SetItemsProcessed(bs.iterations() * s.fluid.size());
}
BENCHMARK(DensityPass)->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
