#include "karst/sim/run_poroelastic.hpp"

#include "karst/core/parallel.hpp"
#include "karst/core/timer.hpp"
#include "karst/io/frame_writer.hpp"
#include "karst/pfem/poroelastic_solid.hpp"
#include "karst/scene/scene_error.hpp"
#include "karst/sim/progress.hpp"

#include <fmt/format.h>

#include <cmath>

namespace karst {

nlohmann::json biot_stats(const PfemTimings& t) {
    return {{"calls", t.biot_calls}, {"iterations", t.biot_iterations}, {"remeshes", t.remeshes},
            {"mean_iterations", t.biot_calls ? double(t.biot_iterations) / t.biot_calls : 0.0}, {"all_converged", t.all_converged}};
}

RunResult run_poroelastic(const Model& model, const RunOptions& options) {
    const Scene& scene = model.scene;
    Stopwatch wall;
    RunResult result;
    result.out_dir = options.out_dir ? *options.out_dir : std::filesystem::path("out") / scene.name;

    PfemTimings timings;
    std::vector<PoroelasticSolid> solids;
    solids.reserve(model.porous.size());
    for (const PorousBody& body : model.porous) solids.emplace_back(model, body, timings);
    Index nodes = 0, elements = 0;
    MeshQuality quality;
    for (const PoroelasticSolid& s : solids) {
        nodes += s.mesh().node_count(), elements += s.mesh().tet_count();
        quality.kept += s.mesh().quality.kept, quality.slivers_dropped += s.mesh().quality.slivers_dropped;
        quality.interior_slivers += s.mesh().quality.interior_slivers, quality.polyhedra += s.mesh().quality.polyhedra;
    }

    FrameWriter out(result.out_dir, scene.output);
    out.write_boundary(model.walls);
    auto write_frame = [&](Real time, Real dt, Index steps) {
        MeshFrame frame;
        PointSet particles;
        for (size_t s = 0; s < solids.size(); ++s) {
            solids[s].append_to(frame);
            solids[s].append_particles_to(particles);
        }
        out.write_frame({nullptr, &frame, &particles}, {time, dt, steps, nodes, 0, 0});
    };
    auto absorbed = [&] {
        Real sum = 0;
        for (const PoroelasticSolid& s : solids) sum += s.absorbed_water();
        return sum;
    };
    const Real absorbed_initial = absorbed();
    write_frame(0, 0, 0);

    const Real end = scene.time.end, frame_dt = 1 / scene.output.fps;
    const Real dt_max = scene.poroelastic.time_step;
    Real time = 0;
    Index steps = 0;
    int next_frame = 1;
    ProgressLine progress(options.quiet);
    Stopwatch stepping;
    double node_steps = 0;
    while (time < end - 1e-12 * std::max(Real(1), end)) {
        // Steps of at most dt_B that land on the frame times.
        const Real frame_time = std::min(end, next_frame * frame_dt);
        const Real n = std::max(Real(1), std::ceil((frame_time - time) / dt_max - 1e-9));
        const Real dt = (frame_time - time) / n;
        for (PoroelasticSolid& s : solids) s.advance(dt, timings);
        time += dt, ++steps, node_steps += double(nodes);
        if (time >= frame_time - 1e-9 * dt) {
            write_frame(time, dt, steps);
            ++next_frame;
        }
        const double elapsed = std::max(stepping.seconds(), 1e-9);
        progress.update({out.frames() - 1, time, end, steps / elapsed, nodes * steps / elapsed / 1e6,
                         (end - time) / std::max(time / elapsed, 1e-12), nodes});
    }
    progress.finish();

    result.stats = {
        {"scene", scene.name},
        {"counts", {{"fluid", 0}, {"boundary", model.walls.size()}, {"porous", nodes}, {"elements", elements},
                    {"fragments", solids.size()}, {"removed", 0}}},
        {"steps", steps},
        {"frames", out.frames()},
        {"sim_time", time},
        {"wall_time", wall.seconds()},
        {"phases", {{"meshing", timings.meshing}, {"assembly", timings.assembly},
                    {"factorisation", timings.factorisation}, {"iterations", timings.iterations},
                    {"pore_flow", timings.pore_flow}}},
        {"biot", biot_stats(timings)},
        {"mesh", {{"kept", quality.kept}, {"polyhedra", quality.polyhedra}, {"slivers_dropped", quality.slivers_dropped},
                  {"interior_slivers", quality.interior_slivers}}},
        {"mass", {{"water_initial", absorbed_initial}, {"water_final", absorbed()}, {"absorbed_initial", absorbed_initial},
                  {"absorbed_final", absorbed()}, {"solute_initial", 0.0}, {"solute_final", 0.0}}},
        {"max_density_error", 0.0},
        {"mipps", node_steps / std::max(stepping.seconds(), 1e-9) / 1e6},  // node-steps of the Biot solver
        {"threads", ThreadLimit::active_threads()},
        {"version", KARST_VERSION},
    };
    out.write_stats(result.stats);
    return result;
}

}  // namespace karst
