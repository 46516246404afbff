// Poroelastic-only scenes (issue 4): porous solids with regions for boundary conditions, run by
// the Biot solver alone, through the same step() as every run. Terzaghi through the shipped
// scene, scene errors, and the output folder.
#include "support/files.hpp"
#include "support/simulate.hpp"

#include "karst/pfem/nodal_stress.hpp"
#include "karst/pfem/porosity.hpp"
#include "karst/pfem/structure_stages.hpp"
#include "karst/scene/scene_error.hpp"

#include <gtest/gtest.h>

#include <cstdlib>
#include <fmt/format.h>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <nlohmann/json.hpp>
#include <sstream>

namespace karst {
namespace {

using test::read_text;

const std::string k_scene = std::string(KARST_SOURCE_DIR) + "/scenes/terzaghi_consolidation.json";

/// Terzaghi's series (MOOSE terzaghi.i parameters: c_v = 13.95, p0 = 0.6977) for a column of
/// height h: pressure at height z over the base.
Real terzaghi_pressure(Real z, Real t, Real h) {
    constexpr Real pi = std::numbers::pi, c_v = 1.5 / (0.0625 + 0.36 * 0.125),
                   p0 = 0.6 * 0.125 / (0.0625 + 0.36 * 0.125);
    Real p = 0;
    for (int k = 0; k < 200; ++k) {
        const Real n = 2 * k + 1;
        p += (k % 2 ? -1 : 1) / n * std::cos(n * pi * z / (2 * h)) *
             std::exp(-n * n * pi * pi * c_v * t / (4 * h * h));
    }
    return 4 * p0 / pi * p;
}

TEST(PoroelasticScene, ShippedTerzaghiSceneConsolidatesLikeTheSeries) {
    test::Simulation sim(read_text(k_scene));
    ASSERT_EQ(sim.state.structures.structures.size(), 1u);
    // The particles sit half a spacing inside the 10 m box: the mesh column is 9.75 m high.
    const Real base = 0.125, h = 9.75, t_end = 1.4;
    sim.run_until(t_end - 1e-9);
    const Structure& s = sim.state.structures.structures[0];
    Real err2 = 0, ref2 = 0;
    for (Index a = 0; a < s.mesh.node_count(); ++a) {
        const Real exact = terzaghi_pressure(s.mesh.nodes[a][2] - base, t_end, h);
        err2 += std::pow(s.fields.p[a] - exact, 2), ref2 += exact * exact;
    }
    EXPECT_LT(std::sqrt(err2 / ref2), 0.03) << "L2 error of the pore pressure over the column";
    EXPECT_EQ(sim.state.structures.timings.biot_calls,
              std::lround(t_end / sim.model.scene.poroelastic.time_step));
}

/// Mandel's problem (Cheng & Detournay 1988; MOOSE's mandel.i with nu 0.1, Biot coefficient 0.9
/// and K_f 5 instead of 0.2, 0.6 and 8, for a clearer Mandel-Cryer effect with Skempton's B under
/// 1): a plane-strain slab of half-width a pressed by rigid frictionless impermeable platens, F
/// the force per unit length on its half (2F on the whole), its sides drained.
/// The pore pressure at distance x from the mid-plane, with p0 = F B (1 + nu_u) / (3 a):
///   p = 2 p0 sum_n s_n (cos(a_n x / a) - cos a_n) e_n,
///   s_n = sin a_n / (a_n - sin a_n cos a_n), e_n = exp(-a_n^2 c t / a^2),
///   tan a_n = (1 - nu) / (nu_u - nu) a_n,
///   c = 2 kappa B^2 G (1 - nu) (1 + nu_u)^2 / (9 (1 - nu_u) (nu_u - nu)),
/// and the platen's settlement per unit height
///   u_z / z = -F (1 - nu) / (2 G a) + F (1 - nu_u) / (G a) sum_n s_n cos a_n e_n,
/// from undrained (1 - nu_u) to drained (1 - nu).
struct MandelSolution {
    Real a, p0, c, drained_strain, relief;  ///< relief: F (1 - nu_u) / (G a)
    std::vector<Real> roots;
    MandelSolution(Real E, Real nu, Real porosity, Real biot, Real K_f, Real mobility, Real a_,
                   Real stress)
        : a(a_) {
        const Real K = E / (3 * (1 - 2 * nu)), G = E / (2 * (1 + nu)), K_s = K / (1 - biot);
        const Real M = 1 / (porosity / K_f + (biot - porosity) / K_s), K_u = K + biot * biot * M;
        const Real B = biot * M / K_u, nu_u = (3 * K_u - 2 * G) / (2 * (3 * K_u + G));
        const Real F = stress * a;
        p0 = F * B * (1 + nu_u) / (3 * a);
        drained_strain = -F * (1 - nu) / (2 * G * a), relief = F * (1 - nu_u) / (G * a);
        c = 2 * mobility * B * B * G * (1 - nu) * (1 + nu_u) * (1 + nu_u) /
            (9 * (1 - nu_u) * (nu_u - nu));
        // Root n lies in ((n - 1) pi, (n - 1) pi + pi / 2): bisection on sin - k a cos.
        const Real k = (1 - nu) / (nu_u - nu), pi = std::numbers::pi;
        for (int n = 1; n <= 200; ++n) {
            Real lo = (n - 1) * pi + 1e-12, hi = (n - 1) * pi + pi / 2;
            auto f = [&](Real r) { return std::sin(r) - k * r * std::cos(r); };
            const bool lo_positive = f(lo) > 0;
            for (int it = 0; it < 100; ++it) {
                const Real mid = 0.5 * (lo + hi);
                ((f(mid) > 0) == lo_positive ? lo : hi) = mid;
            }
            roots.push_back(0.5 * (lo + hi));
        }
    }
    Real pressure(Real x, Real t) const {
        Real sum = 0;
        for (const Real r : roots)
            sum += std::sin(r) / (r - std::sin(r) * std::cos(r)) *
                   (std::cos(r * x / a) - std::cos(r)) * std::exp(-r * r * c * t / (a * a));
        return 2 * p0 * sum;
    }
    Real vertical_strain(Real t) const {
        Real sum = 0;
        for (const Real r : roots)
            sum += std::sin(r) * std::cos(r) / (r - std::sin(r) * std::cos(r)) *
                   std::exp(-r * r * c * t / (a * a));
        return drained_strain + relief * sum;
    }
};

TEST(PoroelasticScene, MandelsProblemShowsTheMandelCryerRiseAndDecaysLikeTheSeries) {
    // The quarter slab: x from the mid-plane (held in x, no flow) to the drained side at x = 1 m,
    // z from the base (held in z) to the rigid platen; plane strain by holding both y faces.
    // The nodes sit dx / 2 inside the box, so the slab's half-width is 0.95 m and the platen's
    // area 0.95 x 0.05 m^2; its force gives a mean stress of 1 Pa.
    const Real a = 0.95, x0 = 0.025, stress = 1, force = stress * a * 0.05;
    test::Simulation sim(fmt::format(R"({{
      "name": "mandel", "particle_spacing": 0.05, "gravity": [0, 0, 0],
      "poroelastic": {{ "time_step": 0.0025, "fluid_bulk_modulus": 5, "permeability_feedback": false,
                        "pressure_source": "biot" }},
      "porous_solids": [ {{ "shape": {{ "type": "box", "min": [0, 0, 0], "max": [1, 0.1, 0.2] }},
        "material": {{ "porosity": 0.1, "permeability": 1.5e-4, "darcy_viscosity": 1e-4, "youngs_modulus": 1.8,
                       "poisson_ratio": 0.1, "biot_coefficient": 0.9, "solid_density": 2000 }},
        "constraints": [
          {{ "kind": "fixed", "axes": "x", "region": {{ "type": "box", "min": [-1, -1, -1], "max": [0, 2, 2] }} }},
          {{ "kind": "fixed", "axes": "y", "region": {{ "type": "box", "min": [-1, -1, -1], "max": [2, 0, 2] }} }},
          {{ "kind": "fixed", "axes": "y", "region": {{ "type": "box", "min": [-1, 0.1, -1], "max": [2, 2, 2] }} }},
          {{ "kind": "fixed", "axes": "z", "region": {{ "type": "box", "min": [-1, -1, -1], "max": [2, 2, 0] }} }},
          {{ "kind": "drained", "pressure": 0, "region": {{ "type": "box", "min": [1, -1, -1], "max": [2, 2, 2] }} }},
          {{ "kind": "platen", "axes": "z", "force": {}, "region": {{ "type": "box", "min": [-1, -1, 0.2], "max": [2, 2, 2] }} }} ] }} ]
    }})",
                                     -force));
    const MandelSolution exact(1.8, 0.1, 0.1, 0.9, 5, 1.5e-4 / 1e-4, a, stress);
    const Structure& s = sim.state.structures.structures.at(0);
    auto mid_plane_pressure = [&] {
        Real sum = 0;
        int n = 0;
        for (Index i = 0; i < s.mesh.node_count(); ++i)
            if (s.mesh.nodes[i].x() < x0 + 1e-9) sum += s.fields.p[i], ++n;
        return sum / n;
    };
    // The mid-plane pressure first rises over the undrained p0 as the drained sides soften and
    // hand their load to the core (the Mandel-Cryer effect, 1.107 p0 at c t / a^2 = 0.06 here),
    // which an uncoupled diffusion of p cannot give; then it decays.
    Real highest = 0;
    for (const Real t : {0.0025, 0.005, 0.01, 0.02, 0.03, 0.05, 0.1, 0.2}) {
        sim.run_until(t - 1e-9, [&] { highest = std::max(highest, mid_plane_pressure()); });
        const Real now = sim.state.time;
        Real err2 = 0, ref2 = 0, settlement = 0;
        for (Index i = 0; i < s.mesh.node_count(); ++i) {
            const Real e = exact.pressure(s.mesh.nodes[i].x() - x0, now);
            err2 += std::pow(s.fields.p[i] - e, 2), ref2 += e * e;
            if (s.mesh.nodes[i].z() > 0.17) settlement = s.fields.u[i].z();
        }
        EXPECT_LT(std::sqrt(err2 / ref2), t < 0.01 ? 0.05 : 0.02) << "L2 error at t = " << now;
        EXPECT_NEAR(mid_plane_pressure(), exact.pressure(0, now), 0.015 * exact.p0)
            << "t = " << now;
        // Between the base and platen node layers, 0.15 m apart.
        EXPECT_NEAR(settlement, 0.15 * exact.vertical_strain(now),
                    0.01 * 0.15 * std::abs(exact.drained_strain))
            << "t = " << now;
    }
    EXPECT_GT(highest, 1.08 * exact.p0);
    EXPECT_LT(highest, 1.13 * exact.p0);
}

TEST(PoroelasticScene, CompactionLowersPermeabilityByKozenyCarman) {
    // A drained, laterally confined block pressed from the top by 0.1 MPa: uniform strain
    // eps_zz = -q / (lambda + 2 mu), so M23 and M24 give one permeability for every tet.
    test::Simulation sim(R"({
      "name": "compaction", "particle_spacing": 0.25, "gravity": [0, 0, 0], "poroelastic": { "time_step": 1.0 },
      "porous_solids": [ { "shape": { "type": "box", "min": [0, 0, 0], "max": [1, 1, 1] },
        "material": { "porosity": 0.3, "permeability": 1e-10, "youngs_modulus": 1e6, "poisson_ratio": 0.25, "biot_coefficient": 0.9 },
        "constraints": [
          { "kind": "fixed", "axes": "x", "region": { "type": "box", "min": [-1, -1, -1], "max": [0, 2, 2] } },
          { "kind": "fixed", "axes": "x", "region": { "type": "box", "min": [1, -1, -1], "max": [2, 2, 2] } },
          { "kind": "fixed", "axes": "y", "region": { "type": "box", "min": [-1, -1, -1], "max": [2, 0, 2] } },
          { "kind": "fixed", "axes": "y", "region": { "type": "box", "min": [-1, 1, -1], "max": [2, 2, 2] } },
          { "kind": "fixed", "axes": "z", "region": { "type": "box", "min": [-1, -1, -1], "max": [2, 2, 0] } },
          { "kind": "drained", "region": { "type": "box", "min": [-1, -1, -1], "max": [2, 2, 2] } },
          { "kind": "traction", "traction": [0, 0, -1e5], "region": { "type": "box", "min": [-1, -1, 1], "max": [2, 2, 2] } } ] } ]
    })");
    sim.advance();
    ASSERT_EQ(sim.state.structures.timings.biot_calls, 1);
    const Structure& s = sim.state.structures.structures[0];
    const BiotProblem& problem = sim.state.biot_cache.find(0, s.mesh_version)->solver->problem();
    const BiotMaterial& m = problem.material;
    const Real eps_v = -1e5 / (m.lame_lambda() + 2 * m.shear_modulus());
    const Real k = kozeny_carman_permeability(1e-10, 0.3, dynamic_porosity(0.3, eps_v, 0, 1e30));
    ASSERT_LT(k, 0.9e-10) << "a 10 % compaction must close pores";
    for (const Mat3& mobility : problem.mobility)
        ASSERT_NEAR(mobility(0, 0) * 0.1 / k, 1, 1e-6);  // eta = 0.1
}

TEST(PoroelasticScene, SoakSceneSpreadsAlongTheLayersAndKeepsItsWater) {
    // scenes/soak_layered_block.json: a wet ball in a block layered 4 : 1 (normal z).
    test::Simulation sim(
        read_text(std::string(KARST_SOURCE_DIR) + "/scenes/soak_layered_block.json"));
    auto moments = [&] {
        const PorousParticles& p = sim.state.porous.particles;
        Real total = 0;
        Vec3 mean = Vec3::Zero(), second = Vec3::Zero();
        for (Index i = 0; i < p.size(); ++i)
            total += p.absorbed_mass[i], mean += p.absorbed_mass[i] * p.x[i];
        mean /= total;
        for (Index i = 0; i < p.size(); ++i)
            second += p.absorbed_mass[i] * (p.x[i] - mean).cwiseAbs2();
        return std::pair{total, Vec3(second / total)};
    };
    const auto [water0, var0] = moments();
    for (int step = 0; step < 30; ++step) sim.advance();
    EXPECT_EQ(sim.state.structures.timings.biot_calls, 30);
    const auto [water1, var1] = moments();
    EXPECT_NEAR(water1, water0, 1e-12 * water0) << "pore water is conserved";
    const Real along = 0.5 * (var1[0] - var0[0] + var1[1] - var0[1]), across = var1[2] - var0[2];
    EXPECT_GT(along, 0);
    EXPECT_NEAR(along / across, 4, 1)
        << "the wet region spreads faster along the layers (k ratio 4; measured 4.16)";
}

TEST(PoroelasticScene, BadPorousScenesAreRefusedWithTheirPath) {
    const std::string valid = read_text(k_scene);
    const auto refuse = test::refuse_scene;
    auto edit = [&](const std::string& from, const std::string& to) {
        std::string s = valid;
        const auto at = s.find(from);
        EXPECT_NE(at, std::string::npos) << from;
        return s.replace(at, from.size(), to);
    };
    EXPECT_EQ(refuse(edit("\"poisson_ratio\"", "\"poison_ratio\"")).path,
              "/porous_solids/0/material/poison_ratio");
    EXPECT_EQ(refuse(edit("\"kind\": \"drained\"", "\"kind\": \"drainde\"")).path,
              "/porous_solids/0/constraints/5/kind");
    EXPECT_EQ(refuse(edit("\"biot_coefficient\": 0.6", "\"biot_coefficient\": 0.05")).path,
              "/porous_solids/0/material/biot_coefficient");
    EXPECT_EQ(refuse(edit("\"axes\": \"x\"", "\"axes\": \"w\"")).path,
              "/porous_solids/0/constraints/0/axes");
    // A platen moves along one axis; the default "xyz" is three.
    EXPECT_EQ(refuse(edit("\"kind\": \"drained\"", "\"kind\": \"platen\"")).path,
              "/porous_solids/0/constraints/5/axes");
    EXPECT_EQ(refuse(edit("\"youngs_modulus\": 7.2", "\"youngs_modulus\": -7.2")).path,
              "/porous_solids/0/material/youngs_modulus");
    // Time tables: rows of two numbers, times from 0 on and increasing.
    const std::string tabled = "\"kind\": \"drained\", \"table\": ";
    const auto table_error = [&](const std::string& rows) {
        return refuse(edit("\"kind\": \"drained\"", tabled + rows));
    };
    EXPECT_EQ(table_error("[]").path, "/porous_solids/0/constraints/5/table");
    EXPECT_EQ(table_error("[[0, 1], [2]]").path, "/porous_solids/0/constraints/5/table/1");
    EXPECT_EQ(table_error("[[-1, 1]]").path, "/porous_solids/0/constraints/5/table/0/0");
    const SceneError backwards = table_error("[[0, 1], [2, 3], [1, 0]]");
    EXPECT_EQ(backwards.path, "/porous_solids/0/constraints/5/table/2/0");
    EXPECT_NE(backwards.expected.find("after the previous row's 2 s"), std::string::npos);
    EXPECT_EQ(table_error("[[0, \"a\"]]").path, "/porous_solids/0/constraints/5/table/0/1");
    // Fluid inside a porous solid.
    const SceneError overlap =
        refuse(edit("\"porous_solids\": [",
                    "\"fluid_blocks\": [ { \"shape\": { \"type\": \"box\", \"min\": [0, 0, 0], "
                    "\"max\": [1, 1, 1] } } ], \"porous_solids\": ["));
    EXPECT_EQ(overlap.path, "/porous_solids/0/shape");
    EXPECT_NE(overlap.found.find("/fluid_blocks/0"), std::string::npos);
}

TEST(PoroelasticScene, CliWritesMeshFramesListedInMeshCaseAndStats) {
    const std::filesystem::path out =
        std::filesystem::temp_directory_path() / "karst_test_poroelastic";
    std::filesystem::remove_all(out);
    const std::string command = std::string(KARST_BINARY) + " run " + k_scene +
                                " --end-time 0.2 --fps 10 --quiet --out " + out.string();
    ASSERT_EQ(std::system(command.c_str()), 0) << command;
    // The mesh's geometry is written once (it never changes here), its arrays every frame.
    EXPECT_TRUE(std::filesystem::exists(out / "mesh_0000.geo"));
    EXPECT_FALSE(std::filesystem::exists(out / "mesh_0001.geo"));
    EXPECT_FALSE(std::filesystem::exists(out / "mesh_pore_pressure_0003.ens"));
    const std::string mesh_case = read_text(out / "mesh.case");
    EXPECT_NE(mesh_case.find("number of steps: 3\nfilename numbers:\n0 0 0\n"), std::string::npos)
        << mesh_case;
    for (const char* array :
         {"displacement", "pore_pressure", "porosity", "permeability", "effective_stress",
          "principal_stress", "crack_candidate", "support_force"}) {
        EXPECT_NE(mesh_case.find(fmt::format(" {} mesh_{}_****.ens", array, array)),
                  std::string::npos)
            << array;
        EXPECT_TRUE(std::filesystem::exists(out / fmt::format("mesh_{}_0000.ens", array)));
    }
    EXPECT_TRUE(std::filesystem::exists(out / "mesh_pore_pressure_0002.ens"));
    const std::string pvd = read_text(out / "run.pvd");
    EXPECT_NE(pvd.find("part=\"3\" file=\"porous_0002.vtp\""), std::string::npos);
    const std::string vtp = read_text(out / "porous_0002.vtp");
    for (const char* array : {"saturation", "porosity", "absorbed_mass", "pore_pressure",
                              "pore_velocity", "fragment", "permeability", "velocity", "id"})
        EXPECT_NE(vtp.find(fmt::format("Name=\"{}\"", array)), std::string::npos) << array;
    const auto stats = nlohmann::json::parse(read_text(out / "stats.json"));
    EXPECT_EQ(stats["counts"]["porous"], 640);
    EXPECT_GT(stats["counts"]["elements"].get<int>(), 1000);
    EXPECT_EQ(stats["counts"]["fragments"], 1);
    for (const char* phase : {"meshing", "assembly", "factorisation", "iterations"})
        EXPECT_TRUE(stats["phases"].contains(phase)) << phase;
    EXPECT_GT(stats["biot"]["iterations"].get<int>(), 0);
    std::filesystem::remove_all(out);
}

TEST(PoroelasticScene, APlatenMovedByATimeTableStrainsTheBarUniformly) {
    // A bar on rollers at both ends (x held there), its x = 1.2 end moved by a ramp of 2 mm per
    // second: uniaxial stress E delta / L everywhere, L the distance between the end layers (to
    // 1e-5: the rigid-mode spring of the unheld y, z and twist modes, 1e-8 diag K, pulls a little).
    test::Simulation sim(R"({
      "name": "platen_ramp", "particle_spacing": 0.1, "gravity": [0, 0, 0], "poroelastic": { "time_step": 0.25 },
      "porous_solids": [ { "shape": { "type": "box", "min": [0, 0, 0], "max": [1.2, 0.3, 0.3] },
        "material": { "porosity": 0.3, "permeability": 1e-10, "youngs_modulus": 1e6, "poisson_ratio": 0.25,
                      "tensile_strength": 1e9 },
        "constraints": [
          { "kind": "drained", "region": { "type": "box", "min": [-1, -1, -1], "max": [2, 2, 2] } },
          { "kind": "fixed", "axes": "x", "region": { "type": "box", "min": [-1, -1, -1], "max": [0, 2, 2] } },
          { "kind": "fixed", "axes": "x", "displacement": [0.002, 0, 0], "table": [[0, 0], [10, 10]],
            "region": { "type": "box", "min": [1.2, -1, -1], "max": [2, 2, 2] } } ] } ]
    })");
    for (int call = 1; call <= 4; ++call) {
        sim.advance();
        const Real t = sim.state.time, delta = 0.002 * t, L = 1.1;
        const Structure& s = sim.state.structures.structures.at(0);
        const BiotProblem& problem =
            sim.state.biot_cache.find(0, s.mesh_version)->solver->problem();
        const NodalStress stress = nodal_stress(s.mesh, problem.material, s.fields);
        for (Index a = 0; a < s.mesh.node_count(); ++a) {
            ASSERT_NEAR(stress.effective[a](0, 0), 1e6 * delta / L, 1e-5 * 1e6 * delta / L)
                << "node " << a << " at t = " << t;
            ASSERT_NEAR(stress.effective[a](1, 1), 0, 1e-5 * 1e6 * delta / L);
        }
        // The force that moves the platen, E A delta / L with A = 0.2 x 0.2 m between the outer
        // node layers, and the opposite one at the held end; nothing across the bar.
        Vec3 moving = Vec3::Zero(), held = Vec3::Zero();
        ASSERT_EQ(s.support_force.size(), size_t(s.mesh.node_count()));
        for (Index a = 0; a < s.mesh.node_count(); ++a)
            (s.mesh.nodes[a].x() > 0.6 ? moving : held) += s.support_force[a];
        const Real F = 1e6 * 0.04 * delta / L;
        EXPECT_NEAR(moving.x(), F, 1e-5 * F) << "t = " << t;
        EXPECT_NEAR(held.x(), -F, 1e-5 * F) << "t = " << t;
        EXPECT_NEAR(moving.y(), 0, 1e-9 * F);
        EXPECT_NEAR(moving.z(), 0, 1e-9 * F);
        // supports.csv's rows: the held end (constraint 1) and the platen (2), 9 nodes each,
        // with the force-displacement pair a lab test plots.
        const std::vector<SupportLog> rows = structure_supports(sim.model, sim.state, t);
        ASSERT_EQ(rows.size(), 2u);
        EXPECT_EQ(rows[0].constraint, 1);
        EXPECT_EQ(rows[1].constraint, 2);
        for (const SupportLog& row : rows) {
            EXPECT_EQ(row.kind, "fixed");
            EXPECT_EQ(row.nodes, 9);
        }
        EXPECT_NEAR(rows[0].force.x(), -F, 1e-5 * F);
        EXPECT_NEAR(rows[1].force.x(), F, 1e-5 * F);
        EXPECT_NEAR(rows[0].displacement.x(), 0, 1e-12);
        EXPECT_NEAR(rows[1].displacement.x(), delta, 1e-9 * delta);
    }
}

TEST(PoroelasticScene, TheSupportsCarryTheWeightOfAnUndrainedBlock) {
    // A block held at its base (all axes), drained only at its top, under its own weight: the
    // supports' forces balance the weight rho g V whatever the pore pressure carries inside
    // (K u - Q p has no net force), and only the base nodes carry them. (A base too narrow for
    // its height counts as a hinge, whose rigid-mode spring would take a share of the weight.)
    // Both element kinds: P1 tets and the M21 polyhedra (whose K_cc comes from the full K).
    for (const char* elements : {"p1", "mfem_polyhedra"}) {
        test::Simulation sim(fmt::format(R"({{
      "name": "weight", "particle_spacing": 0.1, "gravity": [0, 0, -9.81],
      "poroelastic": {{ "time_step": 0.05, "shape_functions": "{}" }},
      "porous_solids": [ {{ "shape": {{ "type": "box", "min": [0, 0, 0], "max": [0.6, 0.6, 0.5] }},
        "material": {{ "porosity": 0.3, "permeability": 1e-12, "youngs_modulus": 1e6, "poisson_ratio": 0.3,
                      "solid_density": 2600, "tensile_strength": 1e9 }},
        "constraints": [
          {{ "kind": "drained", "region": {{ "type": "box", "min": [-1, -1, 0.5], "max": [2, 2, 2] }} }},
          {{ "kind": "fixed", "axes": "xyz", "region": {{ "type": "box", "min": [-1, -1, -1], "max": [2, 2, 0] }} }} ] }} ]
    }})",
                                         elements));
        sim.advance();
        const Structure& s = sim.state.structures.structures.at(0);
        const BiotProblem& problem =
            sim.state.biot_cache.find(0, s.mesh_version)->solver->problem();
        Real volume = 0, largest_p = 0;
        for (Index e = 0; e < s.mesh.tet_count(); ++e) volume += s.mesh.tet_volume(e);
        for (Real p : s.fields.p) largest_p = std::max(largest_p, p);
        ASSERT_GT(largest_p, 100) << "the pore pressure should carry part of the weight";
        const Real weight = problem.material.bulk_density * 9.81 * volume;
        Vec3 total = Vec3::Zero();
        for (Index a = 0; a < s.mesh.node_count(); ++a) {
            total += s.support_force[a];
            if (s.mesh.nodes[a].z() > 0.1) {
                ASSERT_EQ(s.support_force[a], Vec3::Zero()) << a << " " << elements;
            }
        }
        EXPECT_NEAR(total.z(), weight, 1e-9 * weight) << elements;
        EXPECT_NEAR(total.x(), 0, 1e-9 * weight);
        EXPECT_NEAR(total.y(), 0, 1e-9 * weight);
    }
}

/// A 0.4 x 0.4 m block of E = 1 MPa, nu = 0.25, drained throughout (so each call is its
/// drained state), spacing 0.1, with `constraints` (JSON) and a load `top` on its top layer.
std::string loaded_block(Real height, const std::string& constraints, const std::string& top) {
    return fmt::format(R"({{
      "name": "platen", "particle_spacing": 0.1, "gravity": [0, 0, 0], "poroelastic": {{ "time_step": 1 }},
      "porous_solids": [ {{ "shape": {{ "type": "box", "min": [0, 0, 0], "max": [0.4, 0.4, {}] }},
        "material": {{ "porosity": 0.3, "permeability": 1e-10, "youngs_modulus": 1e6, "poisson_ratio": 0.25,
                      "tensile_strength": 1e9 }},
        "constraints": [
          {{ "kind": "drained", "region": {{ "type": "box", "min": [-1, -1, -1], "max": [2, 2, 2] }} }},
          {}, {{ "region": {{ "type": "box", "min": [-1, -1, {}], "max": [2, 2, 2] }}, {} }} ] }} ]
    }})",
                       height, constraints, height, top);
}

/// The top layer's nodes (z above `height` - dx) and their vertical displacements.
std::vector<Real> top_settlement(const test::Simulation& sim, Real height) {
    const Structure& s = sim.state.structures.structures.at(0);
    std::vector<Real> uz;
    for (Index a = 0; a < s.mesh.node_count(); ++a)
        if (s.mesh.nodes[a].z() > height - 0.1) uz.push_back(s.fields.u[a].z());
    return uz;
}

TEST(PoroelasticScene, ARigidPlatenUnderATotalForceSettlesAConfinedColumnLikeItsTraction) {
    // A 1 m column on rollers (each side held normal to itself, the base vertically) pressed by
    // F = 900 N: the oedometric strain F / (A M), A = 0.3 x 0.3 m between the outer node layers,
    // M = E (1 - nu) / ((1 + nu)(1 - 2 nu)) = 1.2 MPa, over the 0.9 m between the end layers.
    const std::string rollers = R"(
      { "kind": "fixed", "axes": "x", "region": { "type": "box", "min": [-1, -1, -1], "max": [0, 2, 2] } },
      { "kind": "fixed", "axes": "x", "region": { "type": "box", "min": [0.4, -1, -1], "max": [2, 2, 2] } },
      { "kind": "fixed", "axes": "y", "region": { "type": "box", "min": [-1, -1, -1], "max": [2, 0, 2] } },
      { "kind": "fixed", "axes": "y", "region": { "type": "box", "min": [-1, 0.4, -1], "max": [2, 2, 2] } },
      { "kind": "fixed", "axes": "z", "region": { "type": "box", "min": [-1, -1, -1], "max": [2, 2, 0] } })";
    const Real F = 900, A = 0.09, M = 1.2e6, expected = -F / (A * M) * 0.9;
    test::Simulation platen(
        loaded_block(1.0, rollers, R"("kind": "platen", "axes": "z", "force": -900)"));
    test::Simulation traction(
        loaded_block(1.0, rollers, R"("kind": "traction", "traction": [0, 0, -10000])"));
    platen.advance(), traction.advance();
    const std::vector<Real> by_platen = top_settlement(platen, 1.0);
    const std::vector<Real> by_traction = top_settlement(traction, 1.0);
    ASSERT_EQ(by_platen.size(), 16u);
    for (size_t k = 0; k < by_platen.size(); ++k) {
        EXPECT_NEAR(by_platen[k], expected, 1e-3 * std::abs(expected)) << "platen node " << k;
        EXPECT_NEAR(by_platen[k], by_traction[k], 0.01 * std::abs(expected)) << "node " << k;
        EXPECT_NEAR(by_platen[k], by_platen[0], 1e-12 * std::abs(expected)) << "node " << k;
    }
    // supports.csv: the platen (constraint 6) at its force and common settlement; the base
    // roller (5) carries the 900 N back and the side rollers nothing along z.
    const std::vector<SupportLog> rows = structure_supports(platen.model, platen.state, 1.0);
    ASSERT_EQ(rows.size(), 6u);
    const SupportLog& top = rows[5];
    EXPECT_EQ(top.constraint, 6);
    EXPECT_EQ(top.kind, "platen");
    EXPECT_EQ(top.nodes, 16);
    EXPECT_EQ(top.force, Vec3(0, 0, -F));
    EXPECT_NEAR(top.displacement.z(), by_platen[0], 1e-12 * std::abs(expected));
    EXPECT_NEAR(rows[4].force.z(), F, 1e-6 * F);
    for (int k = 0; k < 4; ++k) {
        EXPECT_NEAR(rows[k].force.z(), 0, 1e-9 * F) << "roller " << k + 1;
    }
}

TEST(PoroelasticScene, ARigidPlatenMovesItsNodesAsOneWhereATractionWouldTiltThem) {
    // A block held only under half of its base: the same total load as a traction tilts the top
    // (2.4 mm over the held half, 4.4 mm over the free one), while the platen's nodes share one
    // settlement (3.2 mm) to round-off.
    const std::string half_base = R"(
      { "kind": "fixed", "region": { "type": "box", "min": [-1, -1, -1], "max": [0.2, 2, 0] } })";
    test::Simulation platen(
        loaded_block(0.4, half_base, R"("kind": "platen", "axes": "z", "force": -900)"));
    test::Simulation traction(
        loaded_block(0.4, half_base, R"("kind": "traction", "traction": [0, 0, -10000])"));
    platen.advance(), traction.advance();
    auto spread = [](const std::vector<Real>& u) {  // (max - min, largest |u|), m
        const auto [lo, hi] = std::minmax_element(u.begin(), u.end());
        return std::pair{*hi - *lo, std::max(std::abs(*lo), std::abs(*hi))};
    };
    const auto [platen_spread, platen_largest] = spread(top_settlement(platen, 0.4));
    const auto [traction_spread, traction_largest] = spread(top_settlement(traction, 0.4));
    ASSERT_GT(platen_largest, 0);
    EXPECT_LT(platen_spread, 1e-12 * platen_largest) << "m";
    EXPECT_GT(traction_spread, 0.2 * traction_largest) << "m";
}

}  // namespace
}  // namespace karst
