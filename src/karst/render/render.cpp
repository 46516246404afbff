#include "karst/render/render.hpp"

#include "karst/core/timer.hpp"
#include "karst/io/output_folder.hpp"
#include "karst/render/ply_reader.hpp"
#include "karst/scene/geometry.hpp"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdlib>
#include <fstream>
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

/// Runs a tool with its messages in `log`; a failure names the command and the log's last lines.
void run_tool(const std::string& command, const char* tool, const fs::path& log) {
    const int status = std::system((command + " > " + quoted(log) + " 2>&1").c_str());
    if (status == 0) return;
    std::ifstream in(log);
    std::vector<std::string> lines;
    for (std::string line; std::getline(in, line);) lines.push_back(line);
    std::string tail;
    for (size_t k = lines.size() > 4 ? lines.size() - 4 : 0; k < lines.size(); ++k)
        tail += "\n  " + lines[k];
    throw std::runtime_error(
        fmt::format("{} failed (exit status {}): {}{}", tool, status, command,
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

struct Camera {
    Vec3 location, target, sun;
    Real ground = 0, scale = 1, fov = 40;
};

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

std::string pov_scene(const Frame& frame, const Camera& camera, const RenderOptions& options,
                      Real aspect) {
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
    if (frame.porous && frame.porous->triangle_count() > 0)
        pov += mesh2(*frame.porous,
                     "pigment {{ srgb <{:.4f},{:.4f},{:.4f}> }} finish {{ diffuse 0.85 "
                     "specular 0.05 }}",
                     "");
    if (frame.fluid && frame.fluid->triangle_count() > 0) {
        if (options.preview)
            pov += mesh2(*frame.fluid,
                         "pigment {{ srgbt <{:.4f},{:.4f},{:.4f},0.25> }} finish {{ specular 0.7 "
                         "roughness 0.005 }}",
                         "");
        else
            pov += mesh2(*frame.fluid,
                         "pigment {{ srgbf <{:.4f},{:.4f},{:.4f},0.75> }} finish {{ diffuse 0.25 "
                         "specular 0.8 roughness 0.003 reflection {{ 0.03, 0.4 fresnel on }} "
                         "conserve_energy }}",
                         "inside_vector <0,0,1> interior { ior 1.33 }");
    }
    return pov;
}

RenderSettings read_render_settings(const fs::path& file) {
    RenderSettings s;
    if (!fs::exists(file)) return s;
    try {
        const nlohmann::json j = nlohmann::json::parse(std::ifstream(file));
        auto point = [&](const char* name) -> std::optional<Vec3> {
            if (!j.contains(name) || j[name].is_null()) return std::nullopt;
            return Vec3(j[name][0].get<Real>(), j[name][1].get<Real>(), j[name][2].get<Real>());
        };
        s.camera_position = point("camera_position"), s.camera_target = point("camera_target");
        s.fov = j.at("fov"), s.width = j.at("width"), s.height = j.at("height");
        s.samples = j.at("samples");
    } catch (const nlohmann::json::exception& e) {
        throw std::runtime_error(fmt::format("cannot read '{}': {}", file.string(), e.what()));
    }
    return s;
}

}  // namespace

std::string render_settings_json(const RenderSettings& s) {
    auto point = [](const std::optional<Vec3>& p) {
        return p ? nlohmann::json::array({(*p)[0], (*p)[1], (*p)[2]}) : nlohmann::json();
    };
    return nlohmann::json{{"camera_position", point(s.camera_position)},
                          {"camera_target", point(s.camera_target)},
                          {"fov", s.fov},
                          {"width", s.width},
                          {"height", s.height},
                          {"samples", s.samples}}
               .dump(2) +
           "\n";
}

RenderResult render_run(const fs::path& dir, const RenderOptions& options) {
    // Frames with a surface, and the box that holds them all.
    std::vector<Frame> frames;
    Aabb box;
    for (int f = 0;; ++f) {
        Frame frame{read_if_present(dir / fmt::format("fluid_surface_{:04d}.ply", f)),
                    read_if_present(dir / fmt::format("porous_surface_{:04d}.ply", f))};
        if (!frame.fluid && !frame.porous) break;
        for (const auto* m : {&frame.fluid, &frame.porous})
            if (*m)
                for (const Vec3& x : (*m)->vertices.x) box.extend(x);
        frames.push_back(std::move(frame));
    }
    if (frames.empty() || box.min.x() > box.max.x())
        throw std::runtime_error(fmt::format(
            "'{}' has no surface frames (fluid_surface_0000.ply or porous_surface_0000.ply): a "
            "run writes them unless /output/fluid_surface and /output/porous_surface are off",
            dir.string()));
    const RenderSettings settings = read_render_settings(dir / "render.json");
    const int width = options.width.value_or(settings.width),
              height = options.height.value_or(settings.height);
    const Real aspect = Real(width) / height;
    const Camera camera = frame_camera(box, settings, aspect);

    OutputFolder folder(dir, OutputFolder::Resume{});
    RenderResult result;
    Stopwatch rendering;
    const fs::path pov_file = dir / ".render.pov", png_file = dir / ".render.png",
                   log_file = dir / ".render.log";
    for (size_t f = 0; f < frames.size(); ++f) {
        std::ofstream(pov_file) << pov_scene(frames[f], camera, options, aspect);
        run_tool(
            fmt::format("povray +I{} +O{} +W{} +H{} +FN -D -V {} {}", quoted(pov_file),
                        quoted(png_file), width, height,
                        options.threads > 0 ? fmt::format("+WT{}", options.threads) : "",
                        options.preview ? "-A" : fmt::format("+A0.2 +AM2 +R{}", settings.samples)),
            "povray", log_file);
        std::ifstream png(png_file, std::ios::binary);
        std::stringstream bytes;
        bytes << png.rdbuf();
        folder.write(fmt::format("render_{:04d}.png", f), bytes.str());
    }
    result.frames = int(frames.size());
    result.seconds_per_frame = rendering.seconds() / frames.size();
    fs::remove(pov_file), fs::remove(png_file);

    const fs::path movie_tmp = dir / ".movie.mp4";
    run_tool(
        fmt::format("ffmpeg -y -loglevel error -framerate {:.6g} -i {} -c:v libx264 "
                    "-pix_fmt yuv420p -movflags +faststart {}",
                    1 / frame_interval(dir), quoted(dir / "render_%04d.png"), quoted(movie_tmp)),
        "ffmpeg", log_file);
    std::ifstream movie(movie_tmp, std::ios::binary);
    std::stringstream bytes;
    bytes << movie.rdbuf();
    folder.write("movie.mp4", bytes.str());
    fs::remove(movie_tmp), fs::remove(log_file);
    result.movie = dir / "movie.mp4";
    return result;
}

}  // namespace karst
