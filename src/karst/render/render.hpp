#pragma once
// `karst render`: the surfaces of a run's output folder as PNG frames (POV-Ray 3.7) and an MP4
// (ffmpeg, H.264 yuv420p). Water is glass-like and tinted by its M29 colour, rock shaded by its
// colour (darker when wet), on a ground under a soft sun; the camera frames every frame's
// surfaces at once, so it holds still.
#include "karst/scene/scene.hpp"

#include <filesystem>
#include <optional>
#include <string>

namespace karst {

struct RenderOptions {
    bool preview = false;              ///< no refraction, no area light, no anti-aliasing
    std::optional<int> width, height;  ///< override the run's /render/width and height
    int threads = 0;                   ///< POV-Ray render threads (0: all cores)
};

/// render.json, which a run writes into its folder: the scene's /render block for karst render.
std::string render_settings_json(const RenderSettings& settings);

struct RenderResult {
    int frames = 0;
    std::filesystem::path movie;
    double seconds_per_frame = 0;  ///< POV-Ray's wall time per frame
};

/// Renders render_NNNN.png for every frame with a surface in `dir` and movie.mp4 at the run's
/// frame rate (log.csv), listing them in the folder's manifest, with the folder's render.json
/// settings (defaults without one). Throws std::runtime_error when
/// the folder has no surfaces or POV-Ray or ffmpeg fails (or is missing).
RenderResult render_run(const std::filesystem::path& dir, const RenderOptions& options);

}  // namespace karst
