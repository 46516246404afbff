#include "karst/sim/run.hpp"

#include "karst/core/check.hpp"
#include "karst/core/parallel.hpp"
#include "karst/core/timer.hpp"
#include "karst/coupling/porous_boundary_volumes.hpp"
#include "karst/coupling/porous_neighbours.hpp"
#include "karst/io/frame_writer.hpp"
#include "karst/pfem/structure_stages.hpp"
#include "karst/porous/porous_points.hpp"
#include "karst/render/render.hpp"
#include "karst/scene/scene_error.hpp"
#include "karst/scene/schema.hpp"
#include "karst/sim/checkpoint.hpp"
#include "karst/sim/energy.hpp"
#include "karst/sim/model.hpp"
#include "karst/sim/progress.hpp"
#include "karst/sim/step.hpp"
#include "karst/sim/stop_signal.hpp"
#include "karst/sim/watchdog.hpp"
#include "karst/sph/density.hpp"
#include "karst/sph/fluid_neighbours.hpp"
#include "karst/sph/integrate.hpp"
#include "karst/surface/fluid_frame.hpp"
#include "karst/surface/porous_surface.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <optional>

namespace karst {

MassTotals mass_totals(const State& s) {
    const FluidParticles& f = s.fluid;
    const PorousParticles& p = s.porous.particles;
    MassTotals t;
    t.solute = deterministic_sum(f.size(), Real(0), [&](Index i) { return f.solute[i]; });
    t.absorbed = deterministic_sum(p.size(), Real(0), [&](Index i) { return p.absorbed_mass[i]; });
    t.water =
        deterministic_sum(f.size(), Real(0), [&](Index i) { return f.water(i); }) + t.absorbed;
    t.grains =
        t.solute + deterministic_sum(p.size(), Real(0), [&](Index i) { return p.solid_mass[i]; });
    return t;
}

namespace {

Index live_fragments(const State& s) {
    Index n = 0;
    for (const Fragment& f : s.porous.fragments) n += f.mass > 0;
    return n;
}

nlohmann::json biot_stats(const PfemTimings& t) {
    return {{"calls", t.biot_calls},
            {"iterations", t.biot_iterations},
            {"remeshes", t.remeshes},
            {"repeated_after_fracture", t.repeated_calls},
            {"mean_iterations", t.biot_calls ? double(t.biot_iterations) / t.biot_calls : 0.0},
            {"unconverged_calls", t.unconverged_calls},
            {"all_converged", t.unconverged_calls == 0}};
}

nlohmann::json fracture_stats(const FractureCounts& f) {
    return {{"cracks", f.cracks},
            {"links_broken", f.links_broken},
            {"nodes_split", f.nodes_split},
            {"fragments_created", f.fragments_created},
            {"merges", f.merges}};
}

/// The porous frame: pore state (porous/porous_points.hpp) on neighbour lists of the current
/// positions (dissolution may have removed particles since the step's search).
PointSet porous_frame(const Model& model, const State& state) {
    const PorousParticles& p = state.porous.particles;
    CellRanges cells;
    NeighbourLists pairs;
    sort_into_cells(model.porous_grid, p.x, cells);
    find_neighbours(model.porous_grid, p.x, cells, true, pairs);
    PointSet points = porous_points(p, model.pore_laws, pairs, model.h);
    // Links broken on faces through each particle (§5.6): where the rock is cracked.
    const std::vector<Index>& damage = state.structures.damage;
    std::vector<std::int64_t> broken(p.size(), 0);
    for (Index i = 0; i < p.size(); ++i)
        if (size_t(p.id[i]) < damage.size()) broken[i] = damage[p.id[i]];
    points.add_integer("damage", broken);
    return points;
}

/// The values of a named array of `points`.
std::vector<Real> point_array(const PointSet& points, const std::string& name) {
    for (const PointArray& a : points.arrays)
        if (a.name == name) return a.values;
    throw std::logic_error("no point array " + name);
}

/// A flag that overrides a scene key obeys the key's range, and says so with the flag's name.
Real checked_flag(const char* flag, const std::string& pointer, double value) {
    for (const KeySpec& k : scene_schema())
        if (k.pointer == pointer) {
            if (!k.range.contains(value))
                throw SceneError(
                    flag,
                    fmt::format("a number in {} {} (as {})", k.range.describe(), k.unit, pointer),
                    fmt::format("{}", value));
            return value;
        }
    throw std::logic_error("no schema key " + pointer);
}

/// What stats.json holds (its wall time aside).
nlohmann::json run_stats(const Model& model, const State& state, const RunRecord& record,
                         int frames) {
    const double step_seconds = record.profile.total();
    const MassTotals final_totals = mass_totals(state);
    nlohmann::json phases;
    for (size_t s = 0; s < size_t(Stage::Count); ++s)
        phases[std::string(k_stage_names[s])] = record.profile.seconds[s];
    const PfemTimings& pfem = state.structures.timings;
    const MeshQuality quality = structure_mesh_quality(state);
    phases["meshing"] = pfem.meshing, phases["assembly"] = pfem.assembly;
    phases["factorisation"] = pfem.factorisation, phases["iterations"] = pfem.iterations;
    return nlohmann::json{
        {"scene", model.scene.name},
        {"counts",
         {{"fluid", state.fluid.size()},
          {"boundary", model.walls.size()},
          {"porous", state.porous.size()},
          {"elements", quality.elements},
          {"fragments", live_fragments(state)},
          {"removed", state.removed},
          {"pushed_back", state.pushed_back},
          {"porous_removed", state.porous.removed},
          {"dissolved", state.porous.dissolved},
          {"fluid_drained", state.porous.fluid_deleted}}},
        {"steps", state.steps},
        {"frames", frames},
        {"sim_time", state.time},
        {"phases", phases},
        {"mass",
         {{"water_initial", record.initial.water},
          {"water_final", final_totals.water},
          {"absorbed", state.porous.absorbed},
          {"absorbed_initial", record.initial.absorbed},
          {"absorbed_final", final_totals.absorbed},
          {"solute_initial", record.initial.solute},
          {"solute_final", final_totals.solute},
          {"grains_initial", record.initial.grains},
          {"grains_final", final_totals.grains}}},
        {"mass_meaning",
         {{"unit", "kg"},
          {"water",
           "all water: in the fluid particles (their mass less any grains) plus in "
           "the pores; conserved up to fluid that left the domain"},
          {"absorbed",
           "net water the pores took from the fluid by pore flow over the run; "
           "absorbed_final - absorbed_initial differs from it by the remnants "
           "of drained fluid particles given to the pores and the pore water "
           "of porous particles that dissolved or left the domain"},
          {"absorbed_initial", "water in the pores at the start (initial saturation)"},
          {"absorbed_final", "water in the pores at the end"},
          {"solute", "dissolved grains carried by the fluid"},
          {"grains",
           "all grains: solid mass of the porous particles plus the solute; "
           "conserved"}}},
        {"pore_flow", {{"substeps", state.porous.pore_substeps}}},
        {"biot", biot_stats(pfem)},
        {"fracture", fracture_stats(state.structures.fracture)},
        {"mesh",
         {{"kept", quality.kept},
          {"polyhedra", quality.polyhedra},
          {"slivers_dropped", quality.slivers_dropped},
          {"interior_slivers", quality.interior_slivers}}},
        {"max_density_error", record.max_density_error},
        {"frames_over_density_tolerance", record.frames_over_tolerance},
        {"energy",
         {{"released", record.energy.released()},
          {"largest_gain", record.energy.largest_gain()},
          {"largest_rise_over_start", record.energy.largest_rise_over_start()}}},
        {"mipps", step_seconds > 0 ? record.particle_steps / step_seconds / 1e6 : 0.0},
        {"threads", ThreadLimit::active_threads()},
        {"version", KARST_VERSION},
    };
}

/// The scene's walls as karst render draws them.
std::vector<PicturedWall> pictured_walls(const Scene& scene) {
    std::vector<PicturedWall> walls;
    for (const Wall& w : scene.walls)
        walls.push_back(
            {w.shape, w.kind == Wall::Kind::Container, w.layers * scene.particle_spacing});
    return walls;
}

}  // namespace

RunResult run_simulation(const Scene& scene_in, const RunOptions& opt) {
    Scene scene = scene_in;
    if (opt.end_time) scene.time.end = checked_flag("--end-time", "/time/end", *opt.end_time);
    if (opt.fps) scene.output.fps = checked_flag("--fps", "/output/fps", *opt.fps);
    if (!(opt.threads >= 0 && opt.threads <= k_max_threads))
        throw SceneError("--threads", fmt::format("a thread count in [0, {}]", k_max_threads),
                         fmt::format("{}", opt.threads));
    if (opt.checkpoint_every &&
        !(*opt.checkpoint_every > 0 && *opt.checkpoint_every <= k_max_checkpoint_interval))
        throw SceneError("--checkpoint-every",
                         fmt::format("a simulated time in (0, {:g}] s", k_max_checkpoint_interval),
                         fmt::format("{}", *opt.checkpoint_every));
    if (!(opt.checkpoint_keep >= 1 && opt.checkpoint_keep <= k_max_checkpoints_kept))
        throw SceneError("--checkpoint-keep",
                         fmt::format("a count in [1, {}]", k_max_checkpoints_kept),
                         fmt::format("{}", opt.checkpoint_keep));
    if (opt.resume && opt.out_dir)
        throw SceneError("--out", "no --out with --resume (a resumed run writes into its folder)",
                         opt.out_dir->string());
    if (opt.render) check_render_tools();
    ThreadLimit thread_limit(opt.threads);
    Stopwatch wall;
    const Model model = build_model(scene);
    const CheckpointKey key{scene.fingerprint, scene.output.fps};
    State state;
    RunRecord record;
    RunResult result;
    std::optional<FrameWriter> out;
    if (opt.resume) {
        // Everything is read and checked before the folder is touched.
        const std::vector<std::string> names = checkpoint_names(*opt.resume);
        if (names.empty())
            throw SceneError("--resume", "a folder holding a checkpoint_*.kcp file",
                             fmt::format("none in '{}'", opt.resume->string()));
        read_checkpoint(*opt.resume / names.back(), key, state, record);
        result.out_dir = *opt.resume;
        out.emplace(result.out_dir, scene.output, record.frames);
    } else {
        state = make_initial_state(model);
        result.out_dir = opt.out_dir ? *opt.out_dir : std::filesystem::path("out") / scene.name;
        out.emplace(result.out_dir, scene.output, opt.overwrite);
        out->write_boundary(model.walls);
        out->folder().write("render.json",
                            render_settings_json(scene.render, pictured_walls(scene)));
        // The energy account (issue 11): a rise of the mechanical energy over 5 % of the
        // energy released so far is energy the numerics made; the run says so once.
        record.energy = EnergyAccount(mechanical_energy(model, state));
    }
    std::optional<LiveRenderer> live;
    if (opt.render) {
        Aabb walls;
        for (const Vec3& x : model.walls.x) walls.extend(x);
        live.emplace(result.out_dir, *opt.render, scene.render, scene.domain, walls,
                     pictured_walls(scene));
    }
    const bool porous = state.porous.size() > 0;
    const bool meshes = !state.structures.empty();
    const bool fluid_frames = !model.poroelastic_only();

    ProgressLine progress(opt.quiet);
    if (meshes && time_to_next_biot_call(model, state) > scene.time.end - state.time)
        progress.warn(fmt::format(
            "/poroelastic/time_step = {:g} s is longer than what is left of the run ({:g} s): "
            "the Biot solver never runs, so the solids neither deform nor crack",
            scene.poroelastic.time_step, scene.time.end - state.time));
    PorousSurfaces porous_surfaces;  // each fragment's triangles, kept while its members stay
    auto write_frame = [&](FrameLog log) {
        const Energy e = mechanical_energy(model, state);
        log.kinetic_energy = e.kinetic, log.potential_energy = e.potential,
        log.contact_energy = e.contact, log.removed = state.removed;
        std::tie(log.speed_p99, log.max_speed) = fluid_speed_p99_and_max(state.fluid);
        record.energy.add(e);
        if (!record.energy_warned && record.energy.gained_more_than(0.05)) {
            record.energy_warned = true;
            progress.warn(fmt::format(
                "t = {:.4g} s: the mechanical energy (kinetic, potential, contact) rose by "
                "{:.3g} J, {} (log.csv has the account)",
                state.time, record.energy.largest_gain(),
                record.energy.released() > 0
                    ? fmt::format("{:.0f} % of the {:.3g} J released so far",
                                  100 * record.energy.worst_ratio(), record.energy.released())
                    : std::string("with none released")));
        }
        if (!record.removed_warned && state.removed > 0) {
            record.removed_warned = true;
            progress.warn(fmt::format(
                "t = {:.4g} s: fluid left the domain: {} particles ({:.3g} kg) so far; stats.json "
                "counts.removed has the total",
                state.time, state.removed, state.removed * model.particle_mass));
        }
        if (!record.porous_removed_warned && state.porous.removed > 0) {
            record.porous_removed_warned = true;
            progress.warn(
                fmt::format("t = {:.4g} s: porous particles left the domain: {} so far; stats.json "
                            "counts.porous_removed has the total",
                            state.time, state.porous.removed));
        }
        if (!record.biot_warned && state.structures.timings.unconverged_calls > 0) {
            record.biot_warned = true;
            progress.warn(fmt::format(
                "t = {:.4g} s: a Biot call stopped at /poroelastic/max_iterations = {} above its "
                "tolerance; stats.json biot.unconverged_calls counts them",
                state.time, model.scene.poroelastic.max_iterations));
        }
        PointSet porous_points;
        if (porous) porous_points = porous_frame(model, state);
        MeshFrame mesh;
        if (meshes) {
            append_structure_meshes(model, state, mesh);
            log.supports = structure_supports(model, state, state.time - state.structures.elapsed);
        }
        const CrackFrame cracks = crack_frame(state.structures.cracks);
        const OutputSettings& o = scene.output;
        SurfaceMesh fluid_surface, porous_surface;
        std::string level_set;
        if (fluid_frames && o.fluid_surface)
            fluid_surface =
                fluid_frame_surface(model, state.fluid, o.level_set ? &level_set : nullptr);
        if (porous && o.porous_surface)
            porous_surface = porous_surfaces.build(model, state.porous.particles,
                                                   point_array(porous_points, "saturation"));
        FrameParts parts{fluid_frames ? &state.fluid : nullptr, meshes ? &mesh : nullptr,
                         porous ? &porous_points : nullptr, &cracks};
        if (fluid_frames && o.fluid_surface) parts.fluid_surface = &fluid_surface;
        if (porous && o.porous_surface) parts.porous_surface = &porous_surface;
        if (fluid_frames && o.level_set) parts.level_set = &level_set;
        parts.pscale = 0.5 * model.dx;
        out->write_frame(parts, log);
        if (live)
            live->add(out->frames() - 1, parts.fluid_surface, parts.porous_surface, out->folder());
    };
    // The checkpoint of the state now, and only the newest --checkpoint-keep of them kept.
    auto write_checkpoint = [&] {
        RunRecord now = record;
        now.frames = out->history();
        now.wall_seconds += wall.seconds();
        out->folder().write(checkpoint_name(state.steps), checkpoint_bytes(key, state, now));
        std::vector<std::string> names = checkpoint_names(out->dir());
        if (names.size() <= size_t(opt.checkpoint_keep)) return;
        names.resize(names.size() - opt.checkpoint_keep);
        out->folder().remove_if([&](const std::string& name) {
            return std::find(names.begin(), names.end(), name) != names.end();
        });
    };
    const Real every = opt.checkpoint_every.value_or(0);
    Real next_checkpoint = every > 0 ? every * (std::floor(state.time / every + 1e-9) + 1) : 0;

    if (!opt.resume) {
        // Densities of the initial state, so frame 0 shows them.
        update_fluid_neighbours(model, state);
        if (porous) {
            update_porous_neighbours(model, state);
            update_porous_boundary_volumes(model, state);
        }
        update_density(model, state);
        write_frame({0, 0, 0, state.fluid.size(), 0, 0});
        record.initial = mass_totals(state);
    }

    // The pressure solve's tolerance: frames whose steps ended above it are counted and told.
    const Real density_tolerance = scene.fluid.max_density_error;
    Stopwatch stepping;
    const Index steps_before = state.steps;
    const Real time_before = state.time;
    double leg_particle_steps = 0;
    FluidParticles last_good;
    PorousState last_good_porous;
    const Real end = scene.time.end;
    const Real frame_dt = 1 / scene.output.fps;

    auto stats = [&] {
        nlohmann::json s = run_stats(model, state, record, out->frames());
        s["wall_time"] = record.wall_seconds + wall.seconds();
        return s;
    };

    // The run ends loudly on a watchdog stop or a numerical failure, with stats.json.
    const auto stopped_by = [&](const std::exception& e) {
        progress.finish();
        result.ok = false;
        result.failure = e.what();
        result.stats = stats();
        result.stats["failure"] = e.what();
        out->write_stats(result.stats);
        return result;
    };
    try {
        while (state.time < end - 1e-12 * std::max(Real(1), end)) {
            const Real frame_time = std::min(end, record.next_frame * frame_dt);
            const Real dt = next_step_length(model, state, frame_time);
            last_good = state.fluid;
            if (porous) last_good_porous = state.porous;
            const Real last_good_time = state.time;
            StepReport report;
            try {
                Stopwatch step_watch;
                report = step(model, state, dt, record.profile);
                record.frame_step_seconds += step_watch.seconds();
            } catch (const WatchdogError&) {
                // Keep what was good: the state before the failing step becomes the last frame,
                // unless the last frame already shows it (a frame was due at its time).
                state.fluid = last_good;
                if (porous) state.porous = last_good_porous;
                state.time = last_good_time;
                const std::vector<FrameLog>& written = out->history().log;
                // The structures are not rolled back: where their solver is what failed, writing
                // the frame fails too, and the watchdog's error stays the one reported.
                try {
                    if (written.empty() || written.back().time < state.time)
                        write_frame({state.time, dt, state.steps, state.fluid.size(),
                                     record.frame_density_error, 0});
                } catch (const std::exception& e) {
                    progress.warn(fmt::format("the last good frame was not written: {}", e.what()));
                }
                throw;
            }
            record.max_density_error = std::max(record.max_density_error, report.max_density_error);
            record.frame_density_error =
                std::max(record.frame_density_error, report.max_density_error);
            const double particles = double(state.fluid.size() + state.porous.size());
            record.particle_steps += particles;
            leg_particle_steps += particles;
            record.frame_particle_steps += particles;

            const bool frame_due = state.time >= frame_time - 1e-9 * dt;
            if (frame_due) {
                record.frames_over_tolerance += record.frame_density_error > density_tolerance;
                write_frame({state.time, report.dt, state.steps, state.fluid.size(),
                             record.frame_density_error,
                             record.frame_step_seconds > 0
                                 ? record.frame_particle_steps / record.frame_step_seconds / 1e6
                                 : 0});
                ++record.next_frame;
                record.frame_density_error = 0, record.frame_particle_steps = 0,
                record.frame_step_seconds = 0;
            }
            if (every > 0 && state.time >= next_checkpoint - 1e-9 * dt) {
                write_checkpoint();
                next_checkpoint = every * (std::floor(state.time / every + 1e-9) + 1);
            }
            const double elapsed = std::max(stepping.seconds(), 1e-9);
            const double rate = (state.time - time_before) / elapsed;
            progress.update(
                {out->frames() - 1, state.time, end, (state.steps - steps_before) / elapsed,
                 leg_particle_steps / elapsed / 1e6, (end - state.time) / std::max(rate, 1e-12),
                 fluid_frames ? state.fluid.size() : state.porous.size(),
                 porous ? state.porous.absorbed : -1.0, state.removed,
                 porous ? live_fragments(state) : 0});
            if (stop_signal()) break;  // after a whole step: the folder stays consistent
        }
    } catch (const WatchdogError& e) {
        return stopped_by(e);
    } catch (const NumericalFailure& e) {  // outside a step: a frame's structure solve
        return stopped_by(e);
    }
    if (record.frames_over_tolerance > 0)
        progress.warn(fmt::format(
            "the density error exceeded /fluid/max_density_error = {:g} in {} of {} frames "
            "(largest {:.3g}): the pressure solve stopped at max_iterations or the step was "
            "too long; raise /fluid/max_iterations, or lower /time/cfl where the step is "
            "longer than dx / c_s",
            density_tolerance, record.frames_over_tolerance, out->frames() - 1,
            record.max_density_error));
    progress.finish();
    // At the end, or where a signal stopped the run: a later --resume continues from here.
    if (every > 0) write_checkpoint();
    result.stats = stats();
    if (stop_signal()) {
        result.stop_signal = stop_signal();
        result.stats["interrupted"] = {{"signal", result.stop_signal}, {"time", state.time}};
    }
    out->write_stats(result.stats);
    if (live) result.render = live->finish(out->frames(), out->folder());
    return result;
}

}  // namespace karst
