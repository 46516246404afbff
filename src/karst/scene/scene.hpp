#pragma once
// The scene as plain typed data, read from a validated JSON document (every key present or
// defaulted by the schema). Model building (sim/model.cpp) turns it into particles.
#include "karst/core/types.hpp"
#include "karst/scene/geometry.hpp"

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace karst {

struct TimeSettings {
    Real end = 2.0;                ///< s
    Real cfl = 0.4;                ///< lambda_v of M11
    Real dt_max = 5e-3;            ///< s
    Real dt_min = 1e-7;            ///< s
    std::optional<Real> fixed_dt;  ///< s; absent: adaptive
};

struct FluidSettings {
    Real rest_density = 1000;       ///< rho0, kg/m^3
    Real viscosity = 1e-6;          ///< nu, m^2/s
    Real artificial_viscosity = 0.01;  ///< alpha_v (Becker & Teschner 2007)
    Real surface_tension = 0;       ///< gamma_st
    Real adhesion = 0;              ///< beta_adh
    Real wall_friction = 0;         ///< sigma_f
    Real sound_speed = 20;          ///< c_s, m/s
    Real solute_diffusivity = 1e-4; ///< D of M18, m^2/s
    enum class Solver { Dfsph, Pcisph };
    Solver solver = Solver::Dfsph;  ///< pressure solver
    Real max_density_error = 0.01;  ///< eta_rho
    Real max_divergence_error = 0.01;   ///< DFSPH divergence solve: largest dt Drho/Dt / rho0
    int min_iterations = 3;
    int max_iterations = 50;
};

struct FluidBlock {
    Shape shape;
    Vec3 velocity = Vec3::Zero();  ///< m/s
    std::string path;              ///< JSON pointer, for error messages
    Real concentration = 0;        ///< initial C = m_sol / m
};

struct Wall {
    enum class Kind { Obstacle, Container };
    Shape shape;
    Kind kind = Kind::Obstacle;
    int layers = 1;
    std::string path;
};

struct PorousMaterial {
    Real porosity = 0.3;            ///< phi0
    Real permeability = 2e-8;       ///< k0, m^2
    Real darcy_viscosity = 0.1;     ///< eta, Pa s
    Real solid_density = 2650;      ///< rho_s, kg/m^3
    Real youngs_modulus = 1e6;      ///< E (drained), Pa
    Real poisson_ratio = 0.25;
    Real biot_coefficient = 0.9;    ///< B
    Real tensile_strength = 1e5;    ///< sigma_t, Pa
    Real capillary_pressure = 2000;   ///< k^c, Pa
    Real capillary_exponent = 0.5;    ///< alpha
    Real pore_stiffness = 1.4e4;      ///< k^p, Pa
    Real pore_exponent = 7;           ///< gamma of M5
    Real saturation_exponent = 2;     ///< beta
    Real initial_saturation = 0;
    enum class Layering { Bedding, Fibre, FromGeometry };
    Layering layering = Layering::Bedding;
    Vec3 layering_normal{0, 0, 1};    ///< bedding normal, or fibre tangent
    Real layering_ratio = 1;          ///< k along / k across the layers (fibres)
    Real dissolution_porosity = 0.6;  ///< phi_diss (method.md §4.8)
    Real dissolution_saturation = 0.98;  ///< S_diss
    Real absorption_factor = 1;       ///< chi_abs of M15
};

struct WetRegion {
    Shape region;
    Real saturation = 1;
};

/// A boundary condition of the Biot problem on a region of a porous solid.
struct Constraint {
    enum class Kind { Fixed, Drained, Traction };
    Kind kind = Kind::Fixed;
    Shape region;
    std::uint8_t axes = 7;                ///< Fixed: bits x = 1, y = 2, z = 4
    Real pressure = 0;                    ///< Drained, Pa
    Vec3 traction = Vec3::Zero();         ///< Traction, Pa
    std::string path;
};

struct PorousSolid {
    Shape shape;
    bool anchored = true;                     ///< else a free rigid fragment (method.md §4.5)
    Vec3 velocity = Vec3::Zero();             ///< initial, m/s
    Vec3 angular_velocity = Vec3::Zero();     ///< initial, rad/s
    PorousMaterial material;
    std::vector<Constraint> constraints;
    std::vector<WetRegion> wet_regions;
    std::string path;
};

struct PoroelasticSettings {
    Real time_step = 1.0 / 30;       ///< dt_B, s
    Real fluid_bulk_modulus = 1e5;   ///< K_f, Pa
    bool fixed_strain = false;       ///< the paper's splitting instead of fixed-stress
    bool pressure_from_pore_water = true;  ///< seed p^n from M5 each call (else carry the Biot p)
    bool mfem_polyhedra = false;     ///< M21 shape functions instead of P1
    std::string linear_solver = "auto";  ///< auto | direct | amg (LinearSolver in pfem/biot.hpp)
    bool coupled_fragments = true;   ///< Biot on anchored fragments in coupled scenes
    int max_iterations = 5;
    bool anderson = true;            ///< Anderson-accelerated fixed-stress iterations
    Real tolerance = 1e-3;
    bool permeability_feedback = true;  ///< §5.4 after every call
    Real alpha = 1.25;               ///< M19
    Real join_delta = 0.1;           ///< M20
    bool weighted_alpha = false;
};

struct OutputSettings {
    Real fps = 30;
    bool vtp = true;
    bool ply = true;
};

struct Scene {
    std::string name;
    Real particle_spacing = 0.02;  ///< dx, m
    Vec3 gravity{0, 0, -9.81};     ///< m/s^2
    std::optional<Aabb> domain;
    TimeSettings time;
    FluidSettings fluid;
    std::vector<FluidBlock> fluid_blocks;
    std::vector<Wall> walls;
    std::vector<PorousSolid> porous_solids;
    PoroelasticSettings poroelastic;
    bool paper_eq20 = false;       ///< /pore_flow/pair_flux: the paper's Eq. 20 instead of M15
    OutputSettings output;
    Real max_speed = 100;  ///< watchdog, m/s
    int sort_interval = 10;
};

/// Parses and validates scene text; throws SceneError (path, expected, found) on any problem.
Scene parse_scene(const std::string& text);
/// Reads a scene file; a missing or unreadable file is a SceneError too.
Scene load_scene_file(const std::string& path);
/// The built-in default scene (scenes/dam_break_obstacle.json, compiled in).
const std::string& default_scene_text();

}  // namespace karst
