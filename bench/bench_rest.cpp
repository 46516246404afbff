// Deep water at rest (issue 11): the issue's rest scenes run for 2 s from rest, and the figures
// its criteria read, per scene and solver: the fluid's 99th-percentile and largest speed at the
// end (goal: every particle under 0.02 m/s), the plane-averaged pressure against rho0 g depth
// below the top two layers (goal: within 3 %, L2), the energy's largest rise over its start
// (a closed system at rest may lose energy, never gain it), particles lost and pushed back
// from walls, steps and seconds. A run the watchdog stops is reported with its message.
//
//   karst_bench_rest [--scene column|l_tank|all] [--solver dfsph|pcisph|both] [--end T]
//                    [--dt-max S] [--tolerance ETA] [--threads N]
//
// column: 0.08 x 0.08 x 1 m of water at dx 0.01 (100 layers) in a closed box. l_tank: water
// 0.3 m deep in an L-shaped tank at dx 0.01 (a 0.3 x 0.1 m container with a 0.15 m step in
// one half), whose free surface spans both arms. Prints only; appends nothing.
#include "karst/core/parallel.hpp"
#include "karst/core/timer.hpp"
#include "karst/scene/scene.hpp"
#include "karst/sim/energy.hpp"
#include "karst/sim/model.hpp"
#include "karst/sim/state.hpp"
#include "karst/sim/step.hpp"

#include <fmt/format.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

using namespace karst;

namespace {

constexpr Real k_dx = 0.01;

const std::map<std::string, std::string> k_scenes = {
    {"column", R"({
      "name": "rest_column", "particle_spacing": 0.01,
      "fluid_blocks": [ { "shape": { "type": "box", "min": [0, 0, 0], "max": [0.08, 0.08, 1.0] } } ],
      "walls": [ { "kind": "container", "shape": { "type": "box", "min": [0, 0, 0], "max": [0.08, 0.08, 1.2] } } ]
    })"},
    {"l_tank", R"({
      "name": "rest_l_tank", "particle_spacing": 0.01,
      "fluid_blocks": [
        { "shape": { "type": "box", "min": [0, 0, 0], "max": [0.15, 0.1, 0.3] } },
        { "shape": { "type": "box", "min": [0.15, 0, 0.15], "max": [0.3, 0.1, 0.3] } } ],
      "walls": [
        { "kind": "container", "shape": { "type": "box", "min": [0, 0, 0], "max": [0.3, 0.1, 0.4] } },
        { "kind": "obstacle", "shape": { "type": "box", "min": [0.15, 0, 0], "max": [0.3, 0.1, 0.15] } } ]
    })"},
};

struct Settings {
    Real end = 2;
    Real dt_max = 0;     ///< 0: the scene default
    Real tolerance = 0;  ///< 0: the scene default
};

/// L2 error of the plane-averaged pressure (rows of dx along gravity) against rho0 g depth, below
/// the top two layers; depth from the mean height of the top layer plus dx / 2.
Real hydrostatic_l2(const Model& model, const FluidParticles& f) {
    const Vec3 up = -model.scene.gravity.normalized();
    const Real g = model.scene.gravity.norm(), rho0 = model.rho0;
    Real top = -std::numeric_limits<Real>::infinity();
    for (const Vec3& x : f.x) top = std::max(top, x.dot(up));
    Real sum = 0;
    int n = 0;
    for (const Vec3& x : f.x)
        if (x.dot(up) > top - 0.5 * k_dx) sum += x.dot(up), ++n;
    const Real surface = sum / n + 0.5 * k_dx;
    struct Row {
        Real p = 0, h = 0;
        int n = 0;
    };
    std::map<long, Row> rows;
    for (Index i = 0; i < f.size(); ++i) {
        Row& r = rows[std::lround(std::floor(f.x[i].dot(up) / k_dx))];
        r.p += f.pressure(i), r.h += f.x[i].dot(up), ++r.n;
    }
    Real error2 = 0, norm2 = 0;
    for (const auto& [key, r] : rows) {
        const Real depth = surface - r.h / r.n, expected = rho0 * g * depth;
        if (depth < 2 * k_dx) continue;
        error2 += std::pow(r.p / r.n - expected, 2), norm2 += expected * expected;
    }
    return norm2 > 0 ? std::sqrt(error2 / norm2) : 0;
}

void run(const std::string& name, FluidSettings::Solver solver, const Settings& settings) {
    Scene scene = parse_scene(k_scenes.at(name));
    scene.fluid.solver = solver;
    if (settings.dt_max > 0) scene.time.dt_max = settings.dt_max;
    if (settings.tolerance > 0) scene.fluid.max_density_error = settings.tolerance;
    const Model model = build_model(scene);
    State state = make_initial_state(model);
    const Energy start = mechanical_energy(model, state);
    Real largest_rise = 0;
    StepProfile profile;
    std::string failure;
    Stopwatch watch;
    try {
        while (state.time < settings.end) {
            step(model, state,
                 next_step_length(model, state, std::numeric_limits<Real>::infinity()), profile);
            largest_rise =
                std::max(largest_rise, mechanical_energy(model, state).total() - start.total());
        }
    } catch (const std::runtime_error& e) {
        failure = e.what();
    }
    const auto [p99, fastest] = fluid_speed_p99_and_max(state.fluid);
    fmt::print(
        "{:7} {:6}  t {:.3f} s  {:5} steps  speed p99 {:.4f} max {:.4f} m/s  pressure L2 {:.1f} %"
        "  energy rise {:.4f} J of {:.3f}  lost {}  pushed back {}  {:.1f} s{}\n",
        name, solver == FluidSettings::Solver::Dfsph ? "dfsph" : "pcisph", state.time, state.steps,
        p99, fastest, 100 * hydrostatic_l2(model, state.fluid), largest_rise, start.total(),
        state.removed, state.pushed_back, watch.seconds(),
        failure.empty() ? "" : "\n        stopped: " + failure);
}

}  // namespace

int main(int argc, char** argv) {
    Settings settings;
    std::string scene = "all", solver = "both";
    int threads = 0;
    for (int a = 1; a + 1 < argc; a += 2) {
        const std::string key = argv[a], value = argv[a + 1];
        if (key == "--scene")
            scene = value;
        else if (key == "--solver")
            solver = value;
        else if (key == "--end")
            settings.end = std::stod(value);
        else if (key == "--dt-max")
            settings.dt_max = std::stod(value);
        else if (key == "--tolerance")
            settings.tolerance = std::stod(value);
        else if (key == "--threads")
            threads = std::stoi(value);
        else {
            fmt::print(stderr, "unknown option {}\n", key);
            return 2;
        }
    }
    if ((scene != "all" && !k_scenes.count(scene)) ||
        (solver != "both" && solver != "dfsph" && solver != "pcisph")) {
        fmt::print(stderr, "--scene column|l_tank|all, --solver dfsph|pcisph|both\n");
        return 2;
    }
    ThreadLimit limit(threads);
    for (const auto& [name, json] : k_scenes) {
        if (scene != "all" && scene != name) continue;
        for (const auto s : {FluidSettings::Solver::Dfsph, FluidSettings::Solver::Pcisph}) {
            if (solver == "dfsph" && s != FluidSettings::Solver::Dfsph) continue;
            if (solver == "pcisph" && s != FluidSettings::Solver::Pcisph) continue;
            run(name, s, settings);
        }
    }
    return 0;
}
