// `karst check` refuses exactly what `karst run` refuses (issue 12): every refusal that a run
// can make before simulating, through the CLI, gives exit 2 and the same message from both, and
// run writes nothing.
#include "support/files.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace {

namespace fs = std::filesystem;

struct Outcome {
    int exit_code = -1;
    std::string message;
};

Outcome karst(const std::string& args, const fs::path& err) {
    const int status = std::system(
        (std::string(KARST_BINARY) + " " + args + " --quiet 2> " + err.string() + " >/dev/null")
            .c_str());
    return {WEXITSTATUS(status), karst::test::read_text(err)};
}

Outcome check(const std::string& args, const fs::path& err) {
    const int status = std::system(
        (std::string(KARST_BINARY) + " check " + args + " 2> " + err.string() + " >/dev/null")
            .c_str());
    return {WEXITSTATUS(status), karst::test::read_text(err)};
}

/// A small coupled scene: water over an anchored soil block in a tank, and a free block.
/// `solids` replaces the porous solids, `extra` adds top-level keys.
std::string coupled_scene(const std::string& solids, const std::string& extra = "") {
    return R"({ "name": "refused", "particle_spacing": 0.05, "time": { "end": 0.01 },)" + extra +
           R"(
  "fluid_blocks": [ { "shape": { "type": "box", "min": [0, 0, 0.2], "max": [0.4, 0.4, 0.3] } } ],
  "walls": [ { "kind": "container", "shape": { "type": "box", "min": [0, 0, 0], "max": [0.4, 0.4, 0.6] } } ],
  "porous_solids": [ )" +
           solids + R"( ] })";
}

const char* k_fixed_base =
    R"("constraints": [ { "kind": "fixed", "axes": "xyz", "region": { "type": "box", "min": [-1, -1, -1], "max": [2, 2, 0.01] } } ])";

std::string block(const std::string& material, const std::string& more = "") {
    return R"({ "shape": { "type": "box", "min": [0, 0, 0], "max": [0.4, 0.4, 0.1] }, "material": )" +
           material + more + " }";
}

TEST(CheckAgreesWithRun, EveryRunTimeRefusalIsRefusedByCheckWithTheSamePath) {
    const std::string soil = R"({ "porosity": 0.3, "permeability": 1e-10 })";
    const std::string terzaghi = karst::test::read_text(std::string(KARST_SOURCE_DIR) +
                                                        "/scenes/terzaghi_consolidation.json");
    auto replaced = [](std::string s, const std::string& from, const std::string& to) {
        const auto at = s.find(from);
        EXPECT_NE(at, std::string::npos) << from;
        return at == std::string::npos ? s : s.replace(at, from.size(), to);
    };
    const struct {
        std::string scene, path;
    } cases[] = {
        // A poroelastic-only solid without pores has no pore pressure.
        {replaced(terzaghi, "\"porosity\": 0.1", "\"porosity\": 0"),
         "/porous_solids/0/material/porosity"},
        // Constraints where no Biot problem is solved.
        {coupled_scene(block(soil, std::string(", \"anchored\": false, ") + k_fixed_base)),
         "/porous_solids/0/constraints"},
        {coupled_scene(block(R"({ "porosity": 0 })", std::string(", ") + k_fixed_base)),
         "/porous_solids/0/constraints"},
        {coupled_scene(block(soil, std::string(", ") + k_fixed_base),
                       R"( "poroelastic": { "coupled_fragments": "none" },)"),
         "/porous_solids/0/constraints"},
        // A viscosity whose stable explicit step lies under dt_min.
        {replaced(coupled_scene(block(soil), R"( "fluid": { "viscosity": 1 },)"), "\"end\": 0.01 }",
                  "\"end\": 0.01, \"dt_min\": 1e-3 }"),
         "/fluid/viscosity"},
        // Geometry and schema refusals, for completeness.
        {coupled_scene(block(soil), R"( "domain": { "min": [0, 0, 0], "max": [0.1, 0.1, 0.1] },)"),
         "/domain"},
        {coupled_scene(block(R"({ "porosity": 0.3, "permeabilty": 1e-10 })")),
         "/porous_solids/0/material/permeabilty"},
    };
    const fs::path dir = fs::temp_directory_path() / "karst_test_check_agrees";
    fs::remove_all(dir);
    fs::create_directories(dir);
    int n = 0;
    for (const auto& c : cases) {
        const fs::path scene = dir / ("scene" + std::to_string(n++) + ".json");
        std::ofstream(scene) << c.scene;
        const Outcome checked = check(scene.string(), dir / "check.err");
        const Outcome ran =
            karst("run " + scene.string() + " --out " + (dir / "out").string(), dir / "run.err");
        EXPECT_EQ(checked.exit_code, 2) << c.path << ": " << checked.message;
        EXPECT_EQ(ran.exit_code, 2) << c.path << ": " << ran.message;
        EXPECT_NE(checked.message.find(c.path), std::string::npos) << checked.message;
        EXPECT_EQ(checked.message, ran.message);
        EXPECT_FALSE(fs::exists(dir / "out")) << "a refused run writes nothing";
    }
    fs::remove_all(dir);
}

}  // namespace
