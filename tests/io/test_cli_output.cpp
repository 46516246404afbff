// The CLI writes a complete output folder for a tiny scene, run.pvd lists every frame with its
// time, bad input exits with 2 and writes nothing, and the watchdog exits with 1.
#include "support/files.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

namespace {

namespace fs = std::filesystem;

using karst::test::read_text;

int karst(const std::string& args) {
    return karst::test::exit_code_of(std::string(KARST_BINARY) + " " + args);
}

const char* k_tiny = R"({
  "name": "tiny", "particle_spacing": 0.04,
  "time": { "end": 0.1 },
  "fluid_blocks": [ { "shape": { "type": "box", "min": [0, 0, 0], "max": [0.16, 0.16, 0.2] } } ],
  "walls": [ { "kind": "container", "shape": { "type": "box", "min": [0, 0, 0], "max": [0.4, 0.16, 0.3] } } ],
  "output": { "fps": 50, "ply": true }
})";

using karst::test::TempDir;

TEST(Cli, WritesCompleteOutputFolder) {
    TempDir dir("cli");
    std::ofstream(dir.path / "tiny.json") << k_tiny;
    const fs::path out = dir.path / "out";
    ASSERT_EQ(karst("run " + (dir.path / "tiny.json").string() + " --out " + out.string() +
                    " --quiet --threads 1"),
              0);
    // 0.1 s at 50 fps: frames 0..5.
    for (int f = 0; f <= 5; ++f) {
        char name[32];
        std::snprintf(name, sizeof name, "fluid_%04d", f);
        EXPECT_TRUE(fs::exists(out / (std::string(name) + ".vtp"))) << name;
        EXPECT_TRUE(fs::exists(out / (std::string(name) + ".ply"))) << name;
        const std::string vtp = read_text(out / (std::string(name) + ".vtp"));
        EXPECT_NE(vtp.find("<Verts>"), std::string::npos);
        for (const char* array : {"velocity", "density", "pressure", "\"id\""})
            EXPECT_NE(vtp.find(array), std::string::npos);
        EXPECT_TRUE(vtp.ends_with("</VTKFile>\n"));
    }
    EXPECT_FALSE(fs::exists(out / "fluid_0006.vtp"));
    EXPECT_TRUE(fs::exists(out / "boundary.vtp"));
    for (const auto& e : fs::directory_iterator(out))
        EXPECT_NE(e.path().extension(), ".tmp") << e.path();

    // run.pvd: every frame with its exact time, plus the boundary part.
    const std::string pvd = read_text(out / "run.pvd");
    const std::regex fluid_entry(R"re(timestep="([0-9.e-]+)" part="0" file="fluid_(\d{4}).vtp")re");
    int frames = 0;
    for (auto it = std::sregex_iterator(pvd.begin(), pvd.end(), fluid_entry);
         it != std::sregex_iterator(); ++it, ++frames) {
        EXPECT_EQ(std::stoi((*it)[2]), frames);
        EXPECT_NEAR(std::stod((*it)[1]), frames * 0.02, 1e-12);
    }
    EXPECT_EQ(frames, 6);
    EXPECT_NE(pvd.find("part=\"1\" file=\"boundary.vtp\""), std::string::npos);

    const std::string log = read_text(out / "log.csv");
    EXPECT_EQ(std::count(log.begin(), log.end(), '\n'), 7);  // header + 6 frames
    const auto stats = nlohmann::json::parse(read_text(out / "stats.json"));
    for (const char* key : {"counts", "steps", "frames", "sim_time", "wall_time", "phases", "mass",
                            "max_density_error", "mipps", "threads", "version"})
        EXPECT_TRUE(stats.contains(key)) << key;
    for (const char* key : {"fluid", "boundary", "porous", "elements", "fragments"})
        EXPECT_TRUE(stats["counts"].contains(key));
    EXPECT_EQ(stats["frames"], 6);
    EXPECT_EQ(stats["threads"], 1);
    EXPECT_NEAR(stats["sim_time"].get<double>(), 0.1, 1e-12);
    EXPECT_DOUBLE_EQ(stats["mass"]["water_initial"].get<double>(),
                     stats["mass"]["water_final"].get<double>());
    EXPECT_GT(stats["phases"]["pressure_solve"].get<double>(), 0);
}

TEST(Cli, AFracturingRunWritesItsCracksDamageAndCounts) {
    // A cantilever under its weight at three times its strength (tests/pfem/test_fracture_scene).
    TempDir dir("cracks");
    std::ofstream(dir.path / "overhang.json") << R"({
      "name": "overhang", "particle_spacing": 0.05, "time": { "end": 0.2 },
      "domain": { "min": [-0.5, -0.5, -3], "max": [1.5, 0.7, 0.7] }, "poroelastic": { "time_step": 0.02 },
      "porous_solids": [ { "shape": { "type": "box", "min": [0, 0, 0], "max": [1.0, 0.2, 0.2] },
        "material": { "porosity": 0.3, "permeability": 1e-10, "youngs_modulus": 1e7, "tensile_strength": 1e5 },
        "constraints": [
          { "kind": "fixed", "region": { "type": "box", "min": [-1, -1, -1], "max": [0, 2, 2] } },
          { "kind": "drained", "region": { "type": "box", "min": [-1, -1, -1], "max": [2, 2, 2] } } ] } ]
    })";
    const fs::path out = dir.path / "out";
    ASSERT_EQ(karst("run " + (dir.path / "overhang.json").string() + " --out " + out.string() +
                    " --quiet"),
              0);
    const auto stats = nlohmann::json::parse(read_text(out / "stats.json"));
    const auto& fracture = stats["fracture"];
    EXPECT_GT(fracture["cracks"].get<int>(), 0);
    EXPECT_GT(fracture["links_broken"].get<int>(), fracture["cracks"].get<int>());
    EXPECT_GT(fracture["nodes_split"].get<int>(), 0);
    EXPECT_GE(fracture["fragments_created"].get<int>(), 1);
    EXPECT_EQ(stats["counts"]["fragments"].get<int>(),
              1 + fracture["fragments_created"].get<int>());
    EXPECT_TRUE(stats["phases"].contains("fracture"));
    // The last frame's cracks: one 16-gon per crack, listed in run.pvd as part 4.
    const std::string last = "cracks_0006.vtp";
    const std::string cracks = read_text(out / last);
    std::smatch polys;
    const std::regex polys_count(R"re(NumberOfPolys="(\d+)")re");
    std::regex_search(cracks, polys, polys_count);
    ASSERT_FALSE(polys.empty());
    EXPECT_EQ(std::stoi(polys[1]), fracture["cracks"].get<int>());
    for (const char* array : {"\"normal\"", "\"radius\"", "\"area\"", "\"time\""})
        EXPECT_NE(cracks.find(array), std::string::npos) << array;
    EXPECT_NE(read_text(out / "run.pvd").find("part=\"4\" file=\"" + last + "\""),
              std::string::npos);
    EXPECT_NE(read_text(out / "porous_0006.vtp").find("Name=\"damage\""), std::string::npos);
}

TEST(Cli, BadSceneExitsWithTwoAndWritesNothing) {
    TempDir dir("cli_bad");
    std::string bad = k_tiny;
    bad.replace(bad.find("\"fps\""), 5, "\"fsp\"");
    std::ofstream(dir.path / "bad.json") << bad;
    const fs::path out = dir.path / "out";
    EXPECT_EQ(karst("run " + (dir.path / "bad.json").string() + " --out " + out.string()), 2);
    EXPECT_FALSE(fs::exists(out));
    EXPECT_EQ(karst("check " + (dir.path / "bad.json").string()), 2);
    EXPECT_EQ(karst("check " + (dir.path / "missing.json").string()), 2);
    std::ofstream(dir.path / "good.json") << k_tiny;
    EXPECT_EQ(karst("check " + (dir.path / "good.json").string()), 0);
}

/// The tiny scene with a watchdog at 0.3 m/s, as dir/w.json: its block falls faster than that
/// within 0.05 s.
void write_watchdog_scene(const fs::path& dir) {
    std::string scene = k_tiny;
    scene.replace(scene.find("\"output\""), 8, "\"watchdog\": { \"max_speed\": 0.3 }, \"output\"");
    std::ofstream(dir / "w.json") << scene;
}

TEST(Cli, WatchdogStopsWithOneAfterWritingTheLastGoodFrame) {
    TempDir dir("cli_watchdog");
    write_watchdog_scene(dir.path);
    const fs::path out = dir.path / "out";
    EXPECT_EQ(
        karst("run " + (dir.path / "w.json").string() + " --out " + out.string() + " --quiet"), 1);
    const auto stats = nlohmann::json::parse(read_text(out / "stats.json"));
    const std::string failure = stats["failure"];
    EXPECT_NE(failure.find("stage 'integrate'"), std::string::npos) << failure;
    EXPECT_NE(failure.find("particle"), std::string::npos);
    const int frames = stats["frames"];
    EXPECT_GE(frames, 2);
    char last[32];
    std::snprintf(last, sizeof last, "fluid_%04d.vtp", frames - 1);
    EXPECT_TRUE(fs::exists(out / last));
}

TEST(Cli, AWatchdogStopRightAfterAFrameRepeatsNoFrameTime) {
    // At 2000 frames per second every step ends on a frame, so the last good state is already a
    // frame when the watchdog stops the next step: it must not be written again at the same time
    // (ParaView's run.pvd and mesh.case need increasing times).
    TempDir dir("cli_watchdog_frame");
    write_watchdog_scene(dir.path);
    const fs::path out = dir.path / "out";
    EXPECT_EQ(karst("run " + (dir.path / "w.json").string() + " --out " + out.string() +
                    " --quiet --threads 1 --fps 2000"),
              1);
    std::istringstream log(read_text(out / "log.csv"));
    std::string line;
    std::getline(log, line);  // header
    double last = -1;
    int rows = 0;
    while (std::getline(log, line)) {
        const double time = std::stod(line.substr(line.find(',') + 1));
        EXPECT_GT(time, last) << line;
        last = time, ++rows;
    }
    EXPECT_GE(rows, 5);
    const int frames = nlohmann::json::parse(read_text(out / "stats.json"))["frames"];
    EXPECT_EQ(frames, rows);
}

}  // namespace
