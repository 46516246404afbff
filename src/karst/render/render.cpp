#include "karst/render/render.hpp"

#include "karst/core/timer.hpp"
#include "karst/io/output_folder.hpp"
#include "karst/render/ply_reader.hpp"
#include "karst/render/wall_picture.hpp"
#include "karst/scene/geometry.hpp"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <spawn.h>
#include <unistd.h>
#include <sys/wait.h>

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <future>
#include <map>
#include <numbers>
#include <optional>
#include <sstream>
#include <stdexcept>

namespace karst {

namespace fs = std::filesystem;

namespace {

struct Frame {
    std::optional<SurfaceMesh> fluid, porous;
};

std::optional<SurfaceMesh> read_if_present(const fs::path& file) {
    if (!fs::exists(file)) return std::nullopt;
    return read_ply_mesh(file);
}

/// Seconds between frames from log.csv's first two times; 1/30 s without two frames.
double frame_interval(const fs::path& dir) {
    std::ifstream log(dir / "log.csv");
    std::string line;
    std::vector<double> times;
    std::getline(log, line);  // header
    while (times.size() < 2 && std::getline(log, line)) {
        const size_t comma = line.find(',');
        times.push_back(std::stod(line.substr(comma + 1)));
    }
    return times.size() == 2 && times[1] > times[0] ? times[1] - times[0] : 1.0 / 30;
}

std::string quoted(const fs::path& p) {
    std::string s = "'";
    for (char c : p.string()) s += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return s + "'";
}

/// Runs `command` under /bin/sh in a process group of its own, so that a Ctrl-C at the terminal
/// reaches karst (which stops after the current step and still encodes the movie) and not the
/// tool; std::system would ignore SIGINT in karst while it waits. Returns the wait status.
int spawn_and_wait(const std::string& command) {
    posix_spawnattr_t attr;
    posix_spawnattr_init(&attr);
    posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETPGROUP);
    posix_spawnattr_setpgroup(&attr, 0);
    std::string shell = "sh", flag = "-c", line = command;
    char* argv[] = {shell.data(), flag.data(), line.data(), nullptr};
    pid_t pid = 0;
    const int error = posix_spawn(&pid, "/bin/sh", nullptr, &attr, argv, environ);
    posix_spawnattr_destroy(&attr);
    if (error != 0)
        throw std::runtime_error(
            fmt::format("cannot start /bin/sh for '{}': {}", command, std::strerror(error)));
    int status = 0;
    while (waitpid(pid, &status, 0) < 0)
        if (errno != EINTR)
            throw std::runtime_error(
                fmt::format("waiting for '{}': {}", command, std::strerror(errno)));
    return status;
}

/// Runs a tool with its messages in `log`; a failure names the command, how it ended and the
/// log's last lines.
void run_tool(const std::string& command, const char* tool, const fs::path& log) {
    const int status = spawn_and_wait(command + " > " + quoted(log) + " 2>&1");
    if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return;
    const std::string how = WIFSIGNALED(status)
                                ? fmt::format("killed by signal {}", WTERMSIG(status))
                                : fmt::format("exit status {}", WEXITSTATUS(status));
    std::ifstream in(log);
    std::vector<std::string> lines;
    for (std::string line; std::getline(in, line);) lines.push_back(line);
    std::string tail;
    for (size_t k = lines.size() > 4 ? lines.size() - 4 : 0; k < lines.size(); ++k)
        tail += "\n  " + lines[k];
    throw std::runtime_error(
        fmt::format("{} failed ({}): {}{}", tool, how, command,
                    tail.empty() ? "\n(scripts/install_deps.sh installs it)" : tail));
}

std::string vec(const Vec3& v) {
    return fmt::format("<{:.6g},{:.6g},{:.6g}>", v[0], v[1], v[2]);
}

/// A POV-Ray mesh2 of the surface with one texture per distinct vertex colour.
std::string mesh2(const SurfaceMesh& mesh, const std::string& material, const char* interior) {
    std::map<Rgb, int> palette;
    std::vector<int> texture(mesh.vertex_count(), 0);
    for (Index v = 0; v < mesh.vertex_count(); ++v) {
        const Rgb c = mesh.colour.empty() ? Rgb{200, 200, 200} : mesh.colour[v];
        texture[v] = palette.emplace(c, int(palette.size())).first->second;
    }
    std::string out = fmt::format("mesh2 {{\n vertex_vectors {{ {}", mesh.vertex_count());
    for (const Vec3& x : mesh.vertices.x) out += ",\n" + vec(x);
    for (const PointArray& a : mesh.vertices.arrays)
        if (a.name == "normal") {
            out += fmt::format(" }}\n normal_vectors {{ {}", mesh.vertex_count());
            for (Index v = 0; v < mesh.vertex_count(); ++v)
                out += ",\n" + vec(Vec3(a.values[3 * v], a.values[3 * v + 1], a.values[3 * v + 2]));
        }
    out += fmt::format(" }}\n texture_list {{ {}", palette.size());
    std::vector<Rgb> colours(palette.size());
    for (const auto& [c, k] : palette) colours[k] = c;
    for (const Rgb& c : colours)
        out += fmt::format(
            ",\n  texture {{ {} }}",
            fmt::format(fmt::runtime(material), c[0] / 255.0, c[1] / 255.0, c[2] / 255.0));
    out += fmt::format(" }}\n face_indices {{ {}", mesh.triangle_count());
    for (const auto& t : mesh.triangles)
        out += fmt::format(",\n<{},{},{}>,{},{},{}", t[0], t[1], t[2], texture[t[0]], texture[t[1]],
                           texture[t[2]]);
    return out + fmt::format(" }}\n {}\n}}\n", interior);
}

/// The camera of `settings`, its missing parts framed on `box`: seen from the front left and
/// above, at 0.85 of the distance at which the box's bounding sphere fills the narrower field of
/// view (a box's picture is smaller than its sphere's).
Camera frame_camera(const Aabb& box, const RenderSettings& settings, Real aspect) {
    Camera c;
    const Vec3 size = box.max - box.min;
    const Real radius = 0.5 * size.norm();
    c.fov = settings.fov;
    c.target = settings.camera_target.value_or(0.5 * (box.min + box.max));
    const Real fov = settings.fov * std::numbers::pi / 180;  // horizontal
    const Real vertical = 2 * std::atan(std::tan(0.5 * fov) / aspect);
    const Real fit = radius / std::sin(0.5 * std::min(fov, vertical));
    c.location =
        settings.camera_position.value_or(c.target + 0.85 * fit * Vec3(0.45, -1, 0.6).normalized());
    c.sun = c.target + radius * Vec3(-3, -4, 8);
    c.ground = box.min.z() - 1e-3 * radius;
    c.scale = std::max(radius / 4, Real(1e-3));
    return c;
}

std::string pov_scene(const SurfaceMesh* fluid, const SurfaceMesh* porous,
                      const std::vector<PicturedWall>& walls, const Camera& camera,
                      const RenderOptions& options, Real aspect) {
    std::string pov = "#version 3.7;\nglobal_settings { assumed_gamma 1.0 max_trace_level 10 }\n";
    pov +=
        "sky_sphere { pigment { gradient z color_map { [0 srgb <0.93,0.95,0.98>] [1 srgb "
        "<0.55,0.7,0.9>] } } }\n";
    pov += fmt::format(
        "camera {{ perspective location {} sky <0,0,1> right <{:.6g},0,0> look_at {} angle "
        "{:.6g} }}\n",
        vec(camera.location), -aspect, vec(camera.target), camera.fov);
    const Real r = camera.scale;
    if (options.preview)
        pov += fmt::format("light_source {{ {} srgb <1,0.97,0.92> }}\n", vec(camera.sun));
    else
        pov += fmt::format(
            "light_source {{ {} srgb <1,0.97,0.92> area_light <{:.6g},0,0>, <0,{:.6g},0>, 5, 5 "
            "adaptive 1 jitter circular orient }}\n",
            vec(camera.sun), r, r);
    pov += fmt::format("light_source {{ {} srgb 0.3 shadowless }}\n", vec(camera.location));
    pov += fmt::format(
        "plane {{ z, {:.6g} texture {{ pigment {{ checker srgb 0.8 srgb 0.7 scale {:.6g} }} "
        "finish {{ diffuse 0.8 }} }} }}\n",
        camera.ground, r);
    pov += pov_walls(walls, camera.location);
    if (porous && porous->triangle_count() > 0)
        pov += mesh2(*porous,
                     "pigment {{ srgb <{:.4f},{:.4f},{:.4f}> }} finish {{ diffuse 0.85 "
                     "specular 0.05 }}",
                     "");
    if (fluid && fluid->triangle_count() > 0) {
        if (options.preview)
            pov += mesh2(*fluid,
                         "pigment {{ srgbt <{:.4f},{:.4f},{:.4f},0.25> }} finish {{ specular 0.7 "
                         "roughness 0.005 }}",
                         "");
        else
            pov += mesh2(*fluid,
                         "pigment {{ srgbf <{:.4f},{:.4f},{:.4f},0.75> }} finish {{ diffuse 0.25 "
                         "specular 0.8 roughness 0.003 reflection {{ 0.03, 0.4 fresnel on }} "
                         "conserve_energy }}",
                         "inside_vector <0,0,1> interior { ior 1.33 }");
    }
    return pov;
}

/// render.json's settings and walls (defaults and none without the file).
std::pair<RenderSettings, std::vector<PicturedWall>> read_render_settings(const fs::path& file) {
    RenderSettings s;
    std::vector<PicturedWall> walls;
    if (!fs::exists(file)) return {s, walls};
    try {
        const nlohmann::json j = nlohmann::json::parse(std::ifstream(file));
        auto point = [&](const char* name) -> std::optional<Vec3> {
            if (!j.contains(name) || j[name].is_null()) return std::nullopt;
            return Vec3(j[name][0].get<Real>(), j[name][1].get<Real>(), j[name][2].get<Real>());
        };
        s.camera_position = point("camera_position"), s.camera_target = point("camera_target");
        s.fov = j.at("fov"), s.width = j.at("width"), s.height = j.at("height");
        s.samples = j.at("samples");
        if (j.contains("walls")) walls = walls_from_json(j["walls"]);
    } catch (const nlohmann::json::exception& e) {
        throw std::runtime_error(fmt::format("cannot read '{}': {}", file.string(), e.what()));
    }
    return {s, walls};
}

}  // namespace

std::string render_settings_json(const RenderSettings& s, const std::vector<PicturedWall>& walls) {
    auto point = [](const std::optional<Vec3>& p) {
        return p ? nlohmann::json::array({(*p)[0], (*p)[1], (*p)[2]}) : nlohmann::json();
    };
    return nlohmann::json{{"camera_position", point(s.camera_position)},
                          {"camera_target", point(s.camera_target)},
                          {"fov", s.fov},
                          {"width", s.width},
                          {"height", s.height},
                          {"samples", s.samples},
                          {"walls", walls_to_json(walls)}}
               .dump(2) +
           "\n";
}

namespace {

/// The frame's surfaces as written (absent files give absent surfaces).
Frame read_frame(const fs::path& dir, int f) {
    return {read_if_present(dir / fmt::format("fluid_surface_{:04d}.ply", f)),
            read_if_present(dir / fmt::format("porous_surface_{:04d}.ply", f))};
}

void extend(Aabb& box, const Frame& frame) {
    for (const auto* m : {&frame.fluid, &frame.porous})
        if (*m)
            for (const Vec3& x : (*m)->vertices.x) box.extend(x);
}

std::string read_bytes(const fs::path& file) {
    std::ifstream in(file, std::ios::binary);
    std::stringstream bytes;
    bytes << in.rdbuf();
    return bytes.str();
}

/// POV-Ray's picture of `pov` as PNG bytes; `stem` names its scratch files in the folder.
std::string render_png(const RenderView& view, const std::string& stem, const std::string& pov) {
    const fs::path pov_file = view.dir / (stem + ".pov"), png_file = view.dir / (stem + ".png"),
                   log_file = view.dir / (stem + ".log");
    std::ofstream(pov_file) << pov;
    const RenderOptions& o = view.options;
    // The scratch files go also when POV-Ray fails (its log's tail is in the message).
    auto remove_scratch = [&] {
        std::error_code ignored;
        for (const fs::path& f : {pov_file, png_file, log_file}) fs::remove(f, ignored);
    };
    try {
        run_tool(fmt::format("povray +I{} +O{} +W{} +H{} +FN -D -V {} {}", quoted(pov_file),
                             quoted(png_file), view.width, view.height,
                             o.threads > 0 ? fmt::format("+WT{}", o.threads) : "",
                             o.preview ? "-A" : fmt::format("+A0.2 +AM2 +R{}", view.samples)),
                 "povray", log_file);
    } catch (...) {
        remove_scratch();
        throw;
    }
    std::string png = read_bytes(png_file);
    remove_scratch();
    if (png.empty()) throw std::runtime_error("povray exited without writing a picture: " + stem);
    return png;
}

/// movie.mp4 of render_NNNN.png at the run's frame rate.
fs::path encode_movie(const fs::path& dir, OutputFolder& folder) {
    const fs::path movie_tmp = dir / ".movie.mp4", log_file = dir / ".movie.log";
    run_tool(
        fmt::format("ffmpeg -y -loglevel error -framerate {:.6g} -i {} -c:v libx264 "
                    "-pix_fmt yuv420p -movflags +faststart {}",
                    1 / frame_interval(dir), quoted(dir / "render_%04d.png"), quoted(movie_tmp)),
        "ffmpeg", log_file);
    folder.write("movie.mp4", read_bytes(movie_tmp));
    fs::remove(movie_tmp), fs::remove(log_file);
    return dir / "movie.mp4";
}

}  // namespace

RenderView::RenderView(fs::path dir_, const RenderOptions& options_, const RenderSettings& settings,
                       const Aabb& box, std::vector<PicturedWall> walls_)
    : dir(std::move(dir_)),
      options(options_),
      width(options_.width.value_or(settings.width)),
      height(options_.height.value_or(settings.height)),
      samples(settings.samples),
      camera(frame_camera(box, settings, Real(width) / height)),
      walls(std::move(walls_)) {}

std::string RenderView::scene(const SurfaceMesh* fluid, const SurfaceMesh* porous) const {
    return pov_scene(fluid, porous, walls, camera, options, Real(width) / height);
}

std::string RenderView::scene(const fs::path& dir, int f) const {
    const Frame frame = read_frame(dir, f);
    return scene(frame.fluid ? &*frame.fluid : nullptr, frame.porous ? &*frame.porous : nullptr);
}

RenderResult render_run(const fs::path& dir, const RenderOptions& options) {
    // The box that holds every frame's surfaces frames the camera; the frames are read again
    // one at a time to render them, so a long run does not have to fit in memory.
    int frames = 0;
    Aabb box;
    for (;; ++frames) {
        const Frame frame = read_frame(dir, frames);
        if (!frame.fluid && !frame.porous) break;
        extend(box, frame);
    }
    if (frames == 0 || box.empty())
        throw std::runtime_error(fmt::format(
            "'{}' has no surface frames (fluid_surface_0000.ply or porous_surface_0000.ply): a "
            "run writes them unless /output/fluid_surface and /output/porous_surface are off",
            dir.string()));
    auto [settings, walls] = read_render_settings(dir / "render.json");
    const RenderView view(dir, options, settings, box, std::move(walls));
    OutputFolder folder(dir, OutputFolder::Resume{});
    RenderResult result;
    Stopwatch rendering;
    for (int f = 0; f < frames; ++f)
        folder.write(fmt::format("render_{:04d}.png", f),
                     render_png(view, ".render", view.scene(dir, f)));
    result.frames = frames;
    result.seconds_per_frame = rendering.seconds() / frames;
    result.movie = encode_movie(dir, folder);
    return result;
}

void check_render_tools() {
    for (const char* tool : {"povray", "ffmpeg"})
        if (std::system(fmt::format("command -v {} > /dev/null 2>&1", tool).c_str()) != 0)
            throw std::runtime_error(fmt::format(
                "--render needs {}, which is not installed (scripts/install_deps.sh installs it)",
                tool));
}

LiveRenderer::LiveRenderer(fs::path dir, const RenderOptions& options,
                           const RenderSettings& settings, std::optional<Aabb> domain,
                           const Aabb& wall_particles, std::vector<PicturedWall> walls)
    : m_dir(std::move(dir)),
      m_options(options),
      m_settings(settings),
      m_domain(domain),
      m_wall_particles(wall_particles),
      m_walls(std::move(walls)) {}

LiveRenderer::~LiveRenderer() {
    if (m_job.valid()) m_job.wait();
}

void LiveRenderer::collect(OutputFolder& folder) {
    if (!m_job.valid()) return;
    try {
        const auto [png, seconds] = m_job.get();
        folder.write(fmt::format("render_{:04d}.png", m_job_frame), png);
        m_seconds += seconds, ++m_rendered;
    } catch (const std::exception& e) {
        // The simulation goes on (its frames matter more than their pictures); finish() says.
        if (m_failure.empty()) m_failure = fmt::format("frame {}: {}", m_job_frame, e.what());
    }
}

void LiveRenderer::add(int frame, const SurfaceMesh* fluid, const SurfaceMesh* porous,
                       OutputFolder& folder) {
    if (!m_failure.empty()) return;
    if (!m_view) {
        // The camera holds still: the domain, or the walls and this first frame's surfaces.
        Aabb box = m_domain.value_or(m_wall_particles);
        if (!m_domain)
            for (const SurfaceMesh* m : {fluid, porous})
                if (m)
                    for (const Vec3& x : m->vertices.x) box.extend(x);
        if (box.empty()) return;  // nothing to frame yet
        m_view.emplace(m_dir, m_options, m_settings, box, m_walls);
    }
    std::string pov = m_view->scene(fluid, porous);
    collect(folder);  // one job at a time: the simulation waits for the previous frame
    m_job_frame = frame;
    m_job = std::async(std::launch::async, [view = &*m_view, pov = std::move(pov)] {
        Stopwatch watch;
        std::string png = render_png(*view, ".render_live", pov);
        return std::pair(std::move(png), watch.seconds());
    });
}

RenderResult LiveRenderer::finish(int frames, OutputFolder& folder) {
    collect(folder);
    if (!m_failure.empty())
        throw std::runtime_error(
            fmt::format("rendering stopped at {} (the run's frames and stats.json are written; "
                        "karst render renders them)",
                        m_failure));
    RenderResult result;
    if (!m_view) throw std::runtime_error("the run has no surfaces to render");
    // Frames the live renderer did not see (a resumed run's earlier ones) are rendered from
    // their PLY files with the same camera.
    for (int f = 0; f < frames; ++f) {
        const std::string name = fmt::format("render_{:04d}.png", f);
        if (fs::exists(m_dir / name)) continue;
        folder.write(name, render_png(*m_view, ".render_live", m_view->scene(m_dir, f)));
    }
    result.frames = frames;
    result.seconds_per_frame = m_rendered > 0 ? m_seconds / m_rendered : 0;
    result.movie = encode_movie(m_dir, folder);
    return result;
}

}  // namespace karst
