// Every class of bad scene is refused before simulating, naming the JSON path, what was
// expected and what was found.
#include "karst/scene/scene.hpp"
#include "karst/scene/scene_error.hpp"
#include "karst/scene/schema.hpp"
#include "karst/sim/model.hpp"

#include "support/files.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

namespace karst {
namespace {

const char* k_valid = R"({
  "name": "ok",
  "particle_spacing": 0.05,
  "fluid_blocks": [ { "shape": { "type": "box", "min": [0, 0, 0], "max": [0.2, 0.2, 0.2] } } ],
  "walls": [ { "kind": "container", "shape": { "type": "box", "min": [0, 0, 0], "max": [0.5, 0.5, 0.5] } } ]
})";

SceneError refuse(const std::string& json) {
    return test::refuse_scene(json);
}

std::string replace(std::string s, const std::string& from, const std::string& to) {
    const auto at = s.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    return s.replace(at, from.size(), to);
}

TEST(SceneErrors, ValidSceneLoads) {
    const Model m = build_model(parse_scene(k_valid));
    EXPECT_EQ(m.initial_x.size(), 64u);  // 4^3 lattice points in a 0.2 m cube at 0.05 m
    EXPECT_GT(m.walls.size(), 0);
    EXPECT_DOUBLE_EQ(m.scene.fluid.viscosity, 1e-6);  // default filled in
}

TEST(SceneErrors, MisspeltKeyIsNamedWithSuggestion) {
    const SceneError e = refuse(replace(k_valid, "\"particle_spacing\"", "\"particle_spacng\""));
    // The misspelt key is unknown (it does not fall back to a default).
    EXPECT_EQ(e.path, "/particle_spacng");
    EXPECT_NE(e.expected.find("particle_spacing"), std::string::npos);
    EXPECT_NE(e.found.find("unknown key"), std::string::npos);
}

TEST(SceneErrors, UnknownNestedKey) {
    const SceneError e = refuse(
        replace(k_valid, "\"kind\": \"container\"", "\"kind\": \"container\", \"colour\": 3"));
    EXPECT_EQ(e.path, "/walls/0/colour");
}

TEST(SceneErrors, WrongType) {
    const SceneError e =
        refuse(replace(k_valid, "\"particle_spacing\": 0.05", "\"particle_spacing\": \"fine\""));
    EXPECT_EQ(e.path, "/particle_spacing");
    EXPECT_NE(e.expected.find("number"), std::string::npos);
    EXPECT_NE(e.found.find("string"), std::string::npos);
    const SceneError v = refuse(
        replace(k_valid, "\"min\": [0, 0, 0], \"max\": [0.2", "\"min\": [0, 0], \"max\": [0.2"));
    EXPECT_EQ(v.path, "/fluid_blocks/0/shape/min");
}

TEST(SceneErrors, OutOfRange) {
    const SceneError e =
        refuse(replace(k_valid, "\"particle_spacing\": 0.05",
                       "\"particle_spacing\": 0.05, \"fluid\": {\"viscosity\": -1}"));
    EXPECT_EQ(e.path, "/fluid/viscosity");
    EXPECT_NE(e.expected.find("m^2/s"), std::string::npos);
    EXPECT_EQ(e.found, "-1");
    const SceneError s =
        refuse(replace(k_valid, "\"particle_spacing\": 0.05", "\"particle_spacing\": 0"));
    EXPECT_EQ(s.path, "/particle_spacing");
}

TEST(SceneErrors, MissingRequiredKeyAndBadEnum) {
    EXPECT_EQ(refuse(replace(k_valid, "\"name\": \"ok\",", "")).path, "/name");
    const SceneError e =
        refuse(replace(k_valid, "\"type\": \"box\", \"min\": [0, 0, 0], \"max\": [0.2",
                       "\"type\": \"cube\", \"min\": [0, 0, 0], \"max\": [0.2"));
    EXPECT_EQ(e.path, "/fluid_blocks/0/shape/type");
    EXPECT_NE(e.expected.find("\"sphere\""), std::string::npos);
}

TEST(SceneErrors, ACompressiveStrengthBelowTheTensileIsRefused) {
    const std::string solid = replace(
        k_valid, "\"walls\"",
        R"("porous_solids": [ { "shape": { "type": "box", "min": [0.3, 0.3, 0], "max": [0.45, 0.45, 0.15] },
      "material": { "tensile_strength": 5e4, "compressive_strength": 4e4 } } ],
  "walls")");
    const SceneError e = refuse(solid);
    EXPECT_EQ(e.path, "/porous_solids/0/material/compressive_strength");
    EXPECT_NE(e.expected.find("above the tensile strength"), std::string::npos) << e.expected;
    EXPECT_EQ(e.found, "40000.0");
    EXPECT_NO_THROW(build_model(parse_scene(replace(solid, "4e4", "4e5"))));
}

TEST(SceneErrors, InvalidJsonSyntax) {
    const SceneError e = refuse("{ \"name\": ");
    EXPECT_NE(e.found.find("syntax error"), std::string::npos);
}

TEST(SceneErrors, EmptyGeometry) {
    // A sphere smaller than the lattice spacing holds no sample point.
    const SceneError e =
        refuse(replace(k_valid, R"({ "type": "box", "min": [0, 0, 0], "max": [0.2, 0.2, 0.2] })",
                       R"({ "type": "sphere", "center": [0.1, 0.1, 0.1], "radius": 0.001 })"));
    EXPECT_EQ(e.path, "/fluid_blocks/0/shape");
    EXPECT_NE(e.found.find("empty"), std::string::npos);
    // A difference that removes everything.
    const SceneError d = refuse(replace(
        k_valid, R"({ "type": "box", "min": [0, 0, 0], "max": [0.2, 0.2, 0.2] })",
        R"({ "type": "difference", "shapes": [ { "type": "box", "min": [0, 0, 0], "max": [0.2, 0.2, 0.2] },
                                               { "type": "sphere", "center": [0.1, 0.1, 0.1], "radius": 1 } ] })"));
    EXPECT_EQ(d.path, "/fluid_blocks/0/shape");
    // A box whose max is not above its min.
    EXPECT_EQ(refuse(replace(k_valid, "\"max\": [0.2, 0.2, 0.2]", "\"max\": [0.2, 0.0, 0.2]")).path,
              "/fluid_blocks/0/shape/max");
}

TEST(SceneErrors, OverlappingGeometry) {
    const SceneError e = refuse(replace(
        k_valid, "\"fluid_blocks\": [",
        R"("fluid_blocks": [ { "shape": { "type": "sphere", "center": [0.1, 0.1, 0.1], "radius": 0.08 } },)"));
    EXPECT_EQ(e.path, "/fluid_blocks/1/shape");
    EXPECT_NE(e.found.find("/fluid_blocks/0"), std::string::npos);
    // Fluid inside an obstacle.
    const SceneError o = refuse(replace(
        k_valid, "\"walls\": [",
        R"("walls": [ { "shape": { "type": "cylinder", "base": [0.1, 0.1, 0], "top": [0.1, 0.1, 0.3], "radius": 0.05 } },)"));
    EXPECT_EQ(o.path, "/walls/0/shape");
    // Fluid sticking out of its container.
    EXPECT_EQ(refuse(replace(k_valid, "\"max\": [0.5, 0.5, 0.5]", "\"max\": [0.5, 0.5, 0.1]")).path,
              "/walls/0/shape");
}

TEST(SceneErrors, TooManyParticles) {
    const SceneError e =
        refuse(replace(k_valid, "\"particle_spacing\": 0.05", "\"particle_spacing\": 0.0004"));
    EXPECT_EQ(e.path, "/particle_spacing");
    EXPECT_NE(e.found.find("million"), std::string::npos);
}

TEST(SceneErrors, DomainMustHoldParticles) {
    const SceneError e = refuse(replace(
        k_valid, "\"particle_spacing\": 0.05",
        "\"particle_spacing\": 0.05, \"domain\": {\"min\": [0,0,0], \"max\": [0.1,0.1,0.1]}"));
    EXPECT_EQ(e.path, "/domain");
}

TEST(SceneFormat, GeneratedDocsAreCommitted) {
    std::ifstream in(std::string(KARST_SOURCE_DIR) + "/docs/scene_format.md");
    std::stringstream ss;
    ss << in.rdbuf();
    EXPECT_EQ(ss.str(), scene_schema_markdown())
        << "regenerate with: karst schema > docs/scene_format.md";
}

TEST(SceneFormat, ShippedScenesAreValid) {
    for (const char* name :
         {"dam_break_obstacle.json", "martin_moyce_dam_break.json", "bench_dam_break_118k.json",
          "collapsing.json", "hydraulic_fracture.json", "soaked_block.json"}) {
        const std::string path = std::string(KARST_SOURCE_DIR) + "/scenes/" + name;
        EXPECT_NO_THROW(load_scene_file(path)) << path;
    }
}

}  // namespace
}  // namespace karst
