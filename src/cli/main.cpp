// The karst command line: maps flags to options and calls the library; nothing else.
#include "karst/render/render.hpp"
#include "karst/scene/scene.hpp"
#include "karst/scene/scene_error.hpp"
#include "karst/scene/schema.hpp"
#include "karst/sim/model.hpp"
#include "karst/sim/run.hpp"
#include "karst/sim/stop_signal.hpp"

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <exception>
#include <optional>

namespace {

karst::Scene read_scene(const std::string& path) {
    return path.empty() ? karst::parse_scene(karst::default_scene_text())
                        : karst::load_scene_file(path);
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"karst: water soaking into, deforming, dissolving and breaking porous material"};
    app.set_version_flag("--version", KARST_VERSION);
    app.require_subcommand(0, 1);

    std::string scene_path;
    karst::RunOptions run_options;
    std::string out_dir;
    std::optional<double> end_time, fps, checkpoint_every;
    std::string resume_dir;
    CLI::App* run =
        app.add_subcommand("run", "Simulate a scene (the built-in dam break when none is given)");
    run->add_option("scene", scene_path, "Scene file (JSON)");
    run->add_option("--out", out_dir, "Output folder (default out/<scene name>/)");
    run->add_option("--end-time", end_time, "Simulated end time in s (overrides /time/end)");
    run->add_option("--fps", fps, "Output frames per simulated second (overrides /output/fps)");
    run->add_option("--threads", run_options.threads, "Worker threads (0: all cores)");
    run->add_flag("--quiet", run_options.quiet, "No progress line");
    run->add_option("--checkpoint-every", checkpoint_every,
                    "Write a checkpoint every this many simulated seconds, at the end and when "
                    "stopped by Ctrl-C or SIGTERM");
    run->add_option("--checkpoint-keep", run_options.checkpoint_keep,
                    "Newest checkpoints kept in the output folder (default 2)");
    run->add_option("--resume", resume_dir,
                    "Continue the run in this output folder from its newest checkpoint (same "
                    "scene; --end-time may extend it)");
    run->add_flag("--overwrite", run_options.overwrite,
                  "Write into a non-empty output folder that no karst run wrote (only karst's "
                  "own file names are replaced)");

    bool render_after = false;
    karst::RenderOptions render_options;
    run->add_flag("--render", render_after,
                  "Render each frame's surfaces to a PNG as the run goes (POV-Ray, beside the "
                  "simulation) and movie.mp4 at its end; the camera frames the domain");
    std::string render_dir;
    CLI::App* render = app.add_subcommand(
        "render", "Render a run's surfaces to render_NNNN.png and movie.mp4 (POV-Ray, ffmpeg)");
    render->add_option("out_dir", render_dir, "Output folder of a run")->required();
    for (CLI::App* cmd : {run, render}) {
        cmd->add_flag("--preview", render_options.preview,
                      "Fast render: no refraction, soft shadows or anti-aliasing");
        cmd->add_option("--width", render_options.width,
                        "Frame width in pixels (default /render/width)")
            ->check(CLI::Range(16, 7680));
        cmd->add_option("--height", render_options.height,
                        "Frame height in pixels (default /render/height)")
            ->check(CLI::Range(16, 4320));
    }

    std::string check_path;
    CLI::App* check = app.add_subcommand("check", "Validate a scene and print its particle counts");
    check->add_option("scene", check_path, "Scene file (JSON)")->required();

    app.add_subcommand("schema", "Print the scene format reference (Markdown)");

    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return app.exit(e) == 0 ? 0 : 2;
    }
    if (app.get_subcommands().empty()) {  // `karst` alone: what it can do
        fmt::print("{}", app.help());
        return 0;
    }

    try {
        if (app.got_subcommand("schema")) {
            fmt::print("{}", karst::scene_schema_markdown());
            return 0;
        }
        if (app.got_subcommand("check")) {
            const karst::Model model = karst::build_model(karst::load_scene_file(check_path));
            size_t porous = 0;
            for (const karst::PorousBody& body : model.porous) porous += body.rest_x.size();
            fmt::print(
                "scene '{}' is valid: {} fluid particles, {} porous particles in {} solids ({}), "
                "{} boundary particles, "
                "spacing {} m, domain [{}, {}, {}] - [{}, {}, {}] m\n",
                model.scene.name, model.initial_x.size(), porous, model.porous.size(),
                model.porous.empty() ? "none"
                : model.coupled()    ? "coupled with the fluid"
                                     : "poroelastic-only",
                model.walls.size(), model.dx, model.domain.min[0], model.domain.min[1],
                model.domain.min[2], model.domain.max[0], model.domain.max[1], model.domain.max[2]);
            return 0;
        }
        if (app.got_subcommand("render")) {
            const karst::RenderResult r = karst::render_run(render_dir, render_options);
            fmt::print("karst: rendered {} frames ({:.2f} s each) and {}\n", r.frames,
                       r.seconds_per_frame, r.movie.string());
            return 0;
        }
        if (!out_dir.empty()) run_options.out_dir = out_dir;
        run_options.end_time = end_time, run_options.fps = fps;
        run_options.checkpoint_every = checkpoint_every;
        if (!resume_dir.empty()) run_options.resume = resume_dir;
        if (render_after) {
            render_options.threads = run_options.threads;
            run_options.render = render_options;
        }
        karst::catch_stop_signals();
        const karst::RunResult result = karst::run_simulation(read_scene(scene_path), run_options);
        if (result.stop_signal) {
            fmt::print(stderr,
                       "karst: stopped by signal {} at t = {:.6g} s; {} has its frames "
                       "and stats.json\n",
                       result.stop_signal, result.stats["sim_time"].get<double>(),
                       result.out_dir.string());
            return 128 + result.stop_signal;
        }
        if (!result.ok) {
            fmt::print(stderr, "karst: {}\nkarst: the last good frame is in {}\n", result.failure,
                       result.out_dir.string());
            return 1;
        }
        if (!run_options.quiet)
            fmt::print(stderr, "karst: done, {} frames in {} ({:.1f} s, {:.3f} MIPPS)\n",
                       result.stats["frames"].get<int>(), result.out_dir.string(),
                       result.stats["wall_time"].get<double>(),
                       result.stats["mipps"].get<double>());
        if (result.render && !run_options.quiet)
            fmt::print(stderr, "karst: rendered {} frames ({:.2f} s each) and {}\n",
                       result.render->frames, result.render->seconds_per_frame,
                       result.render->movie.string());
        return 0;
    } catch (const karst::SceneError& e) {
        fmt::print(stderr, "karst: {}\n", e.what());
        return 2;
    } catch (const std::exception& e) {
        fmt::print(stderr, "karst: error: {}\n", e.what());
        return 1;
    }
}
