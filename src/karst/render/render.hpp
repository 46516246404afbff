#pragma once
// `karst render`: the surfaces of a run's output folder as PNG frames (POV-Ray 3.7) and an MP4
// (ffmpeg, H.264 yuv420p). Water is glass-like and tinted by its M29 colour, rock shaded by its
// colour (darker when wet), on a ground under a soft sun; the camera frames every frame's
// surfaces at once, so it holds still.
#include "karst/io/output_folder.hpp"
#include "karst/render/wall_picture.hpp"
#include "karst/scene/geometry.hpp"
#include "karst/scene/scene.hpp"
#include "karst/surface/surface_mesh.hpp"

#include <filesystem>
#include <future>
#include <optional>
#include <string>
#include <utility>

namespace karst {

struct RenderOptions {
    bool preview = false;              ///< no refraction, no area light, no anti-aliasing
    std::optional<int> width, height;  ///< override the run's /render/width and height
    int threads = 0;                   ///< POV-Ray render threads (0: all cores)
};

/// render.json, which a run writes into its folder for karst render: the scene's /render block
/// and its walls.
std::string render_settings_json(const RenderSettings& settings,
                                 const std::vector<PicturedWall>& walls);

struct RenderResult {
    int frames = 0;
    std::filesystem::path movie;
    double seconds_per_frame = 0;  ///< POV-Ray's wall time per frame
};

struct Camera {
    Vec3 location, target, sun;
    Real ground = 0, scale = 1, fov = 40;
};

/// How a run's frames are pictured: the folder, the options, the picture size, the camera and
/// the walls.
struct RenderView {
    RenderView(std::filesystem::path dir, const RenderOptions& options,
               const RenderSettings& settings, const Aabb& box, std::vector<PicturedWall> walls);
    /// The POV-Ray scene of a frame's surfaces (either may be absent).
    std::string scene(const SurfaceMesh* fluid, const SurfaceMesh* porous) const;
    /// The POV-Ray scene of frame `f`'s surfaces as written in `dir` (PLY).
    std::string scene(const std::filesystem::path& dir, int f) const;
    std::filesystem::path dir;
    RenderOptions options;
    int width, height, samples;
    Camera camera;  ///< the settings' camera, its missing parts framed on the box
    std::vector<PicturedWall> walls;
};

/// Renders render_NNNN.png for every frame with a surface in `dir` and movie.mp4 at the run's
/// frame rate (log.csv), listing them in the folder's manifest, with the folder's render.json
/// settings and walls (defaults and none without one); the frames are read one at a time. Throws
/// std::runtime_error when the folder has no surfaces or POV-Ray or ffmpeg fails (or is missing).
RenderResult render_run(const std::filesystem::path& dir, const RenderOptions& options);

/// Throws std::runtime_error naming the tool when POV-Ray or ffmpeg is not installed.
void check_render_tools();

/// `karst run --render`: renders each frame as the run writes it. POV-Ray pictures a frame on
/// its own thread while the simulation computes the next (one frame at a time: the run waits
/// for the previous picture before it sends the next), and movie.mp4 is encoded at the end.
/// The camera holds still: the /render settings, framed on the scene's domain or, without
/// one, on the walls and the first frame's surfaces.
class LiveRenderer {
public:
    /// (check_render_tools first, before the run claims its folder.)
    LiveRenderer(std::filesystem::path dir, const RenderOptions& options,
                 const RenderSettings& settings, std::optional<Aabb> domain,
                 const Aabb& wall_particles, std::vector<PicturedWall> walls);
    ~LiveRenderer();
    /// Sends frame `frame` to POV-Ray after writing the previous frame's picture into `folder`.
    void add(int frame, const SurfaceMesh* fluid, const SurfaceMesh* porous, OutputFolder& folder);
    /// Writes the last picture, renders frames below `frames` that have none (a resumed run's
    /// earlier frames) from their PLY files, and encodes movie.mp4. A picture that failed during
    /// the run (which went on without pictures) throws here, after the run's output is written.
    RenderResult finish(int frames, OutputFolder& folder);

private:
    void collect(OutputFolder& folder);
    std::filesystem::path m_dir;
    RenderOptions m_options;
    RenderSettings m_settings;
    std::optional<Aabb> m_domain;
    Aabb m_wall_particles;
    std::vector<PicturedWall> m_walls;
    std::optional<RenderView> m_view;  ///< set at the first frame with something to frame
    std::future<std::pair<std::string, double>> m_job;  ///< PNG bytes and POV-Ray seconds
    int m_job_frame = -1, m_rendered = 0;
    std::string m_failure;  ///< the first picture that failed; no later frame is sent
    double m_seconds = 0;
};

}  // namespace karst
