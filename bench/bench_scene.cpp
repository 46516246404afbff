// Scene benchmarks with a fixed 1 ms step. The default is the standard comparison case (issue
// 2): a 0.98 m cube of water (117,649 particles at 0.02 m) at one end of a closed 4 x 3 x 1.5 m
// box, PCISPH with at most 1 % density error and at least 3 iterations. `--scene
// bench_soak_100k` is issue 3's soak: 50,000 water particles resting on a layered porous block
// of 51,000. Warms up, then times a batch of steps and prints particle-steps per second (fluid
// and porous), MIPPS, seconds per stage and density errors; appends CSV to
// bench/results/2core/<scene>.csv.
//
//   karst_bench_scene [--scene NAME] [--steps N] [--warmup N] [--threads N] [--solver dfsph|pcisph]
#include "provenance.hpp"

#include "karst/core/parallel.hpp"
#include "karst/core/timer.hpp"
#include "karst/scene/scene.hpp"
#include "karst/pfem/structure_stages.hpp"
#include "karst/sim/model.hpp"
#include "karst/sim/state.hpp"
#include "karst/sim/step.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>

using namespace karst;

int main(int argc, char** argv) {
    int steps = 50, warmup = 10, threads = 0;
    std::string scene = "bench_dam_break_118k", solver;
    for (int a = 1; a + 1 < argc; a += 2) {
        if (!std::strcmp(argv[a], "--scene"))
            scene = argv[a + 1];
        else if (!std::strcmp(argv[a], "--steps"))
            steps = std::atoi(argv[a + 1]);
        else if (!std::strcmp(argv[a], "--warmup"))
            warmup = std::atoi(argv[a + 1]);
        else if (!std::strcmp(argv[a], "--threads"))
            threads = std::atoi(argv[a + 1]);
        else if (!std::strcmp(argv[a], "--solver"))
            solver = argv[a + 1];
    }
    ThreadLimit limit(threads);
    const std::string scene_path = std::string(KARST_SOURCE_DIR) + "/scenes/" + scene + ".json";
    Scene scene_data = load_scene_file(scene_path);
    if (solver == "pcisph")
        scene_data.fluid.solver = FluidSettings::Solver::Pcisph;
    else if (solver == "dfsph")
        scene_data.fluid.solver = FluidSettings::Solver::Dfsph;
    else if (!solver.empty()) {
        fmt::print(stderr, "--solver: dfsph or pcisph, not {}\n", solver);
        return 2;
    }
    const bool dfsph = scene_data.fluid.solver == FluidSettings::Solver::Dfsph;
    const Model model = build_model(scene_data);
    State state = make_initial_state(model);
    // The step a run takes (the scenes fix it at 1 ms), Biot calls included where the scene has
    // them.
    auto next_step = [&] {
        return next_step_length(model, state, std::numeric_limits<Real>::infinity());
    };
    StepProfile warm;
    for (int k = 0; k < warmup; ++k) step(model, state, next_step(), warm);
    const Index biot_calls_before = state.structures.timings.biot_calls;

    StepProfile profile;
    std::vector<Real> errors;
    int iterations = 0, divergence_iterations = 0;
    double particle_steps = 0;
    Stopwatch watch;
    for (int k = 0; k < steps; ++k) {
        particle_steps += double(state.fluid.size() + state.porous.size());
        const StepReport r = step(model, state, next_step(), profile);
        errors.push_back(r.max_density_error);
        iterations += r.pressure_iterations;
        divergence_iterations += r.divergence_iterations;
    }
    const double seconds = watch.seconds();
    std::sort(errors.begin(), errors.end());
    const double mean_error = [&] {
        double s = 0;
        for (Real e : errors) s += e;
        return s / errors.size();
    }();
    const Real p99 = errors[std::min(errors.size() - 1, size_t(0.99 * errors.size()))];

    fmt::print(
        "karst_bench_scene {}: {} fluid + {} porous + {} boundary particles, {} threads, {} steps "
        "after {} warm-up\n",
        scene, state.fluid.size(), state.porous.size(), model.walls.size(),
        ThreadLimit::active_threads(), steps, warmup);
    if (state.porous.size() > 0)
        fmt::print("  {:.3f} kg absorbed, {} pore-flow sub-steps per step\n", state.porous.absorbed,
                   double(state.porous.pore_substeps) / (steps + warmup));
    if (!state.structures.empty()) {
        const PfemTimings& t = state.structures.timings;
        fmt::print(
            "  structure stage: {} Biot calls in the timed steps ({} in all, {:.2f} iterations "
            "each), {} elements; since t = 0: "
            "meshing {:.3f} s, assembly {:.3f} s, factorisation {:.3f} s, iterations {:.3f} s\n",
            t.biot_calls - biot_calls_before, t.biot_calls,
            t.biot_calls ? double(t.biot_iterations) / t.biot_calls : 0.0,
            structure_mesh_quality(state).elements, t.meshing, t.assembly, t.factorisation,
            t.iterations);
    }
    fmt::print(
        "  {}: {:.0f} particle-steps/s, {:.4f} MIPPS, {:.1f} ms per step, {:.2f} density + {:.2f} "
        "divergence iterations per step\n",
        dfsph ? "DFSPH" : "PCISPH", particle_steps / seconds, particle_steps / seconds / 1e6,
        1e3 * seconds / steps, double(iterations) / steps, double(divergence_iterations) / steps);
    fmt::print("  max density error per step: mean {:.4f} %, p99 {:.4f} %, max {:.4f} %\n",
               100 * mean_error, 100 * p99, 100 * errors.back());
    for (size_t s = 0; s < size_t(Stage::Count); ++s)
        fmt::print("  {:22s} {:8.4f} s per step\n", k_stage_names[s], profile.seconds[s] / steps);

    std::string header =
        "threads,steps,particles,particle_steps_per_s,mipps,ms_per_step,iterations_per_step,mean_"
        "density_error,p99_density_error";
    for (auto name : k_stage_names) header += ",s_" + std::string(name);
    header += ",biot_calls";
    const auto file = std::filesystem::path(KARST_SOURCE_DIR) / "bench" / "results" / "2core" /
                      (scene + (dfsph ? "_dfsph" : "") + ".csv");
    std::ofstream csv = bench::open_results(file, header);
    csv << bench::provenance_fields(KARST_SOURCE_DIR);
    csv << fmt::format("{},{},{},{:.0f},{:.5f},{:.2f},{:.2f},{:.5f},{:.5f}",
                       ThreadLimit::active_threads(), steps,
                       state.fluid.size() + state.porous.size(), particle_steps / seconds,
                       particle_steps / seconds / 1e6, 1e3 * seconds / steps,
                       double(iterations) / steps, mean_error, p99);
    for (double s : profile.seconds) csv << fmt::format(",{:.5f}", s / steps);
    csv << fmt::format(",{}\n", state.structures.timings.biot_calls - biot_calls_before);
    fmt::print("  appended to {}\n", file.string());
}
