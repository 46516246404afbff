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
    const int status =
        std::system((std::string(KARST_BINARY) + " " + args + " 2>/dev/null").c_str());
    return WEXITSTATUS(status);
}

const char* k_tiny = R"({
  "name": "tiny", "particle_spacing": 0.04,
  "time": { "end": 0.1 },
  "fluid_blocks": [ { "shape": { "type": "box", "min": [0, 0, 0], "max": [0.16, 0.16, 0.2] } } ],
  "walls": [ { "kind": "container", "shape": { "type": "box", "min": [0, 0, 0], "max": [0.4, 0.16, 0.3] } } ],
  "output": { "fps": 50 }
})";

struct TempDir {
    fs::path path;
    explicit TempDir(const std::string& name)
        : path(fs::temp_directory_path() / ("karst_test_" + name)) {
        fs::remove_all(path);
        fs::create_directories(path);
    }
    ~TempDir() { fs::remove_all(path); }
};

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

TEST(Cli, WatchdogStopsWithOneAfterWritingTheLastGoodFrame) {
    TempDir dir("cli_watchdog");
    std::string scene = k_tiny;
    // The block falls: its speed passes 0.3 m/s within 0.05 s.
    scene.replace(scene.find("\"output\""), 8, "\"watchdog\": { \"max_speed\": 0.3 }, \"output\"");
    std::ofstream(dir.path / "w.json") << scene;
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

}  // namespace
