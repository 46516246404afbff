#pragma once
// The scene as plain typed data, read from a validated JSON document (every key present or
// defaulted by the schema). Model building (sim/model.cpp) turns it into particles. Members
// carry no defaults of their own: the schema (scene/schema.cpp) is the one place that holds
// them, and parse_scene the one way to make a Scene.
#include "karst/core/types.hpp"
#include "karst/scene/geometry.hpp"

#include <nlohmann/json_fwd.hpp>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace karst {

struct TimeSettings {
    Real end{};                    ///< s
    Real cfl{};                    ///< lambda_v of M11
    Real dt_max{};                 ///< s
    Real dt_min{};                 ///< s
    std::optional<Real> fixed_dt;  ///< s; absent: adaptive
};

struct FluidSettings {
    Real rest_density{};          ///< rho0, kg/m^3
    Real viscosity{};             ///< nu, m^2/s
    Real artificial_viscosity{};  ///< alpha_v (Becker & Teschner 2007)
    Real surface_tension{};       ///< gamma_st
    Real adhesion{};              ///< beta_adh
    Real wall_friction{};         ///< sigma_f
    Real sound_speed{};           ///< c_s, m/s
    Real solute_diffusivity{};    ///< D of M18, m^2/s
    enum class Solver { Dfsph, Pcisph };
    Solver solver{};              ///< pressure solver
    Real max_density_error{};     ///< eta_rho
    Real max_divergence_error{};  ///< DFSPH divergence solve: largest dt Drho/Dt / rho0
    int min_iterations{};
    int max_iterations{};
};

struct FluidBlock {
    Shape shape;
    Vec3 velocity = Vec3::Zero();  ///< m/s
    std::string path;              ///< JSON pointer, for error messages
    Real concentration{};          ///< initial C = m_sol / m
};

struct Wall {
    enum class Kind { Obstacle, Container };
    Shape shape;
    Kind kind{};
    int layers{};
    std::string path;
};

struct PorousMaterial {
    Real porosity{};         ///< phi0
    Real permeability{};     ///< k0, m^2
    Real darcy_viscosity{};  ///< eta, Pa s
    Real solid_density{};    ///< rho_s, kg/m^3
    Real youngs_modulus{};   ///< E (drained), Pa
    Real poisson_ratio{};
    Real biot_coefficient{};  ///< B
    Real tensile_strength{};  ///< sigma_t, Pa
    /// sigma_t of the saturated material (S = 1), Pa; absent: sigma_t at every saturation.
    std::optional<Real> tensile_strength_wet;
    /// sigma_c of a Mohr-Coulomb shear test (M25), Pa; absent: no shear cracks.
    std::optional<Real> compressive_strength;
    Real friction_angle{};       ///< phi of the shear test, rad (degrees in the scene file)
    Real fracture_energy{};      ///< G_c (M26), J/m^2
    Real capillary_pressure{};   ///< k^c, Pa
    Real capillary_exponent{};   ///< alpha
    Real pore_stiffness{};       ///< k^p, Pa
    Real pore_exponent{};        ///< gamma of M5
    Real saturation_exponent{};  ///< beta
    Real initial_saturation{};
    enum class Layering { Bedding, Fibre, FromGeometry };
    Layering layering{};
    Vec3 layering_normal = Vec3::Zero();  ///< bedding normal, or fibre tangent
    Real layering_ratio{};                ///< k along / k across the layers (fibres)
    std::optional<Real> strength_across;  ///< sigma_t across bedding planes, Pa; absent: sigma_t
    Real dissolution_porosity{};          ///< phi_diss (docs/method.md §4.8)
    Real dissolution_saturation{};        ///< S_diss
    Real absorption_factor{};             ///< chi_abs of M15
};

struct WetRegion {
    Shape region;
    Real saturation{};
};

/// A piecewise-linear factor of time: constant before the first row and after the last; 1 when
/// it has no rows.
struct TimeTable {
    std::vector<std::pair<Real, Real>> rows;  ///< (t in s, factor), t increasing
    Real at(Real t) const {
        if (rows.empty()) return 1;
        if (t <= rows.front().first) return rows.front().second;
        for (size_t k = 1; k < rows.size(); ++k)
            if (t <= rows[k].first) {
                const auto [t0, f0] = rows[k - 1];
                const auto [t1, f1] = rows[k];
                return f0 + (f1 - f0) * (t - t0) / (t1 - t0);
            }
        return rows.back().second;
    }
};

/// A boundary condition of the Biot problem on a region of a porous solid. Its value (traction,
/// pressure or displacement) is multiplied by the table's factor at the time of each Biot call.
struct Constraint {
    enum class Kind { Fixed, Drained, Traction, Platen };
    Kind kind{};
    Shape region;
    std::uint8_t axes{};               ///< Fixed: bits x = 1, y = 2, z = 4; Platen: one bit
    Vec3 displacement = Vec3::Zero();  ///< Fixed, m
    Real pressure{};                   ///< Drained, Pa
    Vec3 traction = Vec3::Zero();      ///< Traction, Pa
    Real force{};                      ///< Platen: total force along its axis, N
    TimeTable table;
    std::string path;
};

struct PorousSolid {
    Shape shape;
    bool anchored{};                       ///< else a free rigid fragment (docs/method.md §4.5)
    Vec3 velocity = Vec3::Zero();          ///< initial, m/s
    Vec3 angular_velocity = Vec3::Zero();  ///< initial, rad/s
    PorousMaterial material;
    std::vector<Constraint> constraints;
    std::vector<WetRegion> wet_regions;
    std::string path;
};

struct PoroelasticSettings {
    Real time_step{};                 ///< dt_B, s
    Real fluid_bulk_modulus{};        ///< K_f, Pa
    bool fixed_strain{};              ///< the paper's splitting instead of fixed-stress
    bool pressure_from_pore_water{};  ///< seed p^n from M5 each call (else carry the Biot p)
    bool mfem_polyhedra{};            ///< M21 shape functions instead of P1
    enum class LinearSolver { Auto, Direct, Amg };
    LinearSolver linear_solver{};  ///< LinearSolver in pfem/biot.hpp says what each does
    bool coupled_fragments{};      ///< Biot on anchored fragments in coupled scenes
    int max_iterations{};
    bool anderson{};  ///< Anderson-accelerated fixed-stress iterations
    Real tolerance{};
    bool permeability_feedback{};  ///< §5.4 after every call
    Real alpha{};                  ///< M19
    Real join_delta{};             ///< M20
    bool weighted_alpha{};
};

/// Which nodes crack (docs/method.md §5.5): Rankine on the effective stress (M25), O'Brien &
/// Hodgins' separation tensor, or Stacey's extension strain.
enum class CrackCriterion { Rankine, SeparationTensor, ExtensionStrain };

struct FractureSettings {
    bool enabled{};
    int max_cracks_per_call{};  ///< N_crack
    CrackCriterion criterion{};
    bool merge{};             ///< wet fragments in slow contact join (§5.6)
    Real merge_saturation{};  ///< S_merge: mean saturation of the contact particles
    Real merge_speed{};       ///< v_merge: largest closing speed of a contact pair, m/s
};

/// The pictures of `karst render` (render/render.hpp); the camera is framed on the surfaces
/// where position or target is absent.
struct RenderSettings {
    std::optional<Vec3> camera_position, camera_target;  ///< m
    Real fov = 40;                                       ///< horizontal, degrees
    int width = 1280, height = 720;                      ///< pixels
    int samples = 2;  ///< anti-aliasing depth: up to samples^2 rays per pixel
};

struct OutputSettings {
    Real fps{};
    bool vtp{};
    bool ply{};
    bool porous{}, mesh{}, walls{}, cracks{};  ///< which VTK parts are written
    bool compress{};                           ///< zlib blocks in the VTK frames
    bool fluid_surface{}, porous_surface{};    ///< surface meshes (docs/method.md §7)
    bool level_set{};                          ///< the fluid level set as .vdb
    Real surface_voxel{};                      ///< fluid surface grid spacing / dx
    bool anisotropic_surface{};                ///< Yu-Turk kernels for the fluid surface
};

struct Scene {
    std::string name;
    Real particle_spacing{};      ///< dx, m
    Vec3 gravity = Vec3::Zero();  ///< m/s^2
    std::optional<Aabb> domain;
    TimeSettings time;
    FluidSettings fluid;
    std::vector<FluidBlock> fluid_blocks;
    std::vector<Wall> walls;
    std::vector<PorousSolid> porous_solids;
    PoroelasticSettings poroelastic;
    FractureSettings fracture;
    bool paper_eq20{};  ///< /pore_flow/pair_flux: the paper's Eq. 20 instead of M15
    OutputSettings output;
    RenderSettings render;
    Real max_speed{};  ///< watchdog, m/s
    int sort_interval{};
    /// Hash of the validated scene without /time/end: a checkpoint resumes only the scene it
    /// was written for (sim/checkpoint.hpp).
    std::uint64_t fingerprint{};
};

/// Parses and validates scene text; throws SceneError (path, expected, found) on any problem.
Scene parse_scene(const std::string& text);

/// A shape as the scene writes it (`type` and its keys; docs/scene_format.md), for a document
/// the schema validated or one karst wrote (render.json). Errors name `path`; a missing key or a
/// wrong type throws nlohmann::json::exception.
Shape read_shape(const nlohmann::json& j, const std::string& path);
/// Reads a scene file; a missing or unreadable file is a SceneError too.
Scene load_scene_file(const std::string& path);
/// The built-in default scene (scenes/dam_break_obstacle.json, compiled in).
const std::string& default_scene_text();

}  // namespace karst
