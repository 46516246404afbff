// Output that cannot hurt (issue 15): a run writes only into a folder it may claim, deletes only
// the files its manifest lists, says why it could not write (the operating system's reason),
// leaves no half-written file, and writes stats.json when stopped by SIGTERM.
#include "support/files.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <unistd.h>

#include <filesystem>
#include <fstream>

namespace {

namespace fs = std::filesystem;

using karst::test::read_text;

const char* k_small = R"({
  "name": "small", "particle_spacing": 0.04, "time": { "end": 0.06 },
  "fluid_blocks": [ { "shape": { "type": "box", "min": [0, 0, 0], "max": [0.16, 0.16, 0.2] } } ],
  "walls": [ { "kind": "container", "shape": { "type": "box", "min": [0, 0, 0], "max": [0.4, 0.16, 0.3] } } ],
  "output": { "fps": 50 }
})";

/// A temporary folder holding the small scene.
struct Sandbox : karst::test::TempDir {
    explicit Sandbox(const std::string& name) : TempDir(name) {
        std::ofstream(path / "small.json") << k_small;
    }
    std::string scene() const { return (path / "small.json").string(); }
};

int shell(const std::string& command, std::string* err = nullptr) {
    return karst::test::exit_code_of(command, err);
}

std::string karst() {
    return KARST_BINARY;
}

TEST(OutputSafety, AFolderKarstDidNotWriteIsRefusedUnlessOverwrite) {
    Sandbox box("foreign");
    const fs::path out = box.path / "mine";
    fs::create_directories(out);
    std::ofstream(out / "thesis.tex") << "precious";
    std::ofstream(out / "fluid_0001.vtp") << "not ours either";
    std::string err;
    EXPECT_EQ(shell(karst() + " run " + box.scene() + " --quiet --out " + out.string(), &err), 2);
    EXPECT_NE(err.find("--out"), std::string::npos) << err;
    EXPECT_NE(err.find("--overwrite"), std::string::npos) << err;
    EXPECT_EQ(read_text(out / "fluid_0001.vtp"), "not ours either");

    ASSERT_EQ(shell(karst() + " run " + box.scene() + " --quiet --overwrite --out " + out.string()),
              0);
    EXPECT_EQ(read_text(out / "thesis.tex"), "precious");
    EXPECT_NE(read_text(out / "fluid_0001.vtp"), "not ours either");  // a name karst writes
    const std::string manifest = read_text(out / "manifest.txt");
    EXPECT_NE(manifest.find("fluid_0003.vtp\n"), std::string::npos);
    EXPECT_EQ(manifest.find("thesis.tex"), std::string::npos);
}

TEST(OutputSafety, ARerunDeletesExactlyTheFilesOfTheRunBefore) {
    Sandbox box("rerun");
    const fs::path out = box.path / "out";
    const std::string run = karst() + " run " + box.scene() + " --quiet --out " + out.string();
    ASSERT_EQ(shell(run), 0);
    ASSERT_TRUE(fs::exists(out / "fluid_0003.vtp"));
    std::ofstream(out / "notes.txt") << "mine";
    ASSERT_EQ(shell(run + " --end-time 0.02"), 0);
    EXPECT_TRUE(fs::exists(out / "fluid_0001.vtp"));
    EXPECT_FALSE(fs::exists(out / "fluid_0002.vtp"));  // the longer run's frames are gone
    EXPECT_EQ(read_text(out / "notes.txt"), "mine");
    // A manifest cannot reach outside its folder.
    std::ofstream(box.path / "outside.txt") << "safe";
    std::ofstream(out / "manifest.txt", std::ios::app) << "../outside.txt\n..\n";
    ASSERT_EQ(shell(run), 0);
    EXPECT_EQ(read_text(box.path / "outside.txt"), "safe");
}

TEST(OutputSafety, AFolderThatCannotBeWrittenEndsWithTheSystemsReason) {
    Sandbox box("unwritable");
    fs::path out;
    if (geteuid() == 0) {
        out = "/proc/karst_cannot_write_here";  // root may write anywhere but here
    } else {
        fs::create_directories(box.path / "locked");
        fs::permissions(box.path / "locked", fs::perms::owner_read | fs::perms::owner_exec);
        out = box.path / "locked" / "out";
    }
    std::string err;
    EXPECT_EQ(shell(karst() + " run " + box.scene() + " --quiet --out " + out.string(), &err), 1);
    EXPECT_TRUE(err.find("denied") != std::string::npos ||
                err.find("not permitted") != std::string::npos ||
                err.find("No such file") != std::string::npos)
        << err;
    fs::permissions(box.path, fs::perms::owner_all, fs::perm_options::add);
    if (fs::exists(box.path / "locked")) fs::permissions(box.path / "locked", fs::perms::owner_all);
}

TEST(OutputSafety, AFullDiskEndsWithTheSystemsReasonAndNoHalfWrittenFile) {
    if (geteuid() != 0) GTEST_SKIP() << "mounting a tiny tmpfs needs root";
    Sandbox box("full_disk");
    const fs::path out = box.path / "tiny";
    fs::create_directories(out);
    if (shell("mount -t tmpfs -o size=96k tmpfs " + out.string()) != 0)
        GTEST_SKIP() << "this machine does not allow mounting a tmpfs";
    std::string err;
    const int code = shell(
        karst() + " run " + box.scene() + " --quiet --out " + out.string() + " --end-time 1", &err);
    bool half_written = false;
    for (const auto& e : fs::directory_iterator(out))
        half_written = half_written || e.path().extension() == ".tmp";
    shell("umount " + out.string());
    EXPECT_EQ(code, 1);
    EXPECT_NE(err.find("No space left on device"), std::string::npos) << err;
    EXPECT_FALSE(half_written);
}

TEST(OutputSafety, SigtermStopsAfterAStepAndLeavesStats) {
    Sandbox box("sigterm");
    const fs::path out = box.path / "out";
    // The built-in dam break, long enough to be stopped once its first frame is out.
    const std::string pvd = (out / "run.pvd").string();
    std::string command = fmt::format("({}", karst());
    command += " run --quiet --end-time 20 --out " + out.string();
    command += " & pid=$!; while [ ! -f " + pvd + " ]; do sleep 0.05; done; sleep 0.5; ";
    command += "kill -TERM $pid; wait $pid)";
    std::string err;
    EXPECT_EQ(shell(command, &err), 128 + SIGTERM);
    EXPECT_NE(err.find("stopped by signal"), std::string::npos) << err;
    const nlohmann::json stats = nlohmann::json::parse(read_text(out / "stats.json"));
    EXPECT_EQ(stats["interrupted"]["signal"], SIGTERM);
    EXPECT_GT(stats["sim_time"].get<double>(), 0);
    EXPECT_LT(stats["sim_time"].get<double>(), 20);
    for (const auto& e : fs::directory_iterator(out)) EXPECT_NE(e.path().extension(), ".tmp");
}

TEST(OutputSafety, EachOutputPartIsSwitchedByItsOwnKey) {
    Sandbox box("parts");
    std::ofstream(box.path / "block.json") << R"({
      "name": "block", "particle_spacing": 0.1, "time": { "end": 0.1 },
      "porous_solids": [{ "shape": { "type": "box", "min": [0,0,0], "max": [0.4,0.4,0.4] },
        "constraints": [{ "kind": "fixed", "region": { "type": "box", "min": [-1,-1,-1], "max": [2,2,0] } }] }],
      "walls": [{ "kind": "obstacle", "shape": { "type": "box", "min": [1,1,1], "max": [1.2,1.2,1.2] } }],
      "poroelastic": { "time_step": 0.05 },
      "output": { "fps": 20, "vtp": false, "porous": false, "mesh": true, "walls": false,
                  "porous_surface": false }
    })";
    const fs::path out = box.path / "out";
    ASSERT_EQ(shell(karst() + " run " + (box.path / "block.json").string() + " --quiet --out " +
                    out.string()),
              0);
    EXPECT_TRUE(fs::exists(out / "mesh.case"));
    EXPECT_TRUE(fs::exists(out / "mesh_0000.geo"));
    EXPECT_FALSE(fs::exists(out / "porous_0000.vtp"));
    EXPECT_FALSE(fs::exists(out / "boundary.vtp"));
    EXPECT_FALSE(fs::exists(out / "porous_surface_0000.ply"));
    const std::string pvd = read_text(out / "run.pvd");
    EXPECT_EQ(pvd.find("porous_"), std::string::npos);
    EXPECT_EQ(pvd.find("boundary.vtp"), std::string::npos);
}

}  // namespace
