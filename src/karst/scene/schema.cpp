#include "karst/scene/schema.hpp"

#include <fmt/format.h>

#include <cmath>

namespace karst {

namespace {

constexpr double inf = std::numeric_limits<double>::infinity();
using json = nlohmann::json;

Range positive(double hi = inf) {
    return {0.0, hi, true, false};
}
Range closed(double lo, double hi) {
    return {lo, hi, false, false};
}
Range any() {
    return {};
}

KeySpec key(std::string pointer, ValueType type, std::string unit, Range range,
            std::optional<json> value, std::string doc, std::vector<std::string> options = {}) {
    return KeySpec{std::move(pointer), type,  std::move(unit), range,
                   std::move(value),   false, std::move(doc),  std::move(options)};
}
KeySpec required(std::string pointer, ValueType type, std::string unit, Range range,
                 std::string doc, std::vector<std::string> options = {}) {
    return KeySpec{std::move(pointer), type, std::move(unit), range,
                   std::nullopt,       true, std::move(doc),  std::move(options)};
}
KeySpec optional(std::string pointer, ValueType type, std::string unit, Range range,
                 std::string doc) {
    return KeySpec{std::move(pointer), type,  std::move(unit), range,
                   std::nullopt,       false, std::move(doc),  {}};
}

std::vector<KeySpec> make_schema() {
    using T = ValueType;
    const json zero3 = json::array({0.0, 0.0, 0.0});
    return {
        required("/name", T::String, "", any(),
                 "Scene name; output goes to out/<name>/ by default. A plain folder name of at "
                 "most 128 bytes (no '/', '\\', '..' or control characters)."),
        required("/particle_spacing", T::Number, "m", positive(10.0),
                 "Particle spacing dx. The SPH support radius is h = 2 dx (docs/method.md §1)."),
        key("/gravity", T::Vec3, "m/s^2", closed(-1000, 1000), json::array({0.0, 0.0, -9.81}),
            "Gravitational acceleration; z is up."),
        optional("/domain", T::Object, "", any(),
                 "Simulation box; particles leaving it are removed and counted. Absent: the bounds "
                 "of all geometry padded by 4 h on every side."),
        required("/domain/min", T::Vec3, "m", any(), "Lower corner of the domain."),
        required("/domain/max", T::Vec3, "m", any(), "Upper corner of the domain."),

        key("/time", T::Object, "", any(), json::object(), "Time integration."),
        key("/time/end", T::Number, "s", closed(0, 1e6), 2.0, "Simulated end time."),
        key("/time/cfl", T::Number, "", closed(0.01, 1.0), 0.4,
            "CFL number lambda_v: dt <= lambda_v dx / v_max (M11)."),
        key("/time/dt_max", T::Number, "s", positive(1.0), 5e-3, "Upper clamp of the time step."),
        key("/time/dt_min", T::Number, "s", positive(1.0), 1e-7,
            "Smallest adaptive step: a run whose step falls below it stops with exit 1 (it is "
            "unstable or far too fast for the spacing)."),
        optional("/time/fixed_dt", T::Number, "s", positive(1.0),
                 "Fixed time step; absent: adaptive CFL step (M11)."),

        key("/fluid", T::Object, "", any(), json::object(), "Fluid material and pressure solver."),
        key("/fluid/rest_density", T::Number, "kg/m^3", closed(100, 20000), 1000.0,
            "Rest density rho0."),
        key("/fluid/viscosity", T::Number, "m^2/s", closed(0, 1.0), 1e-6,
            "Kinematic viscosity nu (docs/method.md §4.2). Explicit: the step stays below 0.05 "
            "dx^2 / nu (with the artificial viscosity's share, M11), so a large nu takes short "
            "steps; a fixed_dt above that, or a bound under dt_min, is refused."),
        key("/fluid/artificial_viscosity", T::Number, "", closed(0, 1), 0.01,
            "alpha_v of the Becker-Teschner artificial viscosity (docs/method.md §4.2), acting "
            "only "
            "between "
            "approaching particles; 0 disables it. Water at scene resolution has almost no "
            "physical damping, and "
            "without some a resting tank starts to slosh and spray within a second (0.4 x 0.4 x "
            "0.2 m, dx = 0.02: "
            "6 m/s after 0.6 s). 0.01 keeps it bounded (RMS 0.03 m/s) and the Martin-Moyce front "
            "within 10 %; "
            "0.02 lets it settle (RMS 0.016 m/s after 1 s)."),
        key("/fluid/surface_tension", T::Number, "", closed(0, 100), 0.0,
            "Akinci 2013 surface-tension coefficient gamma_st (M9); 0 disables it."),
        key("/fluid/adhesion", T::Number, "", closed(0, 100), 0.0,
            "Akinci 2013 adhesion coefficient beta_adh to walls (M10); 0 disables it."),
        key("/fluid/wall_friction", T::Number, "", closed(0, 10), 0.0,
            "Akinci 2012 fluid-wall friction coefficient sigma_f; 0 gives free slip."),
        key("/fluid/sound_speed", T::Number, "m/s", positive(1e4), 20.0,
            "Numerical sound speed c_s used by wall friction and artificial viscosity (about 10x "
            "the expected speed). A step shorter than dx / c_s is held to the share dt c_s / dx "
            "of the pressure solves' bands and removes that share of a compression "
            "(docs/method.md §4.3)."),
        key("/fluid/solute_diffusivity", T::Number, "m^2/s", closed(0, 1), 1e-4,
            "Diffusivity D of the solute among fluid particles (M18; scene-scaled, docs/method.md "
            "§8.2). Explicit, in sub-steps of at most 0.15 dx^2 / D."),
        key("/fluid/solver", T::Enum, "", any(), "dfsph",
            "Pressure solver. dfsph: divergence-free SPH (Bender & Koschier 2017), a "
            "velocity-level solve "
            "that keeps dense fluid from compressing further, then the constant-density solve, "
            "both "
            "with the Akinci boundary of walls and porous particles; pcisph: the paper's "
            "predictive-corrective solver (docs/method.md §4.3), slower, and it settles shallow "
            "water at rest less well.",
            {"dfsph", "pcisph"}),
        key("/fluid/max_density_error", T::Number, "", closed(1e-5, 0.1), 0.01,
            "The pressure solve stops when the largest predicted compression is below this "
            "fraction of rho0 (times dt c_s / dx in a step shorter than dx / c_s)."),
        key("/fluid/max_divergence_error", T::Number, "", closed(1e-6, 0.1), 0.01,
            "DFSPH's divergence solve stops when no particle at or above rho0 would compress by "
            "more than this fraction of rho0 over the step (times dt c_s / dx in a step shorter "
            "than dx / c_s)."),
        key("/fluid/min_iterations", T::Integer, "", closed(1, 100), 3,
            "PCISPH minimum predictor-corrector iterations (DFSPH, warm-started, stops as soon as "
            "it "
            "meets the tolerance)."),
        key("/fluid/max_iterations", T::Integer, "", closed(1, 1000), 50,
            "Maximum iterations of each pressure solve."),

        key("/fluid_blocks", T::ObjectArray, "", any(), json::array(),
            "Blocks of fluid sampled on the scene lattice (i + 1/2) dx."),
        required("/fluid_blocks/[]/shape", T::Shape, "", any(), "Geometry of the block."),
        key("/fluid_blocks/[]/velocity", T::Vec3, "m/s", closed(-1000, 1000), zero3,
            "Initial velocity."),
        key("/fluid_blocks/[]/concentration", T::Number, "", closed(0, 1), 0.0,
            "Initial solute concentration C = m_sol / m (muddy water), docs/method.md §4.9."),

        key("/walls", T::ObjectArray, "", any(), json::array(),
            "Static walls sampled as Akinci 2012 boundary particles."),
        required("/walls/[]/shape", T::Shape, "", any(), "Geometry of the wall."),
        key("/walls/[]/kind", T::Enum, "", any(), "obstacle",
            "obstacle: particles fill a skin inside the shape; container: the shape is the cavity "
            "and particles fill a skin around it.",
            {"obstacle", "container"}),
        key("/walls/[]/layers", T::Integer, "", closed(1, 4), 2,
            "Thickness of the particle skin, in particle layers. One layer lets fast particles "
            "slip through between steps; two is the safe default."),

        key("/porous_solids", T::ObjectArray, "", any(), json::array(),
            "Porous solids (docs/method.md §2, §4.5-4.8): particles on the scene lattice. With "
            "fluid "
            "blocks, or when a "
            "solid is free, each solid is a rigid fragment coupled two-way with the fluid (Akinci "
            "boundary), "
            "absorbing, carrying and releasing water and dissolving into muddy fluid. Without "
            "fluid blocks and "
            "with every solid anchored, the scene is poroelastic-only: the solids are meshed into "
            "tetrahedra "
            "(PFEM) and the Biot solver runs by itself with /poroelastic/time_step."),
        required("/porous_solids/[]/shape", T::Shape, "", any(), "Geometry of the solid."),
        key("/porous_solids/[]/anchored", T::Bool, "", any(), true,
            "true: the solid stays put (a rock on the ground); false: a free rigid body "
            "(docs/method.md "
            "§4.5) "
            "moved by gravity, the fluid and contact with walls and other solids."),
        key("/porous_solids/[]/velocity", T::Vec3, "m/s", closed(-1e3, 1e3), zero3,
            "Initial velocity of a free solid."),
        key("/porous_solids/[]/angular_velocity", T::Vec3, "rad/s", closed(-1e4, 1e4), zero3,
            "Initial angular velocity of a free solid about its centre of mass."),
        key("/porous_solids/[]/material", T::Object, "", any(), json::object(),
            "Material of the solid."),
        key("/porous_solids/[]/material/porosity", T::Number, "", closed(0, 0.95), 0.3,
            "Porosity phi0. Below 1e-4 the solid is impermeable (M3): it takes no water, e.g. a "
            "floating box."),
        key("/porous_solids/[]/material/permeability", T::Number, "m^2", closed(1e-25, 1e-3), 2e-8,
            "Intrinsic permeability k0 (scene-scaled default, docs/method.md §8.2)."),
        key("/porous_solids/[]/material/darcy_viscosity", T::Number, "Pa s", closed(1e-6, 1e6), 0.1,
            "Dynamic viscosity eta of the pore water in Darcy's law."),
        key("/porous_solids/[]/material/solid_density", T::Number, "kg/m^3", closed(10, 30000),
            2650.0, "Density of the grains rho_s."),
        key("/porous_solids/[]/material/youngs_modulus", T::Number, "Pa", closed(1, 1e13), 1e6,
            "Drained Young's modulus E of the skeleton (scene-scaled default)."),
        key("/porous_solids/[]/material/poisson_ratio", T::Number, "", closed(0, 0.49), 0.25,
            "Drained Poisson ratio."),
        key("/porous_solids/[]/material/biot_coefficient", T::Number, "", closed(0.01, 1), 0.9,
            "Biot coefficient B = 1 - K_dr/K_s; it fixes the grain modulus K_s."),
        key("/porous_solids/[]/material/tensile_strength", T::Number, "Pa", positive(1e12), 1e5,
            "Tensile strength sigma_t of the Rankine test (M25): a node whose largest effective "
            "principal stress exceeds it cracks (with /fracture/enabled)."),
        optional("/porous_solids/[]/material/tensile_strength_wet", T::Number, "Pa", positive(1e12),
                 "The tensile strength of the saturated material: water weakens rock and soil, "
                 "so the strengths (tensile_strength, tensile_strength_across and "
                 "compressive_strength) fall linearly with the saturation S to this one at "
                 "S = 1 (docs/method.md M25). Absent: no weakening."),
        optional("/porous_solids/[]/material/compressive_strength", T::Number, "Pa", positive(1e12),
                 "Uniaxial compressive strength sigma_c of a Mohr-Coulomb shear test beside the "
                 "tensile one (docs/method.md M25): a node whose effective principal stresses "
                 "reach (s1 - s3) + (s1 + s3) sin phi = sigma_c (1 - sin phi) cracks along the "
                 "failure plane, at 45 + phi/2 degrees to the plane the largest compression acts "
                 "on; water weakens it as it does the tensile strength. It must exceed "
                 "tensile_strength. Absent: no shear cracks."),
        key("/porous_solids/[]/material/friction_angle", T::Number, "degree", closed(0, 60), 30.0,
            "Friction angle phi of the Mohr-Coulomb shear test (with compressive_strength)."),
        key("/porous_solids/[]/material/fracture_energy", T::Number, "J/m^2", positive(1e12), 10.0,
            "Critical energy-release rate G_c (M26): a crack's area is the node's strain energy "
            "over G_c (its radius clamped to 0.5-3 spacings)."),
        key("/porous_solids/[]/material/capillary_pressure", T::Number, "Pa", closed(0, 1e8),
            2000.0, "Capillary scale k^c of M4: the suction of dry material."),
        key("/porous_solids/[]/material/capillary_exponent", T::Number, "", closed(0.01, 1), 0.5,
            "Exponent alpha of M4, P^c = k^c (1 - S)^alpha."),
        key("/porous_solids/[]/material/pore_stiffness", T::Number, "Pa", closed(1, 1e10), 1.4e4,
            "Pore stiffness k^p of M5, P^p = k^p S max(0, S^gamma - 1)."),
        key("/porous_solids/[]/material/pore_exponent", T::Number, "", closed(1, 15), 7.0,
            "Tait exponent gamma of M5: how steeply over-full pores push water on."),
        key("/porous_solids/[]/material/saturation_exponent", T::Number, "", closed(0, 6), 2.0,
            "Exponent beta of the relative permeability k_r = S^beta."),
        key("/porous_solids/[]/material/initial_saturation", T::Number, "", closed(0, 1.2), 0.0,
            "Saturation S at t = 0 outside the wet regions."),
        key("/porous_solids/[]/material/dissolution_porosity", T::Number, "", closed(0, 1), 0.6,
            "phi_diss of docs/method.md §4.8. A porous particle dissolves into muddy fluid (its "
            "grains become the fluid's solute) when all hold: porosity >= dissolution_porosity, "
            "saturation >= dissolution_saturation, and open water touches it (fluid within h, none "
            "closer than 0.6 dx). With the default 0.6, a material of porosity below 0.6 never "
            "dissolves; scenes/dissolving_mound.json shows one that does."),
        key("/porous_solids/[]/material/dissolution_saturation", T::Number, "", closed(0.5, 2),
            0.98,
            "S_diss of docs/method.md §4.8: the saturation at which a porous-enough "
            "particle dissolves (see dissolution_porosity)."),
        key("/porous_solids/[]/material/absorption_factor", T::Number, "", closed(0, 1e3), 1.0,
            "chi_abs of M15: scales the permeability of fluid-porous pairs (how fast the surface "
            "absorbs)."),
        key("/porous_solids/[]/layering", T::Object, "", any(), json::object(),
            "Layering of the permeability (M12): ratio along / across bedding planes or a fibre "
            "axis."),
        key("/porous_solids/[]/layering/kind", T::Enum, "", any(), "bedding",
            "bedding: planes with the given normal; fibre: fibres along the given axis (normal is "
            "read as the "
            "fibre tangent, K0 = k_perp I + (k_par - k_perp) t t^T); from_geometry: bedding planes "
            "whose normal is, "
            "per particle, the direction of least spread of its neighbourhood (weighted PCA, M28).",
            {"bedding", "fibre", "from_geometry"}),
        key("/porous_solids/[]/layering/normal", T::Vec3, "", closed(-1, 1),
            json::array({0.0, 0.0, 1.0}),
            "Bedding-plane normal (or fibre tangent) in the solid's frame."),
        key("/porous_solids/[]/layering/ratio", T::Number, "", closed(0.01, 100), 1.0,
            "k along the layers (fibres) / k across them (1: isotropic); det K stays k0^3."),
        optional("/porous_solids/[]/layering/tensile_strength_across", T::Number, "Pa",
                 positive(1e12),
                 "bedding and from_geometry only: the tensile strength across the bedding planes. "
                 "Layered rock splits along its layers: a crack along the layer opens where the "
                 "effective normal stress across it exceeds this (docs/method.md M25). Absent: the "
                 "material's tensile_strength."),
        key("/porous_solids/[]/wet_regions", T::ObjectArray, "", any(), json::array(),
            "Regions of the solid that start wet."),
        required("/porous_solids/[]/wet_regions/[]/region", T::Shape, "", any(),
                 "Where the solid starts wet."),
        key("/porous_solids/[]/wet_regions/[]/saturation", T::Number, "", closed(0, 1.2), 1.0,
            "Saturation there."),
        key("/porous_solids/[]/constraints", T::ObjectArray, "", any(), json::array(),
            "Boundary conditions of the Biot problem on regions of the solid. A node belongs to a "
            "region when it lies inside it or within 3/4 of a spacing of it (the outer particles "
            "sit half a spacing inside the geometry). Unconstrained: free "
            "body (rigid modes held by a weak spring), no flux."),
        required("/porous_solids/[]/constraints/[]/kind", T::Enum, "", any(),
                 "fixed: displacement prescribed (0 unless given) on the given axes; drained: pore "
                 "pressure prescribed; "
                 "traction: a uniform traction on the surface facets inside the region; "
                 "platen: a rigid frictionless platen, the nodes in the region share one "
                 "displacement along `axes` (one axis) and carry the total `force` along it.",
                 {"fixed", "drained", "traction", "platen"}),
        required("/porous_solids/[]/constraints/[]/region", T::Shape, "", any(),
                 "Where the condition holds."),
        key("/porous_solids/[]/constraints/[]/axes", T::Enum, "", any(), "xyz",
            "fixed: the displacement components held (at 0 unless `displacement` says); platen: "
            "its one axis.",
            {"xyz", "x", "y", "z", "xy", "xz", "yz"}),
        key("/porous_solids/[]/constraints/[]/pressure", T::Number, "Pa", closed(-1e12, 1e12), 0.0,
            "drained only: the prescribed pore pressure."),
        key("/porous_solids/[]/constraints/[]/traction", T::Vec3, "Pa", closed(-1e12, 1e12), zero3,
            "traction only: force per area on the surface (e.g. [0, 0, -1e4] presses down)."),
        key("/porous_solids/[]/constraints/[]/force", T::Number, "N", closed(-1e15, 1e15), 0.0,
            "platen only: the total force on the platen along its axis (negative pushes toward "
            "-axis), shared by its nodes; with `table`, a load-controlled test."),
        key("/porous_solids/[]/constraints/[]/displacement", T::Vec3, "m", closed(-1e3, 1e3), zero3,
            "fixed only: the prescribed displacement of the held components (a platen that moves "
            "with `table`)."),
        optional(
            "/porous_solids/[]/constraints/[]/table", T::Table, "", closed(-1e6, 1e6),
            "A piecewise-linear time table [[t0, f0], [t1, f1], ...] (t in s, increasing from "
            "0 on) that multiplies the constraint's traction, pressure, displacement or force: "
            "constant before the first row and after the last. Absent: a factor of 1. A load "
            "that ramps to failure, a pressure raised in steps, a platen moved at a rate."),

        key("/pore_flow", T::Object, "", any(), json::object(),
            "Transport of pore water between porous particles (docs/method.md §4.7)."),
        key("/pore_flow/pair_flux", T::Enum, "", any(), "darcy",
            "darcy: the conservative Darcy pair flux M15, driven by pore pressure, capillarity and "
            "gravity; "
            "paper_eq20: the paper's Eq. 20 in its conservative form (docs/method.md §9 item 7), "
            "which "
            "diffuses the "
            "absorbed mass along the pore velocity and ignores gravity and capillarity as drivers, "
            "for comparison.",
            {"darcy", "paper_eq20"}),
        key("/poroelastic", T::Object, "", any(), json::object(),
            "PFEM mesh and Biot solver (docs/method.md §5)."),
        key("/poroelastic/time_step", T::Number, "s", positive(1e6), 1.0 / 30,
            "Biot step dt_B (one call per step; docs/method.md §8.2: one per frame)."),
        key("/poroelastic/coupled_fragments", T::Enum, "", any(), "anchored",
            "In a scene with fluid or free solids: anchored: every anchored fragment of a "
            "permeable solid is "
            "meshed and gets a Biot call every time_step, loaded by the fluid's forces, with its "
            "pore pressure "
            "from the pore water, feeding porosity, bulk volume and permeability back "
            "(docs/method.md "
            "§5); none: "
            "fragments stay rigid (faster; no stress, no mesh frames). Free fragments are not "
            "solved.",
            {"anchored", "none"}),
        key("/poroelastic/fluid_bulk_modulus", T::Number, "Pa", closed(1, 1e12), 1e5,
            "Pore-water bulk modulus K_f in the Biot storage 1/M = phi/K_f + (B - phi)/K_s. The "
            "default is the SPH pore stiffness gamma k^p (docs/method.md §8.2); water is 2.2e9."),
        key("/poroelastic/pressure_source", T::Enum, "", any(), "pore_water",
            "pore_water: the pore water moves by Darcy flow among the particles (M15) and seeds "
            "the "
            "Biot pressure at every call from M5 (docs/method.md §5.3); biot: the Biot pressure is "
            "carried from call to call (linear poroelasticity, e.g. Terzaghi's test).",
            {"pore_water", "biot"}),
        key("/poroelastic/splitting", T::Enum, "", any(), "fixed_stress",
            "fixed_stress (M22, L = B^2/K_dr) or fixed_strain (the paper's order, L = 0; diverges "
            "when tau = B^2 M/K_dr > 1).",
            {"fixed_stress", "fixed_strain"}),
        key("/poroelastic/shape_functions", T::Enum, "", any(), "p1",
            "p1: linear tets (docs/method.md §5.2 default); mfem_polyhedra: EDT polyhedra with "
            "Laplace "
            "shape functions (M21), slower to assemble but free of the tets' shear locking (a "
            "cantilever: 0.4 % off Timoshenko against 5 % with p1 at the same nodes).",
            {"p1", "mfem_polyhedra"}),
        key("/poroelastic/linear_solver", T::Enum, "", any(), "auto",
            "direct: CHOLMOD for both systems (a slow factorisation per mesh, then fast solves); "
            "amg: "
            "conjugate gradients with hypre's BoomerAMG for both (a fast set-up, slower solves), "
            "for "
            "meshes rebuilt at nearly every call or too big for a factor's memory; auto: CHOLMOD "
            "for "
            "the elasticity and, from 30,000 pressure unknowns, AMG for the flow, which is set up "
            "again whenever dt or the permeability changes.",
            {"auto", "direct", "amg"}),
        key("/poroelastic/max_iterations", T::Integer, "", closed(1, 1000), 5, "k_max of M22."),
        key("/poroelastic/acceleration", T::Enum, "", any(), "anderson",
            "anderson: the fixed-stress pressure iterates are mixed over the last three (Anderson "
            "acceleration: fewer iterations per call, most where the coupling is strong); none: "
            "the "
            "plain M22 iteration. The fixed-strain order is never accelerated.",
            {"anderson", "none"}),
        key("/poroelastic/tolerance", T::Number, "", closed(1e-14, 1), 1e-3,
            "Relative change of p and u that ends the iterations (M22)."),
        key("/poroelastic/permeability_feedback", T::Bool, "", any(), true,
            "Update porosity (M23) and permeability (M24) from the strain and pressure after every "
            "Biot call; false keeps k = k0, as linear poroelasticity benchmarks assume."),
        key("/poroelastic/alpha", T::Number, "", closed(0.6, 10), 1.25,
            "Alpha-shape factor (M19)."),
        key("/poroelastic/join_delta", T::Number, "", closed(0, 1), 0.1,
            "EDT joining factor delta (M20)."),
        key("/poroelastic/weighted_alpha", T::Bool, "", any(), false,
            "Use the weighted alpha shape (regular triangulation) instead of the plain one."),

        key("/fracture", T::Object, "", any(), json::object(),
            "Fracture of the meshed solids (docs/method.md §5.5-5.6): after every Biot call, "
            "Rankine "
            "cracks on the effective stress break element links, split nodes, and pieces no longer "
            "held by an anchor become free rigid fragments."),
        key("/fracture/enabled", T::Bool, "", any(), true,
            "false: the solids never crack (the stress is still written as crack_candidate)."),
        key("/fracture/max_cracks_per_call", T::Integer, "", closed(1, 1000), 8,
            "N_crack: most cracks per structure and Biot call, taken in decreasing "
            "sigma'_1 / sigma_t; none within h of another crack of the same call."),
        key("/fracture/criterion", T::Enum, "", any(), "rankine",
            "rankine: a node cracks when its largest effective principal stress exceeds the "
            "tensile strength (M25); separation_tensor: O'Brien & Hodgins' separation tensor of "
            "the elements' tensile and compressive nodal forces, scaled so that uniaxial tension "
            "cracks at the same strength (docs/method.md §5.5); extension_strain: Stacey's "
            "criterion, the largest principal strain over tensile_strength / E (the same in "
            "uniaxial tension; a solid in compression splits along the load once Poisson's "
            "ratio times the compression exceeds the strength).",
            {"rankine", "separation_tensor", "extension_strain"}),
        key("/fracture/merge", T::Bool, "", any(), true,
            "Fragments that touch while wet join again (docs/method.md §5.6): the mean saturation "
            "of their touching particles at least merge_saturation, every touching pair closing "
            "slower than merge_speed, and at least 3 tets of the weighted alpha shape of the "
            "contact spanning both. Two sides of one crack never rejoin."),
        key("/fracture/merge_saturation", T::Number, "", closed(0, 10), 0.9,
            "S_merge: the contact's mean saturation needed to merge."),
        key("/fracture/merge_speed", T::Number, "m/s", closed(0, 100), 0.05,
            "v_merge: the closing speed below which touching fragments may merge."),
        key("/output", T::Object, "", any(), json::object(), "What is written, and how often."),
        key("/output/fps", T::Number, "1/s", closed(0.1, 10000), 30.0,
            "Frames per simulated second."),
        key("/output/vtp", T::Bool, "", any(), true, "Write the fluid particles, fluid_NNNN.vtp."),
        key("/output/porous", T::Bool, "", any(), true,
            "Write the porous particles, porous_NNNN.vtp."),
        key("/output/mesh", T::Bool, "", any(), true,
            "Write the PFEM meshes with their Biot fields: mesh.case (EnSight Gold) and its "
            "files."),
        key("/output/walls", T::Bool, "", any(), true,
            "Write the wall particles once, boundary.vtp."),
        key("/output/cracks", T::Bool, "", any(), true,
            "Write the crack disks, cracks_NNNN.vtp (once a solid has cracked)."),
        key("/output/ply", T::Bool, "", any(), false,
            "Also write binary PLY point frames fluid_NNNN.ply (for Houdini and Blender; they "
            "cannot be compressed and would more than double the output)."),
        key("/output/compress", T::Bool, "", any(), true,
            "zlib-compress the VTK frames (ParaView and every VTK reader read both kinds)."),
        key("/output/fluid_surface", T::Bool, "", any(), true,
            "Write the fluid surface (docs/method.md §7), fluid_surface_NNNN.ply and .vtp: "
            "triangles with normal, velocity, concentration and the M29 colour."),
        key("/output/porous_surface", T::Bool, "", any(), true,
            "Write each fragment's alpha-shape surface, porous_surface_NNNN.ply and .vtp, with "
            "saturation, porosity and the M29 colour (wet is darker)."),
        key("/output/level_set", T::Bool, "", any(), false,
            "Also write the fluid's level set phi = 0.5 - c (negative inside), "
            "fluid_level_set_NNNN.vdb, for Houdini and Blender volume workflows."),
        key("/output/surface_voxel", T::Number, "", closed(0.1, 2), 0.5,
            "The fluid surface's grid spacing, as a fraction of particle_spacing."),
        key("/output/anisotropic_surface", T::Bool, "", any(), false,
            "Yu-Turk anisotropic kernels for the fluid surface: thin sheets and splashes stay "
            "sheets instead of beads, at about twice the meshing time."),

        key("/render", T::Object, "", any(), json::object(),
            "The pictures of karst render and karst run --render (docs/output_format.md)."),
        optional("/render/camera_position", T::Vec3, "m", closed(-1e6, 1e6),
                 "Where the camera stands; absent, it is framed on every frame's surfaces."),
        optional("/render/camera_target", T::Vec3, "m", closed(-1e6, 1e6),
                 "The point the camera looks at; absent, the centre of the surfaces' box."),
        key("/render/fov", T::Number, "deg", closed(1, 170), 40.0, "Horizontal field of view."),
        key("/render/width", T::Integer, "", closed(16, 7680), 1280,
            "Frame width in pixels (--width overrides it)."),
        key("/render/height", T::Integer, "", closed(16, 4320), 720,
            "Frame height in pixels (--height overrides it)."),
        key("/render/samples", T::Integer, "", closed(1, 9), 2,
            "Anti-aliasing depth of the full-quality render: up to samples^2 rays per pixel "
            "where edges need them (POV-Ray +R); --preview casts one."),

        key("/watchdog", T::Object, "", any(), json::object(), "Run-time sanity limits."),
        key("/watchdog/max_speed", T::Number, "m/s", positive(1e6), 100.0,
            "A particle faster than this stops the run (exit code 1)."),

        key("/numerics", T::Object, "", any(), json::object(), "Performance knobs."),
        key("/numerics/sort_interval", T::Integer, "", closed(1, 100000), 10,
            "Steps between reorderings of the particle arrays along a Morton curve."),

        required("shape/type", T::Enum, "", any(), "Kind of geometry.",
                 {"box", "sphere", "cylinder", "union", "difference"}),
        required("shape:box/min", T::Vec3, "m", any(), "Box lower corner."),
        required("shape:box/max", T::Vec3, "m", any(), "Box upper corner."),
        required("shape:sphere/center", T::Vec3, "m", any(), "Sphere centre."),
        required("shape:sphere/radius", T::Number, "m", positive(), "Sphere radius."),
        required("shape:cylinder/base", T::Vec3, "m", any(), "Centre of the base disk."),
        required("shape:cylinder/top", T::Vec3, "m", any(), "Centre of the top disk."),
        required("shape:cylinder/radius", T::Number, "m", positive(), "Cylinder radius."),
        required("shape:union/shapes", T::ShapeArray, "", any(), "Shapes joined together."),
        required("shape:difference/shapes", T::ShapeArray, "", any(),
                 "The first shape minus all the others."),
    };
}

std::string format_number(double v) {
    if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
    return fmt::format("{:g}", v);
}

}  // namespace

bool Range::contains(double v) const {
    if (std::isnan(v)) return false;
    if (lo_open ? !(v > lo) : !(v >= lo)) return false;
    if (hi_open ? !(v < hi) : !(v <= hi)) return false;
    return true;
}

std::string Range::describe() const {
    if (std::isinf(lo) && std::isinf(hi)) return "";
    return fmt::format("{}{}, {}{}", lo_open ? "(" : "[", format_number(lo), format_number(hi),
                       hi_open ? ")" : "]");
}

const std::vector<KeySpec>& scene_schema() {
    static const std::vector<KeySpec> schema = make_schema();
    return schema;
}

std::string describe_type(const KeySpec& spec) {
    switch (spec.type) {
        case ValueType::String:
            return "string";
        case ValueType::Number:
            return "number";
        case ValueType::Integer:
            return "integer";
        case ValueType::Bool:
            return "boolean";
        case ValueType::Vec3:
            return "array of 3 numbers";
        case ValueType::Enum: {
            std::string s = "one of";
            for (size_t i = 0; i < spec.options.size(); ++i)
                s += fmt::format("{} \"{}\"", i ? "," : "", spec.options[i]);
            return s;
        }
        case ValueType::Object:
            return "object";
        case ValueType::ObjectArray:
            return "array of objects";
        case ValueType::Shape:
            return "shape object";
        case ValueType::ShapeArray:
            return "non-empty array of shape objects";
        case ValueType::Table:
            return "non-empty array of [time, value] rows";
    }
    return "?";
}

std::string scene_schema_markdown() {
    std::string md =
        "# Scene format\n\n"
        "<!-- Generated by `karst schema` from src/karst/scene/schema.cpp; do not edit. -->\n\n"
        "A scene is one JSON object. Units are SI. Unknown keys, wrong types and out-of-range "
        "values\n"
        "are refused before simulating, with the JSON path, what was expected and what was found\n"
        "(exit code 2); so is a key given twice in one object and a number too small for a double\n"
        "(1e-400). `[]` stands for any array index. Geometry objects (`shape`) are described "
        "by\n"
        "the `shape` rows: `shape/type` picks the kind and `shape:<type>/...` lists its keys;\n"
        "`union` and `difference` nest further shapes. All particles lie on one lattice\n"
        "`(i + 1/2) dx`, so fluid and walls fit together without gaps.\n\n"
        "| key | type | unit | range | default | description |\n"
        "|---|---|---|---|---|---|\n";
    for (const KeySpec& s : scene_schema()) {
        std::string def = s.value ? s.value->dump() : (s.required ? "required" : "optional");
        md += fmt::format("| `{}` | {} | {} | {} | {} | {} |\n", s.pointer, describe_type(s),
                          s.unit, s.range.describe(), def, s.doc);
    }
    return md;
}

}  // namespace karst
