#include "karst/core/fnv1a.hpp"
#include "karst/scene/scene.hpp"
#include "karst/scene/read_json.hpp"
#include "karst/scene/scene_error.hpp"
#include "karst/scene/validate.hpp"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <bit>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <numbers>
#include <stdexcept>
#include <sstream>

namespace karst {

namespace {

using json = nlohmann::json;

/// FNV-1a of the validated document (defaults filled in, keys sorted) without /time/end, which a
/// resumed run may extend.
std::uint64_t scene_fingerprint(json doc) {
    doc["time"].erase("end");
    return fnv1a(doc.dump());
}

/// Scenes are hand-written or generated descriptions, never data: 64 MB is far beyond any.
constexpr std::uintmax_t k_max_scene_bytes = std::uintmax_t(64) << 20;

/// The name is the output folder's: file systems allow 255 bytes, and 128 leaves room.
constexpr size_t k_max_name_bytes = 128;

Vec3 vec3(const json& v) {
    return {v[0].get<Real>(), v[1].get<Real>(), v[2].get<Real>()};
}

/// The value of an enum key (validated against the schema's options): every option must map to
/// a value here, so an option added to the schema and forgotten here fails loudly.
template <class T>
T option(const json& v, std::initializer_list<std::pair<const char*, T>> options) {
    const std::string name = v.get<std::string>();
    for (const auto& [text, value] : options)
        if (name == text) return value;
    throw std::logic_error("scene reader: no value for the option '" + name + "'");
}

}  // namespace

Shape read_shape(const json& j, const std::string& path) {
    Shape s;
    const std::string type = j.at("type");
    if (type == "box") {
        s.kind = Shape::Kind::Box, s.a = vec3(j.at("min")), s.b = vec3(j.at("max"));
        for (int d = 0; d < 3; ++d)
            if (!(s.b[d] > s.a[d]))
                throw SceneError(path + "/max", fmt::format("max[{}] > min[{}] = {}", d, d, s.a[d]),
                                 fmt::format("{}", s.b[d]));
    } else if (type == "sphere") {
        s.kind = Shape::Kind::Sphere, s.a = vec3(j.at("center")), s.radius = j.at("radius");
    } else if (type == "cylinder") {
        s.kind = Shape::Kind::Cylinder, s.a = vec3(j.at("base")), s.b = vec3(j.at("top")),
        s.radius = j.at("radius");
        if ((s.b - s.a).norm() <= 0)
            throw SceneError(path + "/top", "a point different from base", j.at("top").dump());
    } else {
        s.kind = type == "union" ? Shape::Kind::Union : Shape::Kind::Difference;
        const json& shapes = j.at("shapes");
        for (size_t i = 0; i < shapes.size(); ++i)
            s.children.push_back(read_shape(shapes[i], fmt::format("{}/shapes/{}", path, i)));
    }
    return s;
}

Scene parse_scene(const std::string& text) {
    json doc = read_scene_json(text);
    validate_scene_document(doc);

    Scene s;
    s.name = doc["name"];
    // The name becomes the folder out/<name>/: it must stay inside out/.
    const bool control = std::any_of(s.name.begin(), s.name.end(),
                                     [](char c) { return static_cast<unsigned char>(c) < 0x20; });
    if (s.name.find_first_of("/\\") != std::string::npos ||
        s.name.find("..") != std::string::npos || s.name == "." || control ||
        s.name.size() > k_max_name_bytes)
        throw SceneError("/name",
                         fmt::format("a plain folder name of at most {} bytes (no '/', '\\', "
                                     "'..' or control characters)",
                                     k_max_name_bytes),
                         s.name.size() > k_max_name_bytes
                             ? fmt::format("a name of {} bytes", s.name.size())
                             : doc["name"].dump());
    s.particle_spacing = doc["particle_spacing"];
    s.gravity = vec3(doc["gravity"]);
    if (doc.contains("domain")) {
        s.domain = Aabb{vec3(doc["domain"]["min"]), vec3(doc["domain"]["max"])};
        for (int d = 0; d < 3; ++d)
            if (!(s.domain->max[d] > s.domain->min[d]))
                throw SceneError(fmt::format("/domain/max/{}", d),
                                 fmt::format("a value above min {}", s.domain->min[d]),
                                 fmt::format("{}", s.domain->max[d]));
    }
    const json& t = doc["time"];
    s.time.end = t["end"], s.time.cfl = t["cfl"], s.time.dt_max = t["dt_max"],
    s.time.dt_min = t["dt_min"];
    if (t.contains("fixed_dt")) s.time.fixed_dt = t["fixed_dt"].get<Real>();
    if (s.time.dt_min > s.time.dt_max)
        throw SceneError("/time/dt_min", fmt::format("a value at most dt_max = {}", s.time.dt_max),
                         fmt::format("{}", s.time.dt_min));

    const json& f = doc["fluid"];
    s.fluid.rest_density = f["rest_density"], s.fluid.viscosity = f["viscosity"];
    s.fluid.artificial_viscosity = f["artificial_viscosity"];
    s.fluid.surface_tension = f["surface_tension"], s.fluid.adhesion = f["adhesion"];
    s.fluid.wall_friction = f["wall_friction"], s.fluid.sound_speed = f["sound_speed"];
    s.fluid.solute_diffusivity = f["solute_diffusivity"];
    s.fluid.solver = option<FluidSettings::Solver>(
        f["solver"],
        {{"dfsph", FluidSettings::Solver::Dfsph}, {"pcisph", FluidSettings::Solver::Pcisph}});
    s.fluid.max_density_error = f["max_density_error"];
    s.fluid.max_divergence_error = f["max_divergence_error"];
    s.fluid.min_iterations = f["min_iterations"], s.fluid.max_iterations = f["max_iterations"];
    if (s.fluid.min_iterations > s.fluid.max_iterations)
        throw SceneError("/fluid/min_iterations",
                         fmt::format("at most max_iterations = {}", s.fluid.max_iterations),
                         fmt::format("{}", s.fluid.min_iterations));

    for (size_t i = 0; i < doc["fluid_blocks"].size(); ++i) {
        const json& b = doc["fluid_blocks"][i];
        const std::string path = fmt::format("/fluid_blocks/{}", i);
        s.fluid_blocks.push_back({read_shape(b["shape"], path + "/shape"), vec3(b["velocity"]),
                                  path, b["concentration"].get<Real>()});
    }
    for (size_t i = 0; i < doc["walls"].size(); ++i) {
        const json& w = doc["walls"][i];
        const std::string path = fmt::format("/walls/{}", i);
        s.walls.push_back({read_shape(w["shape"], path + "/shape"),
                           option<Wall::Kind>(w["kind"], {{"container", Wall::Kind::Container},
                                                          {"obstacle", Wall::Kind::Obstacle}}),
                           w["layers"].get<int>(), path});
    }
    for (size_t i = 0; i < doc["porous_solids"].size(); ++i) {
        const json& j = doc["porous_solids"][i];
        PorousSolid solid;
        solid.path = fmt::format("/porous_solids/{}", i);
        solid.shape = read_shape(j["shape"], solid.path + "/shape");
        const json& m = j["material"];
        PorousMaterial& mat = solid.material;
        mat.porosity = m["porosity"], mat.permeability = m["permeability"],
        mat.darcy_viscosity = m["darcy_viscosity"];
        mat.solid_density = m["solid_density"], mat.youngs_modulus = m["youngs_modulus"];
        mat.poisson_ratio = m["poisson_ratio"], mat.biot_coefficient = m["biot_coefficient"];
        mat.tensile_strength = m["tensile_strength"], mat.fracture_energy = m["fracture_energy"];
        if (m.contains("tensile_strength_wet"))
            mat.tensile_strength_wet = m["tensile_strength_wet"].get<Real>();
        if (m.contains("compressive_strength")) {
            mat.compressive_strength = m["compressive_strength"].get<Real>();
            if (!(*mat.compressive_strength > mat.tensile_strength))
                throw SceneError(solid.path + "/material/compressive_strength",
                                 fmt::format("a compressive strength above the tensile strength "
                                             "({} Pa)",
                                             mat.tensile_strength),
                                 m["compressive_strength"].dump());
        }
        mat.friction_angle = m["friction_angle"].get<Real>() * std::numbers::pi / 180;
        mat.capillary_pressure = m["capillary_pressure"],
        mat.capillary_exponent = m["capillary_exponent"];
        mat.pore_stiffness = m["pore_stiffness"],
        mat.saturation_exponent = m["saturation_exponent"];
        mat.pore_exponent = m["pore_exponent"];
        mat.initial_saturation = m["initial_saturation"];
        mat.dissolution_porosity = m["dissolution_porosity"],
        mat.dissolution_saturation = m["dissolution_saturation"];
        mat.absorption_factor = m["absorption_factor"];
        using Layering = PorousMaterial::Layering;
        mat.layering =
            option<Layering>(j["layering"]["kind"], {{"bedding", Layering::Bedding},
                                                     {"fibre", Layering::Fibre},
                                                     {"from_geometry", Layering::FromGeometry}});
        solid.anchored = j["anchored"], solid.velocity = vec3(j["velocity"]),
        solid.angular_velocity = vec3(j["angular_velocity"]);
        mat.layering_normal = vec3(j["layering"]["normal"]),
        mat.layering_ratio = j["layering"]["ratio"];
        if (j["layering"].contains("tensile_strength_across")) {
            if (mat.layering == Layering::Fibre)
                throw SceneError(solid.path + "/layering/tensile_strength_across",
                                 "no strength across layers for fibres (bedding or "
                                 "from_geometry only)",
                                 j["layering"]["tensile_strength_across"].dump());
            mat.strength_across = j["layering"]["tensile_strength_across"].get<Real>();
        }
        if (mat.layering_normal.norm() < 1e-6)
            throw SceneError(solid.path + "/layering/normal", "a direction of length at least 1e-6",
                             j["layering"]["normal"].dump());
        for (size_t w = 0; w < j["wet_regions"].size(); ++w)
            solid.wet_regions.push_back(
                {read_shape(j["wet_regions"][w]["region"],
                            fmt::format("{}/wet_regions/{}/region", solid.path, w)),
                 j["wet_regions"][w]["saturation"].get<Real>()});
        if (mat.biot_coefficient < mat.porosity)  // else the grains would have negative storage
            throw SceneError(solid.path + "/material/biot_coefficient",
                             fmt::format("a value at least the porosity {}", mat.porosity),
                             fmt::format("{}", mat.biot_coefficient));
        for (size_t c = 0; c < j["constraints"].size(); ++c) {
            const json& cj = j["constraints"][c];
            Constraint con;
            con.path = fmt::format("{}/constraints/{}", solid.path, c);
            con.kind =
                option<Constraint::Kind>(cj["kind"], {{"fixed", Constraint::Kind::Fixed},
                                                      {"drained", Constraint::Kind::Drained},
                                                      {"traction", Constraint::Kind::Traction},
                                                      {"platen", Constraint::Kind::Platen}});
            con.region = read_shape(cj["region"], con.path + "/region");
            const std::string axes = cj["axes"];
            con.axes = std::uint8_t((axes.find('x') != std::string::npos ? 1 : 0) |
                                    (axes.find('y') != std::string::npos ? 2 : 0) |
                                    (axes.find('z') != std::string::npos ? 4 : 0));
            if (con.kind == Constraint::Kind::Platen && std::popcount(con.axes) != 1)
                throw SceneError(con.path + "/axes", "one axis (x, y or z) for a platen",
                                 cj["axes"].dump());
            con.pressure = cj["pressure"], con.traction = vec3(cj["traction"]);
            con.force = cj["force"];
            con.displacement = vec3(cj["displacement"]);
            if (cj.contains("table"))
                for (const json& row : cj["table"])
                    con.table.rows.emplace_back(row[0].get<Real>(), row[1].get<Real>());
            solid.constraints.push_back(std::move(con));
        }
        s.porous_solids.push_back(std::move(solid));
    }
    s.paper_eq20 =
        option<bool>(doc["pore_flow"]["pair_flux"], {{"darcy", false}, {"paper_eq20", true}});
    const json& pe = doc["poroelastic"];
    s.poroelastic.time_step = pe["time_step"],
    s.poroelastic.fluid_bulk_modulus = pe["fluid_bulk_modulus"];
    s.poroelastic.fixed_strain =
        option<bool>(pe["splitting"], {{"fixed_stress", false}, {"fixed_strain", true}});
    s.poroelastic.pressure_from_pore_water =
        option<bool>(pe["pressure_source"], {{"pore_water", true}, {"biot", false}});
    s.poroelastic.mfem_polyhedra =
        option<bool>(pe["shape_functions"], {{"p1", false}, {"mfem_polyhedra", true}});
    using Solver = PoroelasticSettings::LinearSolver;
    s.poroelastic.linear_solver =
        option<Solver>(pe["linear_solver"],
                       {{"auto", Solver::Auto}, {"direct", Solver::Direct}, {"amg", Solver::Amg}});
    s.poroelastic.coupled_fragments =
        option<bool>(pe["coupled_fragments"], {{"anchored", true}, {"none", false}});
    s.poroelastic.max_iterations = pe["max_iterations"], s.poroelastic.tolerance = pe["tolerance"];
    s.poroelastic.anderson =
        option<bool>(pe["acceleration"], {{"anderson", true}, {"none", false}});
    s.poroelastic.alpha = pe["alpha"], s.poroelastic.join_delta = pe["join_delta"];
    s.poroelastic.weighted_alpha = pe["weighted_alpha"];
    s.poroelastic.permeability_feedback = pe["permeability_feedback"];
    s.fracture.enabled = doc["fracture"]["enabled"],
    s.fracture.max_cracks_per_call = doc["fracture"]["max_cracks_per_call"];
    s.fracture.criterion = option<CrackCriterion>(
        doc["fracture"]["criterion"], {{"rankine", CrackCriterion::Rankine},
                                       {"separation_tensor", CrackCriterion::SeparationTensor},
                                       {"extension_strain", CrackCriterion::ExtensionStrain}});
    s.fracture.merge = doc["fracture"]["merge"];
    s.fracture.merge_saturation = doc["fracture"]["merge_saturation"];
    s.fracture.merge_speed = doc["fracture"]["merge_speed"];
    s.output.fps = doc["output"]["fps"], s.output.vtp = doc["output"]["vtp"],
    s.output.ply = doc["output"]["ply"], s.output.compress = doc["output"]["compress"];
    s.output.porous = doc["output"]["porous"], s.output.mesh = doc["output"]["mesh"];
    s.output.walls = doc["output"]["walls"], s.output.cracks = doc["output"]["cracks"];
    s.output.fluid_surface = doc["output"]["fluid_surface"],
    s.output.porous_surface = doc["output"]["porous_surface"];
    s.output.level_set = doc["output"]["level_set"];
    s.output.surface_voxel = doc["output"]["surface_voxel"];
    s.output.anisotropic_surface = doc["output"]["anisotropic_surface"];
    const json& r = doc["render"];
    if (r.contains("camera_position")) s.render.camera_position = vec3(r["camera_position"]);
    if (r.contains("camera_target")) s.render.camera_target = vec3(r["camera_target"]);
    s.render.fov = r["fov"], s.render.width = r["width"], s.render.height = r["height"];
    s.render.samples = r["samples"];
    if (s.render.camera_position && s.render.camera_target &&
        *s.render.camera_position == *s.render.camera_target)
        throw SceneError("/render/camera_target", "a point other than /render/camera_position",
                         "the same point");
    s.max_speed = doc["watchdog"]["max_speed"];
    s.sort_interval = doc["numerics"]["sort_interval"];
    s.fingerprint = scene_fingerprint(doc);
    return s;
}

Scene load_scene_file(const std::string& path) {
    // Only a regular file: a FIFO would block the read forever, a folder reads as nothing.
    namespace fs = std::filesystem;
    std::error_code ec;
    const fs::file_status status = fs::status(path, ec);
    if (fs::exists(status) && !fs::is_regular_file(status)) {
        const char* kind = fs::is_directory(status) ? "a folder"
                           : fs::is_fifo(status)    ? "a FIFO (named pipe)"
                                                    : "not a regular file";
        throw SceneError("", "a scene file (JSON)", fmt::format("{} at '{}'", kind, path));
    }
    const std::uintmax_t bytes = fs::exists(status) ? fs::file_size(path, ec) : 0;
    if (!ec && bytes > k_max_scene_bytes)
        throw SceneError("", fmt::format("a scene file of at most {} MB", k_max_scene_bytes >> 20),
                         fmt::format("{} bytes at '{}'", bytes, path));
    std::ifstream in(path, std::ios::binary);
    if (!in) throw SceneError("", "a readable scene file", fmt::format("no file at '{}'", path));
    std::stringstream ss;
    ss << in.rdbuf();
    return parse_scene(ss.str());
}

}  // namespace karst
