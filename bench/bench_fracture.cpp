// Fracture benchmark (issue 13) near the paper's Mountain size: a 4 m block of 64,084 particles at
// 0.1 m, held at its base, with a pressurised wet pocket that cracks at the first Biot call.
// Prints the seconds of that call's fracture stage (crack tests, link breaking, node splitting,
// the topology and the new fragments) and of the Biot calls that follow each cracking round
// (their mesh changed: their elasticity is solved through the uncracked factor where it can
// be, SpdSolve::compute_split), what fracture did, and the next call (a fresh factorisation).
// Appends CSV to bench/results/2core/bench_fracture_70k.csv.
//
//   karst_bench_fracture [--threads N] [--edge L]
#include "provenance.hpp"

#include "karst/core/parallel.hpp"
#include "karst/core/timer.hpp"
#include "karst/sim/model.hpp"
#include "karst/sim/state.hpp"
#include "karst/sim/step.hpp"

#include <fmt/format.h>

#include <cstring>
#include <filesystem>
#include <fstream>

using namespace karst;

int main(int argc, char** argv) {
    int threads = 0;
    Real edge = 4.0;
    for (int a = 1; a + 1 < argc; a += 2) {
        if (!std::strcmp(argv[a], "--threads")) threads = std::atoi(argv[a + 1]);
        if (!std::strcmp(argv[a], "--edge")) edge = std::atof(argv[a + 1]);
    }
    ThreadLimit limit(threads);
    const Real c = edge / 2;
    const std::string scene = fmt::format(R"({{
      "name": "bench_fracture", "particle_spacing": 0.1,
      "porous_solids": [ {{
        "shape": {{ "type": "box", "min": [0, 0, 0], "max": [{0}, {0}, {0}] }},
        "material": {{ "porosity": 0.3, "permeability": 1e-11, "darcy_viscosity": 0.1,
                      "youngs_modulus": 1e7, "initial_saturation": 1.0, "tensile_strength": 1.5e4,
                      "fracture_energy": 1.0 }},
        "wet_regions": [ {{ "region": {{ "type": "sphere", "center": [{1}, {1}, {1}], "radius": 0.35 }},
                           "saturation": 1.2 }} ],
        "constraints": [ {{ "kind": "fixed", "region": {{ "type": "box", "min": [-1, -1, -1], "max": [{2}, {2}, 0] }} }} ] }} ],
      "poroelastic": {{ "time_step": 0.02 }}
    }})",
                                          edge, c, edge + 1);
    Stopwatch setup;
    const Model model = build_model(parse_scene(scene));
    State state = make_initial_state(model);
    const Real t_setup = setup.seconds();
    StepProfile profile;
    const PfemTimings before = state.structures.timings;
    Stopwatch call;
    while (state.structures.timings.biot_calls == before.biot_calls)
        step(model, state, next_step_length(model, state, 1.0), profile);
    const Real t_call = call.seconds();
    const PfemTimings& t = state.structures.timings;
    const FractureCounts& f = state.structures.fracture;
    const Real fracture = profile[Stage::Fracture];
    const Real structure = profile[Stage::Structure];
    const Index repeated = t.repeated_calls;
    fmt::print("karst_bench_fracture: {} particles, {} threads\n", state.porous.size(),
               ThreadLimit::active_threads());
    fmt::print("  set-up (mesh, first factorisation)  {:.3f} s\n", t_setup);
    fmt::print("  first Biot call with fracture       {:.3f} s\n", t_call);
    fmt::print(
        "    fracture stage                    {:.3f} s ({} cracks, {} links broken, "
        "{} nodes split, {} fragments)\n",
        fracture, f.cracks, f.links_broken, f.nodes_split, f.fragments_created);
    fmt::print("    Biot calls and feedback           {:.3f} s ({} calls, {} after a crack)\n",
               structure, t.biot_calls, repeated);
    fmt::print("      of which assembly {:.3f} s, factorisation {:.3f} s, iterations {:.3f} s\n",
               t.assembly - before.assembly, t.factorisation - before.factorisation,
               t.iterations - before.iterations);

    const auto file = std::filesystem::path(KARST_SOURCE_DIR) / "bench" / "results" / "2core" /
                      "bench_fracture_70k.csv";
    std::ofstream csv = bench::open_results(
        file,
        "threads,particles,cracks,links_broken,nodes_split,fragments,s_setup,s_call,s_fracture,"
        "s_biot,biot_calls,repeated_calls,s_assembly,s_factorisation,s_iterations");
    csv << bench::provenance_fields(KARST_SOURCE_DIR);
    csv << fmt::format("{},{},{},{},{},{},{:.4f},{:.4f},{:.4f},{:.4f},{},{},{:.4f},{:.4f},{:.4f}\n",
                       ThreadLimit::active_threads(), state.porous.size(), f.cracks, f.links_broken,
                       f.nodes_split, f.fragments_created, t_setup, t_call, fracture, structure,
                       t.biot_calls, repeated, t.assembly - before.assembly,
                       t.factorisation - before.factorisation, t.iterations - before.iterations);
    // The call after: the cracking call's split solvers are gone (release_split_solvers), so it
    // factorises the cracked mesh afresh (and may crack further).
    const PfemTimings at_end = t;
    Stopwatch next_call;
    while (state.structures.timings.biot_calls == at_end.biot_calls)
        step(model, state, next_step_length(model, state, 1.0), profile);
    fmt::print(
        "  next Biot call                      {:.3f} s (factorisation {:.3f} s, {} after a "
        "crack)\n",
        next_call.seconds(), t.factorisation - at_end.factorisation,
        t.repeated_calls - at_end.repeated_calls);

    fmt::print("  appended to {}\n", file.string());
}
