// Hostile input (issue 15): what once crashed, hung or failed silently is refused with its JSON
// path (exit 2), or runs and stops loudly (exit 1). The scenes of tests/data/bad_scenes are the
// regression cases found by mutating the shipped scenes; the deep and huge ones are built here.
#include "karst/scene/read_json.hpp"
#include "karst/sim/model.hpp"
#include "karst/sim/run.hpp"

#include "support/files.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <algorithm>
#include <filesystem>
#include <string>

namespace karst {
namespace {

namespace fs = std::filesystem;

const std::string k_box = R"({"type":"box","min":[0,0,0],"max":[0.2,0.2,0.2]})";

std::string fluid_scene(const std::string& shape, const std::string& extra = "") {
    return R"({"name":"t","particle_spacing":0.05)" + extra + R"(,"fluid_blocks":[{"shape":)" +
           shape + "}]}";
}

std::string repeat(const std::string& s, int n) {
    std::string out;
    for (int i = 0; i < n; ++i) out += s;
    return out;
}

bool starts_with(const std::string& s, const std::string& prefix) {
    return s.rfind(prefix, 0) == 0;
}

TEST(HostileInput, DeepNestingIsRefusedAtItsPathWithoutRecursing) {
    const std::string unions =
        repeat(R"({"type":"union","shapes":[)", 10000) + k_box + repeat("]}", 10000);
    const SceneError a = test::refuse_scene(fluid_scene(unions));
    EXPECT_TRUE(starts_with(a.path, "/fluid_blocks/0/shape/shapes/0/shapes/0")) << a.what();
    EXPECT_NE(a.expected.find("nested at most 64 deep"), std::string::npos);

    const SceneError b = test::refuse_scene(
        fluid_scene(k_box, R"(,"gravity":)" + repeat("[", 100000) + repeat("]", 100000)));
    EXPECT_TRUE(starts_with(b.path, "/gravity/0/0")) << b.path;

    const SceneError c =
        test::refuse_scene(fluid_scene(R"({"type":"box","min":[0,)" + repeat(R"({"a":)", 100000) +
                                       "1" + repeat("}", 100000) + R"(,0],"max":[1,1,1]})"));
    EXPECT_TRUE(starts_with(c.path, "/fluid_blocks/0/shape/min/1/a/a")) << c.path;

    // Just inside the limit is read (and then judged by the schema, which wants a number).
    const std::string ok = repeat("[", k_max_json_depth) + repeat("]", k_max_json_depth);
    EXPECT_NO_THROW(read_scene_json(ok));
    EXPECT_THROW(read_scene_json("[" + ok + "]"), SceneError);
}

TEST(HostileInput, ANumberADoubleCannotHoldIsNamedByItsPath) {
    const SceneError a =
        test::refuse_scene(fluid_scene(R"({"type":"box","min":[0,0,0],"max":[1e309,0.2,0.2]})"));
    EXPECT_EQ(a.path, "/fluid_blocks/0/shape/max/0");
    EXPECT_EQ(a.found, "1e309");
    const SceneError b = test::refuse_scene(fluid_scene(k_box, R"(,"gravity":[0,0,-1e400])"));
    EXPECT_EQ(b.path, "/gravity/2");
    const SceneError c = test::refuse_scene(R"({"name":"t","particle_spacing":-2e308})");
    EXPECT_EQ(c.path, "/particle_spacing");
}

TEST(HostileInput, WhatWouldSilentlyChangeTheSceneIsRefused) {
    // A key given twice: the parser would keep the last.
    const SceneError a = test::refuse_scene(fluid_scene(k_box, R"(,"particle_spacing":0.02)"));
    EXPECT_EQ(a.path, "/particle_spacing");
    EXPECT_NE(a.expected.find("each key once"), std::string::npos);
    const SceneError b = test::refuse_scene(
        fluid_scene(R"({"type":"box","min":[0,0,0],"max":[1,1,1],"max":[0.2,0.2,0.2]})"));
    EXPECT_EQ(b.path, "/fluid_blocks/0/shape/max");
    // A number that underflows to 0; a subnormal one is held, and zeros are zeros.
    const SceneError c = test::refuse_scene(fluid_scene(k_box, R"(,"time":{"end":1e-400})"));
    EXPECT_EQ(c.path, "/time/end");
    EXPECT_EQ(c.found, "1e-400");
    EXPECT_EQ(test::refuse_scene(fluid_scene(k_box, R"(,"gravity":[0,-2.5e-999,-9.81])")).path,
              "/gravity/1");
    EXPECT_NO_THROW(read_scene_json(R"([1e-320, 0e-400, 0.000e-999, -0.0])"));
    // A NUL byte: the parser would stop there and ignore the rest.
    const std::string nul = fluid_scene(k_box) + std::string(1, '\0') + "{{{ not json";
    const SceneError d = test::refuse_scene(nul);
    EXPECT_NE(d.found.find("NUL byte"), std::string::npos);
}

TEST(HostileInput, MessagesNameKeysWithoutEchoingThemRaw) {
    // A key holding '/' is a pointer token (~1); control characters are escaped, long keys cut.
    const SceneError a = test::refuse_scene(fluid_scene(k_box, R"(,"fluid/viscosity":1)"));
    EXPECT_EQ(a.path, "/fluid~1viscosity");
    EXPECT_NE(a.found.find("\"fluid/viscosity\""), std::string::npos);
    const SceneError b = test::refuse_scene(fluid_scene(k_box, R"(,"a\u001b[2Jb":1)"));
    EXPECT_EQ(b.path, "/a\\u001b[2Jb");
    EXPECT_EQ(std::string(b.what()).find('\x1b'), std::string::npos);
    const SceneError c =
        test::refuse_scene(fluid_scene(k_box, ",\"" + std::string(1 << 20, 'k') + "\":1"));
    EXPECT_LT(std::string(c.what()).size(), 2000u);
    // A long key of two-byte characters is cut between characters: the message stays UTF-8.
    std::string accents = "a";
    for (int i = 0; i < 70; ++i) accents += "\u00e9";
    const SceneError u = test::refuse_scene(fluid_scene(k_box, ",\"" + accents + "\":1"));
    EXPECT_NO_THROW((void)nlohmann::json(std::string(u.what())).dump()) << "valid UTF-8";
    EXPECT_NE(u.path.find("... (141 bytes)"), std::string::npos) << u.path;
    // A misspelt shape type is named as the unknown key it is.
    const SceneError d =
        test::refuse_scene(fluid_scene(R"({"typ":"box","min":[0,0,0],"max":[0.2,0.2,0.2]})"));
    EXPECT_EQ(d.path, "/fluid_blocks/0/shape/typ");
    EXPECT_NE(d.expected.find("\"type\""), std::string::npos);
    // A syntax error says where, in words, without the parser's internal tag.
    const SceneError e = test::refuse_scene(fluid_scene(k_box) + " x");
    EXPECT_NE(e.found.find("line 1"), std::string::npos) << e.found;
    EXPECT_EQ(e.found.find("json.exception"), std::string::npos) << e.found;
}

TEST(HostileInput, ShapesFarApartAreRefusedOrSampledPartByPart) {
    const auto spheres = [](double apart) {
        return fmt::format(
            R"({{"type":"union","shapes":[{{"type":"sphere","center":[0,0,0],"radius":0.1}},)"
            R"({{"type":"sphere","center":[{0},{0},{0}],"radius":0.1}}]}})",
            apart);
    };
    // 300 m apart at dx 0.05: a neighbour grid of 2.7e10 cells, refused before any sampling
    // (which once visited all 2e11 lattice points of the box).
    const SceneError e = test::refuse_scene(fluid_scene(spheres(300)));
    EXPECT_EQ(e.path, "/particle_spacing");
    EXPECT_NE(e.expected.find("neighbour grid"), std::string::npos);
    // 3 m apart: each sphere's box is visited, and the particles are those of two blocks.
    const Model together = build_model(parse_scene(fluid_scene(spheres(3))));
    const Model apart =
        build_model(parse_scene(R"({"name":"t","particle_spacing":0.05,"fluid_blocks":[)"
                                R"({"shape":{"type":"sphere","center":[0,0,0],"radius":0.1}},)"
                                R"({"shape":{"type":"sphere","center":[3,3,3],"radius":0.1}}]})"));
    ASSERT_EQ(together.initial_x.size(), 64u);
    auto sorted = [](std::vector<Vec3> x) {
        std::sort(x.begin(), x.end(), [](const Vec3& p, const Vec3& q) {
            return std::lexicographical_compare(p.data(), p.data() + 3, q.data(), q.data() + 3);
        });
        return x;
    };
    EXPECT_EQ(sorted(together.initial_x), sorted(apart.initial_x));
}

TEST(HostileInput, ASolidThatCannotMeshIsRefusedWhereItGetsABiotProblem) {
    const auto solid = [](const std::string& max) {
        return R"({"name":"t","particle_spacing":0.05,"porous_solids":[{"shape":{"type":"box",)"
               R"("min":[0,0,0],"max":)" +
               max + R"(}}],"poroelastic":{"time_step":0.05}})";
    };
    for (const char* max : {"[0.05,0.05,0.05]", "[0.5,0.5,0.05]"}) {
        const SceneError e = test::refuse_scene(solid(max));
        EXPECT_EQ(e.path, "/porous_solids/0/shape") << max;
        EXPECT_NE(e.expected.find("two particles thick"), std::string::npos) << e.what();
    }
    EXPECT_NO_THROW(build_model(parse_scene(solid("[0.1,0.1,0.1]"))));
    // A thin rod along the diagonal: its particles touch only at cube corners, and it ran with
    // 0 elements and "all_converged". Twice as thick, it meshes.
    const auto rod = [](double radius) {
        return fmt::format(
            R"({{"name":"t","particle_spacing":0.05,"porous_solids":[{{"shape":{{"type":)"
            R"("cylinder","base":[0,0,0],"top":[0.8,0.8,0.8],"radius":{}}}}}]}})",
            radius);
    };
    const SceneError thin = test::refuse_scene(rod(0.03));
    EXPECT_EQ(thin.path, "/porous_solids/0/shape");
    EXPECT_NE(thin.expected.find("off one plane"), std::string::npos) << thin.what();
    EXPECT_NO_THROW(build_model(parse_scene(rod(0.05))));
    // An alpha that keeps no lattice cell's tetrahedron (radius sqrt(3)/2 dx; orthoradius
    // sqrt(0.45) dx when weighted): every solid meshed with 0 elements.
    const auto with_alpha = [&](const char* alpha, const char* weighted) {
        return R"({"name":"t","particle_spacing":0.05,"porous_solids":[{"shape":{"type":"box",)"
               R"("min":[0,0,0],"max":[0.3,0.3,0.3]}}],"poroelastic":{"alpha":)" +
               std::string(alpha) + R"(,"weighted_alpha":)" + weighted + "}}";
    };
    for (const auto& [alpha, weighted] : {std::pair{"0.8", "false"}, {"0.65", "true"}}) {
        const SceneError e = test::refuse_scene(with_alpha(alpha, weighted));
        EXPECT_EQ(e.path, "/poroelastic/alpha") << alpha;
    }
    EXPECT_NO_THROW(build_model(parse_scene(with_alpha("0.9", "false"))));
    EXPECT_NO_THROW(build_model(parse_scene(with_alpha("0.7", "true"))));
}

TEST(HostileInput, GeometryBeyondTheLatticeIsRefusedBeforeCounting) {
    for (const std::string& shape :
         {std::string(R"({"type":"box","min":[-1e19,0,0],"max":[0.2,0.2,0.2]})"),
          std::string(R"({"type":"box","min":[-1e308,0,0],"max":[0.2,0.2,0.2]})"),
          std::string(R"({"type":"box","min":[0,0,0],"max":[0.2,0.2,1e308]})"),
          std::string(R"({"type":"box","min":[0,0,0],"max":[1e19,0.2,0.2]})"),
          std::string(R"({"type":"sphere","center":[0,0,0],"radius":1e300})")}) {
        const SceneError e = test::refuse_scene(fluid_scene(shape));
        EXPECT_EQ(e.path, "/fluid_blocks/0/shape") << shape;
        EXPECT_NE(e.expected.find("of the origin"), std::string::npos) << e.what();
    }
    const SceneError tiny = test::refuse_scene(
        R"({"name":"t","particle_spacing":1e-300,"fluid_blocks":[{"shape":)" + k_box + "}]}");
    EXPECT_EQ(tiny.path, "/fluid_blocks/0/shape");
    // Walls are held to the same limit.
    const SceneError wall = test::refuse_scene(fluid_scene(
        k_box,
        R"(,"walls":[{"kind":"container","shape":{"type":"box","min":[0,0,0],"max":[60000,1,1]}}])"));
    EXPECT_EQ(wall.path, "/walls/0/shape");
}

const std::string k_porous_block = R"(
  "porous_solids": [{"shape": {"type": "box", "min": [0,0,0], "max": [0.4,0.4,0.4]},
    "constraints": [{"kind": "fixed", "region": {"type": "box", "min": [-1,-1,-1], "max": [2,2,0]}}]}])";

TEST(HostileInput, StepAndFrameCountsAreBounded) {
    for (const char* step : {"1e-300", "5e-324"}) {
        const SceneError e =
            test::refuse_scene(R"({"name":"t","particle_spacing":0.1,"time":{"end":3.5},)" +
                               k_porous_block + R"(,"poroelastic":{"time_step":)" + step + "}}");
        EXPECT_EQ(e.path, "/poroelastic/time_step") << step;
    }
    EXPECT_EQ(test::refuse_scene(fluid_scene(k_box, R"(,"time":{"fixed_dt":5e-324})")).path,
              "/time/fixed_dt");
    EXPECT_EQ(
        test::refuse_scene(fluid_scene(k_box, R"(,"time":{"end":1000},"output":{"fps":10000})"))
            .path,
        "/output/fps");
}

TEST(HostileInput, AViscosityTheExplicitStepCannotCarryIsRefused) {
    // At dx 0.05 the stable step is 0.05 dx^2 / nu_eff (sph/integrate.hpp): 1.25e-4 s for nu = 1.
    EXPECT_EQ(test::refuse_scene(
                  fluid_scene(k_box, R"(,"fluid":{"viscosity":1},"time":{"fixed_dt":1e-3})"))
                  .path,
              "/time/fixed_dt");
    EXPECT_EQ(
        test::refuse_scene(fluid_scene(k_box, R"(,"fluid":{"viscosity":1},"time":{"dt_min":1e-3})"))
            .path,
        "/fluid/viscosity");
    EXPECT_EQ(test::refuse_scene(
                  fluid_scene(k_box, R"(,"fluid":{"artificial_viscosity":1,"sound_speed":10000},)"
                                     R"("time":{"dt_min":1e-5})"))
                  .path,
              "/fluid/artificial_viscosity");
    EXPECT_NO_THROW(build_model(parse_scene(
        fluid_scene(k_box, R"(,"fluid":{"viscosity":0.01},"time":{"fixed_dt":1e-3})"))));
    EXPECT_NO_THROW(build_model(parse_scene(fluid_scene(k_box, R"(,"fluid":{"viscosity":1})"))));
}

TEST(HostileInput, AConstraintOrWetRegionThatSelectsNoParticleIsRefused) {
    const std::string far = R"({"type": "box", "min": [5,5,5], "max": [6,6,6]})";
    const std::string block = R"({"name":"t","particle_spacing":0.1,"porous_solids": [{
        "shape": {"type": "box", "min": [0,0,0], "max": [0.4,0.4,0.4]},)";
    EXPECT_EQ(test::refuse_scene(block + R"("constraints": [{"kind": "fixed", "region": )" + far +
                                 "}]}]}")
                  .path,
              "/porous_solids/0/constraints/0/region");
    EXPECT_EQ(test::refuse_scene(block + R"("wet_regions": [{"saturation": 1, "region": )" + far +
                                 "}]}]}")
                  .path,
              "/porous_solids/0/wet_regions/0/region");
    // Within 3/4 of a spacing of a particle still selects (the Biot constraints reach as far).
    const std::string touching = R"({"type": "box", "min": [-1,-1,-1], "max": [2,2,-0.02]})";
    EXPECT_NO_THROW(build_model(parse_scene(
        block + R"("constraints": [{"kind": "fixed", "region": )" + touching + "}]}]}")));
}

TEST(HostileInput, TheSceneNameStaysInsideTheOutputFolder) {
    for (const char* name : {"../x", "/abs/path", "a/b", "..", ".", "a\\\\b", "x\\u0001"}) {
        const SceneError e = test::refuse_scene(
            R"({"name":")" + std::string(name) +
            R"(","particle_spacing":0.05,"fluid_blocks":[{"shape":)" + k_box + "}]}");
        EXPECT_EQ(e.path, "/name") << name;
    }
    EXPECT_NO_THROW(build_model(parse_scene(fluid_scene(k_box))));
    // A folder name longer than file systems allow would fail only when the run creates it.
    const auto named = [](size_t bytes) {
        return R"({"name":")" + std::string(bytes, 'n') +
               R"(","particle_spacing":0.05,"fluid_blocks":[{"shape":)" + k_box + "}]}";
    };
    EXPECT_EQ(test::refuse_scene(named(129)).path, "/name");
    EXPECT_NO_THROW(parse_scene(named(128)));
}

TEST(HostileInput, OnlyARegularFileIsReadAsAScene) {
    const fs::path dir = fs::temp_directory_path() / "karst_test_not_a_file";
    fs::remove_all(dir);
    fs::create_directories(dir);
    const fs::path fifo = dir / "scene.json";
    ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
    for (const auto& [path, kind] : {std::pair{fifo, "a FIFO"}, std::pair{dir, "a folder"}}) {
        try {
            load_scene_file(path.string());
            ADD_FAILURE() << kind << " was read as a scene";
        } catch (const SceneError& e) {
            EXPECT_NE(e.found.find(kind), std::string::npos) << e.what();
        }
    }
    fs::remove_all(dir);
}

RunResult run_quietly(const std::string& json, const std::string& name) {
    RunOptions options;
    options.quiet = true;
    options.out_dir = fs::temp_directory_path() / ("karst_test_" + name);
    RunResult r = run_simulation(parse_scene(json), options);
    fs::remove_all(*options.out_dir);
    return r;
}

/// A run of a scene kept in tests/data/bad_scenes.
RunResult run_kept_scene(const std::string& file) {
    return run_quietly(test::read_text(fs::path(KARST_SOURCE_DIR) / "tests/data/bad_scenes" / file),
                       fs::path(file).stem().string());
}

TEST(HostileInput, AStepBelowDtMinStopsTheRun) {
    const RunResult r = run_kept_scene("rc0_dt_min_not_enforced.json");
    EXPECT_FALSE(r.ok);
    EXPECT_NE(r.failure.find("below /time/dt_min"), std::string::npos) << r.failure;
}

TEST(HostileInput, AFixedStepNeverOvershootsTheEndTime) {
    const RunResult r =
        run_quietly(fluid_scene(k_box, R"(,"time":{"end":0.02,"fixed_dt":1},"output":{"fps":100})"),
                    "fixed_dt");
    ASSERT_TRUE(r.ok) << r.failure;
    EXPECT_DOUBLE_EQ(r.stats["sim_time"].get<double>(), 0.02);
    EXPECT_EQ(r.stats["steps"].get<int>(), 1);
}

TEST(HostileInput, NonFiniteBiotFieldsStopTheRunNamingTheNode) {
    // E = 1 Pa against a nearly incompressible pore fluid, without the fixed-stress split: the
    // iterations diverge to NaN (once exit 0, and a crash in the pore pairs of a coupled run).
    const RunResult r = run_quietly(R"({"name": "nan_biot", "particle_spacing": 0.1,
      "time": {"end": 0.3},
      "porous_solids": [{"shape": {"type": "box", "min": [0,0,0], "max": [0.6,0.6,0.6]},
        "material": {"porosity": 0.35, "permeability": 4e-08, "youngs_modulus": 1,
                     "biot_coefficient": 1.0, "initial_saturation": 1.0},
        "constraints": [{"kind": "fixed", "region": {"type": "box", "min": [-1,-1,-1], "max": [2,2,0]}}]}],
      "poroelastic": {"splitting": "fixed_strain", "fluid_bulk_modulus": 1e12,
                      "max_iterations": 200, "acceleration": "none", "time_step": 0.05}})",
                                    "nan_biot");
    EXPECT_FALSE(r.ok);
    EXPECT_NE(r.failure.find("non-finite displacement (Biot)"), std::string::npos) << r.failure;
    EXPECT_NE(r.failure.find("stage 'structure' at particle"), std::string::npos);
    EXPECT_GT(r.stats["biot"]["unconverged_calls"].get<int>(), 0);
}

TEST(HostileInput, ABiotStepLongerThanTheRunIsToldNotIgnored) {
    // It ran to its end with biot.calls 0 and said nothing.
    const std::string scene = R"({"name": "biot_never", "particle_spacing": 0.05,
      "time": {"end": 0.1},
      "porous_solids": [{"shape": {"type": "box", "min": [0,0,0], "max": [0.2,0.2,0.2]},
        "constraints": [{"kind": "fixed", "region": {"type": "box", "min": [-1,-1,-1], "max": [2,2,0.01]}}]}],
      "poroelastic": {"time_step": )";
    for (const char* time_step : {"0.5", "0.04"}) {
        testing::internal::CaptureStderr();
        const RunResult r = run_quietly(scene + time_step + "}}", "biot_never");
        const std::string told = testing::internal::GetCapturedStderr();
        ASSERT_TRUE(r.ok) << r.failure;
        const bool never = r.stats["biot"]["calls"].get<int>() == 0;
        EXPECT_EQ(never, std::string(time_step) == "0.5");
        EXPECT_EQ(told.find("the Biot solver never runs") != std::string::npos, never) << told;
    }
}

TEST(HostileInput, PoreWaterTooStiffForItsMobilityStopsTheRun) {
    const RunResult r = run_kept_scene("rc0_nan_biot_fixed_strain.json");
    EXPECT_FALSE(r.ok);
    EXPECT_NE(r.failure.find("sub-steps"), std::string::npos) << r.failure;
}

/// Exit code of the karst binary on `args`, killed after `seconds` (124 then).
int karst_exit_code(const std::string& args, int seconds) {
    return test::exit_code_of("timeout " + std::to_string(seconds) + " " + KARST_BINARY + " " +
                              args);
}

TEST(HostileInput, EveryKeptFuzzCaseIsRefusedByCheck) {
    const fs::path dir = fs::path(KARST_SOURCE_DIR) / "tests/data/bad_scenes/fuzz";
    const fs::path scene = fs::temp_directory_path() / "karst_test_fuzz_case.json";
    int cases = 0;
    for (const auto& entry : fs::directory_iterator(dir)) {
        ++cases;
        ASSERT_EQ(std::system(
                      ("zcat '" + entry.path().string() + "' > '" + scene.string() + "'").c_str()),
                  0);
        EXPECT_EQ(karst_exit_code("check " + scene.string(), 120), 2) << entry.path();
    }
    EXPECT_GE(cases, 30);
    fs::remove(scene);
}

TEST(HostileInput, EveryKeptSceneEndsWithItsExitCode) {
    const fs::path dir = fs::path(KARST_SOURCE_DIR) / "tests/data/bad_scenes";
    const fs::path out = fs::temp_directory_path() / "karst_test_bad_scenes";
    // exit code of `karst check`, of `karst run` (the runs that are refused only in the run
    // are none: check and run refuse the same scenes).
    const std::vector<std::tuple<const char*, int, int>> expected{
        {"crash_run_cave_biot_nan_segv.json", 0, 1},
        {"hang_biot_time_step_1e-300.json", 2, 2},
        {"rc0_dt_min_not_enforced.json", 0, 1},
        {"rc0_fast_fragment_escapes_container.json", 0, 1},
        {"rc0_fixed_dt_overshoots_end.json", 0, 0},
        {"rc0_nan_biot_fixed_strain.json", 0, 1},
        {"rc0_poroelastic_spread_without_elements.json", 0, 1},
        {"rc1_biot_time_step_denormal.json", 2, 2},
        {"watchdog_ok_speed.json", 0, 0},
    };
    int listed = 0;
    for (const auto& entry : fs::directory_iterator(dir))
        listed += entry.path().extension() == ".json";
    EXPECT_EQ(listed, int(expected.size())) << "a kept scene without an expected exit code";
    for (const auto& [name, check_code, run_code] : expected) {
        const std::string scene = (dir / name).string();
        EXPECT_EQ(karst_exit_code("check " + scene, 120), check_code) << name;
        EXPECT_EQ(karst_exit_code("run " + scene + " --quiet --out " + out.string(), 590), run_code)
            << name;
        fs::remove_all(out);
    }
}

}  // namespace
}  // namespace karst
