#include "karst/sim/run.hpp"

#include "karst/core/parallel.hpp"
#include "karst/core/timer.hpp"
#include "karst/io/frame_writer.hpp"
#include "karst/scene/scene_error.hpp"
#include "karst/sim/model.hpp"
#include "karst/sim/progress.hpp"
#include "karst/sim/run_poroelastic.hpp"
#include "karst/sim/step.hpp"
#include "karst/sim/watchdog.hpp"
#include "karst/sph/density.hpp"
#include "karst/sph/fluid_neighbours.hpp"
#include "karst/sph/integrate.hpp"

#include <fmt/format.h>

#include <cmath>

namespace karst {

namespace {

Real total_mass(const FluidParticles& f) {
    return deterministic_sum(f.size(), Real(0), [&](Index i) { return f.mass[i]; });
}
Real total_solute(const FluidParticles& f) {
    return deterministic_sum(f.size(), Real(0), [&](Index i) { return f.solute[i]; });
}

/// Step length that reaches `target` in a whole number of steps no longer than dt_cfl, so
/// frames land on their exact times without a sliver step.
Real step_towards(Real dt_cfl, Real now, Real target) {
    const Real remaining = target - now;
    const Real n = std::max(Real(1), std::ceil(remaining / dt_cfl - 1e-9));
    return remaining / n;
}

}  // namespace

RunResult run_simulation(const Scene& scene_in, const RunOptions& opt) {
    Scene scene = scene_in;
    if (opt.end_time) {
        if (!(*opt.end_time >= 0)) throw SceneError("--end-time", "a time >= 0 s", fmt::format("{}", *opt.end_time));
        scene.time.end = *opt.end_time;
    }
    if (opt.fps) {
        if (!(*opt.fps > 0)) throw SceneError("--fps", "a frame rate > 0", fmt::format("{}", *opt.fps));
        scene.output.fps = *opt.fps;
    }
    if (opt.threads < 0) throw SceneError("--threads", "a thread count >= 0", fmt::format("{}", opt.threads));
    ThreadLimit thread_limit(opt.threads);
    Stopwatch wall;
    const Model model = build_model(scene);
    if (!model.porous.empty()) {
        if (!model.initial_x.empty())
            throw SceneError("/porous_solids", "no fluid blocks beside porous solids (fluid-porous coupling is issue 3, not built yet)",
                             fmt::format("{} fluid blocks", scene.fluid_blocks.size()));
        return run_poroelastic(model, opt);
    }
    State state = make_initial_state(model);

    RunResult result;
    result.out_dir = opt.out_dir ? *opt.out_dir : std::filesystem::path("out") / scene.name;
    FrameWriter out(result.out_dir, scene.output);
    out.write_boundary(model.walls);

    // Densities of the initial state, so frame 0 shows them.
    update_fluid_neighbours(model, state);
    update_density(model, state);
    out.write_frame({&state.fluid}, {0, 0, 0, state.fluid.size(), 0, 0});

    const Real water_initial = total_mass(state.fluid), solute_initial = total_solute(state.fluid);
    StepProfile profile;
    ProgressLine progress(opt.quiet);
    Real max_density_error = 0, frame_density_error = 0;
    double particle_steps = 0, frame_particle_steps = 0, frame_step_seconds = 0;
    Stopwatch stepping;
    FluidParticles last_good;
    const Real end = scene.time.end;
    const Real frame_dt = 1 / scene.output.fps;
    int next_frame = 1;

    auto stats = [&] {
        const double step_seconds = profile.total();
        nlohmann::json phases;
        for (size_t s = 0; s < size_t(Stage::Count); ++s) phases[std::string(k_stage_names[s])] = profile.seconds[s];
        return nlohmann::json{
            {"scene", scene.name},
            {"counts", {{"fluid", state.fluid.size()}, {"boundary", model.walls.size()}, {"porous", 0},
                        {"elements", 0}, {"fragments", 0}, {"removed", state.removed}}},
            {"steps", state.steps},
            {"frames", out.frames()},
            {"sim_time", state.time},
            {"wall_time", wall.seconds()},
            {"phases", phases},
            {"mass", {{"water_initial", water_initial}, {"water_final", total_mass(state.fluid)},
                      {"solute_initial", solute_initial}, {"solute_final", total_solute(state.fluid)}}},
            {"max_density_error", max_density_error},
            {"mipps", step_seconds > 0 ? particle_steps / step_seconds / 1e6 : 0.0},
            {"threads", ThreadLimit::active_threads()},
            {"version", KARST_VERSION},
        };
    };

    try {
        while (state.time < end - 1e-12 * std::max(Real(1), end)) {
            const Real frame_time = std::min(end, next_frame * frame_dt);
            Real dt = cfl_time_step(model, state);
            if (!scene.time.fixed_dt) dt = step_towards(dt, state.time, frame_time);
            last_good = state.fluid;
            const Real last_good_time = state.time;
            StepReport report;
            try {
                Stopwatch step_watch;
                report = step(model, state, dt, profile);
                frame_step_seconds += step_watch.seconds();
            } catch (const WatchdogError&) {
                // Keep what was good: the state before the failing step becomes the last frame.
                state.fluid = last_good;
                state.time = last_good_time;
                out.write_frame({&state.fluid}, {state.time, dt, state.steps, state.fluid.size(), frame_density_error, 0});
                throw;
            }
            max_density_error = std::max(max_density_error, report.max_density_error);
            frame_density_error = std::max(frame_density_error, report.max_density_error);
            particle_steps += double(state.fluid.size());
            frame_particle_steps += double(state.fluid.size());

            const bool frame_due = state.time >= frame_time - 1e-9 * dt;
            if (frame_due) {
                out.write_frame({&state.fluid}, {state.time, dt, state.steps, state.fluid.size(), frame_density_error,
                                              frame_step_seconds > 0 ? frame_particle_steps / frame_step_seconds / 1e6 : 0});
                ++next_frame;
                frame_density_error = 0, frame_particle_steps = 0, frame_step_seconds = 0;
            }
            const double elapsed = stepping.seconds();
            const double rate = state.time / std::max(elapsed, 1e-9);
            progress.update({out.frames() - 1, state.time, end, state.steps / std::max(elapsed, 1e-9),
                             particle_steps / std::max(elapsed, 1e-9) / 1e6, (end - state.time) / std::max(rate, 1e-12),
                             state.fluid.size()});
        }
    } catch (const WatchdogError& e) {
        progress.finish();
        result.ok = false;
        result.failure = e.what();
        result.stats = stats();
        result.stats["failure"] = e.what();
        out.write_stats(result.stats);
        return result;
    }
    progress.finish();
    result.stats = stats();
    out.write_stats(result.stats);
    return result;
}

}  // namespace karst
