#pragma once
// A whole run: model, state, the time loop with frame cadence, output and the watchdog.
#include "karst/render/render.hpp"
#include "karst/scene/scene.hpp"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <optional>
#include <string>

namespace karst {

/// Most worker threads --threads accepts (TBB uses at most the machine's cores anyway).
inline constexpr int k_max_threads = 1024;
/// Longest --checkpoint-every (simulated s) and most --checkpoint-keep.
inline constexpr double k_max_checkpoint_interval = 1e6;
inline constexpr int k_max_checkpoints_kept = 1000;

struct RunOptions {
    std::optional<std::filesystem::path> out_dir;  ///< default out/<scene name>/
    std::optional<double> end_time;                ///< s; overrides /time/end
    std::optional<double> fps;                     ///< overrides /output/fps
    int threads = 0;                               ///< 0: all cores
    bool quiet = false;
    bool overwrite = false;  ///< write into a non-empty folder no karst run wrote
    /// Simulated seconds between checkpoints (sim/checkpoint.hpp); one is also written at the
    /// end and when a signal stops the run. None when not given.
    std::optional<double> checkpoint_every;
    int checkpoint_keep = 2;  ///< newest checkpoints kept in the folder
    /// Continue the run in this folder from its newest checkpoint (frames and stats go there).
    std::optional<std::filesystem::path> resume;
    /// Render each frame as it is written, and movie.mp4 at the end (render/render.hpp).
    std::optional<RenderOptions> render;
};

struct RunResult {
    bool ok = true;
    std::string failure;  ///< watchdog message when !ok
    int stop_signal = 0;  ///< SIGINT or SIGTERM that stopped the run early (sim/stop_signal.hpp)
    std::filesystem::path out_dir;
    nlohmann::json stats;  ///< what stats.json holds
    std::optional<RenderResult>
        render;  ///< with RunOptions::render, unless the watchdog stopped it
};

/// Runs `scene` to its end time, writing frames (or continues it from a checkpoint, bit for bit
/// as if it had never stopped). Throws SceneError before writing anything if the scene, the
/// options or the checkpoint are bad; a watchdog stop returns ok = false after writing the last
/// good frame and stats.json.
RunResult run_simulation(const Scene& scene, const RunOptions& options);

}  // namespace karst
