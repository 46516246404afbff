// Checkpoint and resume (issue 15): a run killed (or stopped) after a checkpoint and resumed from
// it writes the same frames, byte for byte, and the same stats.json (timings aside) as the run
// that never stopped; a checkpoint of another scene, frame rate or a damaged one is refused with
// exit 2 before anything in the folder changes.
#include "support/files.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <nlohmann/json.hpp>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <set>

namespace {

namespace fs = std::filesystem;

using karst::test::read_text;

// Water poured on an anchored soil block (Biot calls every 0.02 s with permeability feedback)
// with a free block falling into it: fluid, pore flow, contacts and the PFEM all carry state.
const char* k_soak = R"({
  "name": "resume_soak", "particle_spacing": 0.02, "time": { "end": 0.4 },
  "walls": [ { "kind": "container", "shape": { "type": "box", "min": [0, 0, 0], "max": [0.32, 0.2, 0.4] } } ],
  "fluid_blocks": [ { "shape": { "type": "box", "min": [0.02, 0.02, 0.14], "max": [0.3, 0.18, 0.26] } } ],
  "porous_solids": [
    { "shape": { "type": "box", "min": [0, 0, 0], "max": [0.32, 0.2, 0.1] },
      "material": { "porosity": 0.45, "permeability": 1e-9, "youngs_modulus": 2e5, "poisson_ratio": 0.25,
                    "initial_saturation": 0.2 } },
    { "shape": { "type": "box", "min": [0.12, 0.06, 0.28], "max": [0.2, 0.14, 0.34] }, "anchored": false,
      "material": { "porosity": 0.3, "permeability": 1e-10, "solid_density": 1800 } } ],
  "poroelastic": { "time_step": 0.02 },
  "output": { "fps": 20 }
})";

// A saturated block with a pressurised wet pocket that cracks (the hydraulic-fracture demo,
// coarser and shorter): 19 cracks with 31 split nodes by the checkpoint at 0.05 s, 5 more after.
const char* k_cracking = R"({
  "name": "resume_cracking", "particle_spacing": 0.025, "time": { "end": 0.5 },
  "porous_solids": [ {
    "shape": { "type": "box", "min": [0, 0, 0], "max": [0.3, 0.3, 0.25] },
    "material": { "porosity": 0.3, "permeability": 1e-11, "darcy_viscosity": 0.1, "youngs_modulus": 1e6,
                  "initial_saturation": 1.0, "tensile_strength": 1.6e4, "fracture_energy": 1.0 },
    "wet_regions": [ { "region": { "type": "sphere", "center": [0.15, 0.15, 0.125], "radius": 0.06 }, "saturation": 1.2 } ],
    "constraints": [ { "kind": "fixed", "region": { "type": "box", "min": [-1, -1, -1], "max": [1, 1, 0] } } ] } ],
  "output": { "fps": 10 }
})";

struct Sandbox : karst::test::TempDir {
    explicit Sandbox(const std::string& name, const char* scene_text) : TempDir(name) {
        std::ofstream(path / "scene.json") << scene_text;
    }
    std::string scene() const { return (path / "scene.json").string(); }
    fs::path out(const std::string& name) const { return path / name; }
};

int karst(const std::string& args, std::string* err = nullptr) {
    return karst::test::exit_code_of(std::string(KARST_BINARY) + " " + args, err);
}

std::set<std::string> files_ending(const fs::path& dir, const std::string& suffix) {
    std::set<std::string> names;
    for (const auto& e : fs::directory_iterator(dir))
        if (e.path().filename().string().ends_with(suffix))
            names.insert(e.path().filename().string());
    return names;
}

/// stats.json without the figures that measure the machine rather than the run.
nlohmann::json stats_without_timings(const fs::path& dir) {
    nlohmann::json stats = nlohmann::json::parse(read_text(dir / "stats.json"));
    for (const char* key : {"wall_time", "phases", "mipps"}) stats.erase(key);
    return stats;
}

/// Every frame file of `a` is in `b` with the same bytes and `b` has no other; stats agree.
void expect_same_run(const fs::path& a, const fs::path& b) {
    for (const char* kind : {".vtp", ".geo", ".ens", ".case"}) {
        const std::set<std::string> names = files_ending(a, kind);
        EXPECT_EQ(names, files_ending(b, kind)) << kind;
        for (const std::string& name : names)
            EXPECT_TRUE(read_text(a / name) == read_text(b / name)) << name << " differs";
    }
    EXPECT_EQ(stats_without_timings(a), stats_without_timings(b));
    if (fs::exists(a / "supports.csv")) {
        EXPECT_TRUE(read_text(a / "supports.csv") == read_text(b / "supports.csv"));
    }
}

/// Keeps the checkpoints of `dir` up to the `kept`-th (in step order) and every frame file, as a
/// process killed right after writing later frames would leave it.
void forget_checkpoints_after(const fs::path& dir, size_t kept) {
    const std::set<std::string> names = files_ending(dir, ".kcp");
    ASSERT_GT(names.size(), kept);
    size_t k = 0;
    for (const std::string& name : names)
        if (++k > kept) fs::remove(dir / name);
}

TEST(Checkpoint, AResumedCoupledRunWritesTheSameFramesAndStatsAsTheStraightRun) {
    Sandbox box("resume_coupled", k_soak);
    const fs::path straight = box.out("straight"), resumed = box.out("resumed");
    ASSERT_EQ(karst("run " + box.scene() + " --quiet --checkpoint-every 0.1 --checkpoint-keep 10 " +
                    "--out " + straight.string()),
              0);
    // 0.1, 0.2, 0.3 and 0.4 s (the last is also the one written at the end).
    EXPECT_EQ(files_ending(straight, ".kcp").size(), 4u);
    const auto stats = nlohmann::json::parse(read_text(straight / "stats.json"));
    ASSERT_GE(stats["biot"]["calls"].get<int>(), 15);
    fs::copy(straight, resumed, fs::copy_options::recursive);
    forget_checkpoints_after(resumed, 2);  // the one at 0.2 s, mid-run between Biot calls
    ASSERT_EQ(karst("run " + box.scene() + " --quiet --resume " + resumed.string()), 0);
    expect_same_run(straight, resumed);
}

TEST(Checkpoint, AResumedRunThatCracksAndSplitsNodesContinuesBitForBit) {
    Sandbox box("resume_cracking", k_cracking);
    const fs::path straight = box.out("straight"), resumed = box.out("resumed");
    ASSERT_EQ(
        karst("run " + box.scene() + " --quiet --checkpoint-every 0.05 --checkpoint-keep 20 " +
              "--out " + straight.string()),
        0);
    const auto stats = nlohmann::json::parse(read_text(straight / "stats.json"));
    ASSERT_GT(stats["fracture"]["nodes_split"].get<int>(), 0);
    // Split nodes change the mesh: a new geometry file, and frames that read an older one.
    const std::set<std::string> geometries = files_ending(straight, ".geo");
    EXPECT_GT(geometries.size(), 1u);
    const std::string log = read_text(straight / "log.csv");
    EXPECT_LT(geometries.size(), size_t(std::count(log.begin(), log.end(), '\n') - 1));
    // One row per frame for the fixed base (constraint 0) and none for anything else.
    const std::string supports = read_text(straight / "supports.csv");
    EXPECT_EQ(std::count(supports.begin(), supports.end(), '\n'),
              std::count(log.begin(), log.end(), '\n'));
    EXPECT_NE(supports.find("\n5,0.5,0,0,fixed,"), std::string::npos) << supports;
    fs::copy(straight, resumed, fs::copy_options::recursive);
    forget_checkpoints_after(resumed, 1);  // at 0.05 s, with cracks to come
    ASSERT_EQ(karst("run " + box.scene() + " --quiet --resume " + resumed.string()), 0);
    expect_same_run(straight, resumed);
}

/// Runs the soak scene to 1.2 s straight into `straight`, and into `stopped` with `flags`, sending
/// `signal` once a file matching `wait_for` (a shell pattern in `stopped`) exists; returns the
/// stopped run's exit code.
int straight_and_signalled_runs(const Sandbox& box, const fs::path& straight,
                                const fs::path& stopped, const std::string& flags,
                                const std::string& wait_for, const char* signal) {
    const std::string run =
        fmt::format("{} run {} --quiet --end-time 1.2", KARST_BINARY, box.scene());
    EXPECT_EQ(karst::test::exit_code_of(run + " --out " + straight.string()), 0);
    std::string command = "(" + run + " " + flags + " --out " + stopped.string();
    command += " & pid=$!; while ! ls " + (stopped / wait_for).string() +
               " >/dev/null 2>&1; do sleep 0.01; done; ";
    command += fmt::format("kill -{} $pid; wait $pid)", signal);
    return karst::test::exit_code_of(command);
}

TEST(Checkpoint, ARunKilledAfterACheckpointAndResumedEndsAsTheStraightRun) {
    Sandbox box("resume_killed", k_soak);
    const fs::path straight = box.out("straight"), killed = box.out("killed");
    // SIGKILL once the first checkpoint is on disk: nothing of the process gets to clean up.
    // (Should the run finish first, the resume starts from its last checkpoint and the
    // comparison still holds.)
    const int code = straight_and_signalled_runs(box, straight, killed, "--checkpoint-every 0.1",
                                                 "checkpoint_*.kcp", "KILL");
    ASSERT_TRUE(code == 128 + SIGKILL || code == 0) << code;
    ASSERT_FALSE(files_ending(killed, ".kcp").empty());
    ASSERT_EQ(karst("run " + box.scene() + " --quiet --end-time 1.2 --resume " + killed.string()),
              0);
    expect_same_run(straight, killed);
}

TEST(Checkpoint, SigtermWritesACheckpointFromWhichTheRunContinues) {
    Sandbox box("resume_sigterm", k_soak);
    const fs::path straight = box.out("straight"), stopped = box.out("stopped");
    // A checkpoint interval longer than the run: the only checkpoint is the one SIGTERM makes.
    const int code = straight_and_signalled_runs(box, straight, stopped, "--checkpoint-every 100",
                                                 "run.pvd", "TERM");
    ASSERT_TRUE(code == 128 + SIGTERM || code == 0) << code;
    ASSERT_EQ(files_ending(stopped, ".kcp").size(), 1u);
    ASSERT_EQ(karst("run " + box.scene() + " --quiet --end-time 1.2 --resume " + stopped.string()),
              0);
    expect_same_run(straight, stopped);
    EXPECT_FALSE(stats_without_timings(stopped).contains("interrupted"));
}

TEST(Checkpoint, AResumeMayExtendTheEndTimeAndKeepsOnlyTheNewestCheckpoints) {
    Sandbox box("resume_extend", k_soak);
    const fs::path straight = box.out("straight"), extended = box.out("extended");
    ASSERT_EQ(karst("run " + box.scene() + " --quiet --out " + straight.string()), 0);
    ASSERT_EQ(karst("run " + box.scene() + " --quiet --end-time 0.2 --checkpoint-every 0.05 " +
                    "--out " + extended.string()),
              0);
    EXPECT_EQ(files_ending(extended, ".kcp").size(), 2u) << "--checkpoint-keep defaults to 2";
    ASSERT_EQ(karst("run " + box.scene() + " --quiet --resume " + extended.string()), 0);
    expect_same_run(straight, extended);
}

TEST(Checkpoint, ACheckpointOfAnotherSceneRateOrADamagedOneIsRefusedWithoutTouchingTheFolder) {
    Sandbox box("resume_refused", k_soak);
    const fs::path out = box.out("out");
    ASSERT_EQ(karst("run " + box.scene() + " --quiet --end-time 0.1 --checkpoint-every 0.05 " +
                    "--out " + out.string()),
              0);
    const std::string frames_before = read_text(out / "run.pvd");
    auto refused = [&](const std::string& args, const std::string& says) {
        std::string err;
        EXPECT_EQ(karst("run " + args, &err), 2) << args;
        EXPECT_NE(err.find(says), std::string::npos) << err;
        EXPECT_EQ(read_text(out / "run.pvd"), frames_before) << args;
        EXPECT_TRUE(fs::exists(out / "fluid_0002.vtp")) << args;
    };
    // Another scene: one material value changed.
    std::string other = k_soak;
    other.replace(other.find("\"porosity\": 0.45"), 16, "\"porosity\": 0.44");
    std::ofstream(box.path / "other.json") << other;
    refused((box.path / "other.json").string() + " --resume " + out.string(), "another scene");
    refused(box.scene() + " --fps 40 --resume " + out.string(), "frames per second");
    refused(box.scene() + " --resume " + out.string() + " --out " + out.string(), "--out");
    refused(box.scene() + " --resume " + box.path.string(), "--resume");
    refused(box.scene() + " --checkpoint-every -1 --out " + out.string(), "--checkpoint-every");
    refused(box.scene() + " --checkpoint-keep 0 --out " + out.string(), "--checkpoint-keep");
    // Damaged: cut short, then one byte flipped.
    const std::set<std::string> names = files_ending(out, ".kcp");
    ASSERT_FALSE(names.empty());
    const fs::path newest = out / *names.rbegin();
    std::string bytes = read_text(newest);
    std::ofstream(newest, std::ios::binary) << bytes.substr(0, bytes.size() / 2);
    refused(box.scene() + " --resume " + out.string(), "damaged");
    bytes[bytes.size() / 2] ^= 0x10;
    std::ofstream(newest, std::ios::binary) << bytes;
    refused(box.scene() + " --resume " + out.string(), "damaged");
    std::ofstream(newest, std::ios::binary) << "not a checkpoint";
    refused(box.scene() + " --resume " + out.string(), "karst checkpoint");
}

}  // namespace
