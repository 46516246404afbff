// `karst render` (issue 14): a cave_soak run renders to one PNG per frame and an MP4 whose frame
// count ffprobe confirms, and a frame shows water and rock, not a blank picture; `karst run
// --render` makes its pictures while the run goes on.
#include "karst/render/wall_picture.hpp"
#include "support/files.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fmt/format.h>

#include <csignal>
#include <filesystem>
#include <fstream>

namespace karst {
namespace {

namespace fs = std::filesystem;

bool on_path(const char* tool) {
    return std::system(fmt::format("command -v {} > /dev/null 2>&1", tool).c_str()) == 0;
}

/// The text a shell command prints.
std::string output_of(const std::string& command) {
    std::string out;
    if (FILE* pipe = popen(command.c_str(), "r")) {
        char buffer[4096];
        for (size_t n; (n = fread(buffer, 1, sizeof buffer, pipe)) > 0;) out.append(buffer, n);
        pclose(pipe);
    }
    return out;
}

TEST(Render, TheCaveSoakRendersAFramePerSurfaceAndAMovie) {
    for (const char* tool : {"povray", "ffmpeg", "ffprobe"})
        if (!on_path(tool))
            GTEST_SKIP() << tool << " is not installed (scripts/install_deps.sh installs it)";
    const test::TempDir dir("render");
    const fs::path out = dir.path / "out";
    const std::string karst = KARST_BINARY;
    ASSERT_EQ(test::exit_code_of(karst + " run " + KARST_SOURCE_DIR +
                                 "/scenes/cave_soak.json --quiet --end-time 0.1 --fps 20 --out " +
                                 out.string()),
              0);
    ASSERT_EQ(test::exit_code_of(karst + " render " + out.string() +
                                 " --preview --width 320 --height 180"),
              0);
    int pngs = 0;
    for (const auto& e : fs::directory_iterator(out)) pngs += e.path().extension() == ".png";
    EXPECT_EQ(pngs, 3);  // frames at 0, 0.05 and 0.1 s
    const std::string frames = output_of(
        "ffprobe -v error -count_frames -select_streams v:0 -show_entries "
        "stream=nb_read_frames,codec_name,pix_fmt -of csv=p=0 " +
        (out / "movie.mp4").string());
    EXPECT_EQ(frames, "h264,yuv420p,3\n");

    // The last frame's pixels: bluish water and sandy rock are both there.
    const std::string rgb = output_of("ffmpeg -v error -i " + (out / "render_0002.png").string() +
                                      " -f rawvideo -pix_fmt rgb24 -");
    ASSERT_EQ(rgb.size(), 320u * 180 * 3);
    int water = 0, rock = 0;
    for (size_t p = 0; p < rgb.size(); p += 3) {
        const int r = std::uint8_t(rgb[p]), g = std::uint8_t(rgb[p + 1]),
                  b = std::uint8_t(rgb[p + 2]);
        water += b > r + 25 && b >= g;
        rock += r > b + 40 && g > b + 15;
    }
    EXPECT_GT(water, 150);  // the 0.1 m water cube covers about 1,000 pixels
    EXPECT_GT(rock, 5000);
    // The manifest lists the renders: a rerun into the folder removes them.
    const std::string manifest = test::read_text(out / "manifest.txt");
    EXPECT_NE(manifest.find("render_0002.png"), std::string::npos);
    EXPECT_NE(manifest.find("movie.mp4"), std::string::npos);
}

TEST(Render, ARunRendersItsFramesAsItGoes) {
    for (const char* tool : {"povray", "ffmpeg"})
        if (!on_path(tool))
            GTEST_SKIP() << tool << " is not installed (scripts/install_deps.sh installs it)";
    // The built-in dam break with an end far away, stopped once its second picture is out: the
    // pictures came during the run, and the stopped run still ends with every frame's picture
    // and the movie.
    const test::TempDir dir("render_live");
    const fs::path out = dir.path / "out";
    const std::string picture = (out / "render_0001.png").string();
    std::string command = fmt::format(
        "({} run --quiet --end-time 20 --fps 20 --render --preview --width 160 --height 90 "
        "--out {} & pid=$!; while [ ! -f {} ]; do sleep 0.05; done; kill -TERM $pid; wait $pid)",
        KARST_BINARY, out.string(), picture);
    std::string err;
    EXPECT_EQ(test::exit_code_of(command, &err), 128 + SIGTERM) << err;
    const nlohmann::json stats = nlohmann::json::parse(test::read_text(out / "stats.json"));
    const int frames = stats["frames"];
    EXPECT_GE(frames, 2);
    EXPECT_LT(stats["sim_time"].get<double>(), 20);
    for (int f = 0; f < frames; ++f)
        EXPECT_TRUE(fs::exists(out / fmt::format("render_{:04d}.png", f))) << f;
    EXPECT_FALSE(fs::exists(out / fmt::format("render_{:04d}.png", frames)));
    EXPECT_TRUE(fs::exists(out / "movie.mp4"));
    for (const auto& e : fs::directory_iterator(out))
        EXPECT_NE(e.path().filename().string()[0], '.') << e.path();  // no scratch file left
}

TEST(Render, AFolderWithoutSurfacesIsRefusedWithTheReason) {
    const test::TempDir dir("render_empty");
    std::string err;
    EXPECT_EQ(test::exit_code_of(std::string(KARST_BINARY) + " render " + dir.path.string(), &err),
              1);
    EXPECT_NE(err.find("no surface frames"), std::string::npos) << err;
}

}  // namespace
}  // namespace karst

namespace karst {
namespace {

const char* k_block = R"({ "name": "cam", "particle_spacing": 0.05, "time": { "end": 0.02 },
  "fluid_blocks": [ { "shape": { "type": "box", "min": [0, 0, 0], "max": [0.2, 0.2, 0.2] } } ],
  "walls": [ { "kind": "container", "shape": { "type": "box", "min": [0, 0, 0], "max": [0.4, 0.4, 0.4] } } ],
  "render": { RENDER } })";

std::string with_render(const std::string& render) {
    std::string scene = k_block;
    return scene.replace(scene.find("RENDER"), 6, render);
}

TEST(Render, TheRenderBlockOfTheSceneReachesTheRunFolder) {
    const test::TempDir dir("render_block");
    std::ofstream(dir.path / "scene.json") << with_render(
        R"("camera_position": [1, -2, 1.5], "fov": 55, "width": 640, "height": 360, "samples": 3)");
    const fs::path out = dir.path / "out";
    ASSERT_EQ(
        test::exit_code_of(std::string(KARST_BINARY) + " run " +
                           (dir.path / "scene.json").string() + " --quiet --out " + out.string()),
        0);
    const auto settings = nlohmann::json::parse(test::read_text(out / "render.json"));
    EXPECT_EQ(settings["camera_position"], nlohmann::json::array({1.0, -2.0, 1.5}));
    EXPECT_TRUE(settings["camera_target"].is_null());  // framed on the surfaces
    EXPECT_EQ(settings["fov"], 55.0);
    EXPECT_EQ(settings["width"], 640);
    EXPECT_EQ(settings["height"], 360);
    EXPECT_EQ(settings["samples"], 3);
    // The walls, for karst render to draw: the container and its thickness (2 layers x dx).
    ASSERT_EQ(settings["walls"].size(), 1u);
    EXPECT_EQ(settings["walls"][0]["container"], true);
    EXPECT_DOUBLE_EQ(settings["walls"][0]["thickness"].get<double>(), 0.1);
    EXPECT_EQ(settings["walls"][0]["shape"]["type"], "box");
    EXPECT_EQ(settings["walls"][0]["shape"]["max"], nlohmann::json::array({0.4, 0.4, 0.4}));
}

TEST(Render, WallsAreDrawnAsTheirShapes) {
    auto shape = [](Shape::Kind kind, Vec3 a, Vec3 b, Real radius) {
        Shape s;
        s.kind = kind, s.a = a, s.b = b, s.radius = radius;
        return s;
    };
    const Shape pillar = shape(Shape::Kind::Cylinder, {1, 0.3, 0}, {1, 0.3, 0.3}, 0.08);
    const Shape tank = shape(Shape::Kind::Box, Vec3::Zero(), {1.6, 0.6, 0.8}, 0);
    Shape ring = shape(Shape::Kind::Difference, Vec3::Zero(), Vec3::Zero(), 0);
    ring.children = {shape(Shape::Kind::Sphere, Vec3::Zero(), Vec3::Zero(), 1),
                     shape(Shape::Kind::Sphere, Vec3::Zero(), Vec3::Zero(), 0.5)};
    const std::vector<PicturedWall> walls{
        {pillar, false, 0.04}, {tank, true, 0.04}, {ring, false, 0.02}};
    // render.json keeps every shape, nested ones too.
    const std::vector<PicturedWall> back = walls_from_json(walls_to_json(walls));
    ASSERT_EQ(back.size(), 3u);
    EXPECT_EQ(back[0].shape.kind, Shape::Kind::Cylinder);
    EXPECT_EQ(back[0].shape.b, pillar.b);
    EXPECT_EQ(back[0].shape.radius, 0.08);
    EXPECT_TRUE(back[1].container);
    ASSERT_EQ(back[2].shape.children.size(), 2u);
    EXPECT_EQ(back[2].shape.children[1].radius, 0.5);
    // The obstacle is its own shape; the container a shell of the walls' thickness around the
    // space it holds, without the walls and lid on the camera's side (here: y < 0 and z > 0.8).
    const std::string pov = pov_walls(walls, Vec3(0.8, -2, 1.5));
    EXPECT_NE(pov.find("cylinder { <1,0.3,0>, <1,0.3,0.3>, 0.08 }"), std::string::npos) << pov;
    EXPECT_NE(pov.find("difference { box { <-0.04,-0.04,-0.04>, <1.64,0.64,0.84> } box { <0,0,0>, "
                       "<1.6,0.6,0.8> } box { <-2.64,-2.64,-2.64>, <4.24,0.0016,3.44> } box { "
                       "<-2.64,-2.64,0.7984>, "
                       "<4.24,3.24,3.44> }"),
              std::string::npos)
        << pov;
    EXPECT_NE(pov.find("difference { sphere { <0,0,0>, 1 } sphere { <0,0,0>, 0.5 } }"),
              std::string::npos)
        << pov;
    // A container whose held space takes away a cylinder shorter than twice the walls'
    // thickness: the grown shape takes away nothing (not an inside-out cylinder).
    Shape cup = shape(Shape::Kind::Difference, Vec3::Zero(), Vec3::Zero(), 0);
    cup.children = {tank, shape(Shape::Kind::Cylinder, {0.5, 0.3, 0.3}, {0.5, 0.3, 0.35}, 0.1)};
    const std::string cup_pov = pov_walls({{cup, true, 0.04}}, Vec3(0.8, -2, 1.5));
    EXPECT_EQ(cup_pov.find("cylinder"), cup_pov.rfind("cylinder")) << cup_pov;
    EXPECT_NE(cup_pov.find("difference { difference { box { <-0.04,-0.04,-0.04>, <1.64,0.64,0.84> "
                           "} } difference { box"),
              std::string::npos)
        << cup_pov;
    EXPECT_THROW(walls_from_json(nlohmann::json::parse(R"([{"shape": {"type": "cone"}}])")),
                 nlohmann::json::exception);
}

TEST(Render, ACameraLookingAtItselfOrAMisspeltKeyIsRefused) {
    EXPECT_EQ(test::refuse_scene(with_render(R"("camera_position": [1, 1, 1],
                                              "camera_target": [1, 1, 1])"))
                  .path,
              "/render/camera_target");
    EXPECT_EQ(test::refuse_scene(with_render(R"("camera_positon": [1, 1, 1])")).path,
              "/render/camera_positon");
    EXPECT_EQ(test::refuse_scene(with_render(R"("samples": 12)")).path, "/render/samples");
}

}  // namespace
}  // namespace karst
