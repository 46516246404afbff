#pragma once
// A poroelastic-only run (issue 4): porous solids and no fluid. The Biot solver runs by itself
// with its own time step (/poroelastic/time_step), writing mesh_NNNN.vtu frames.
#include "karst/sim/model.hpp"
#include "karst/sim/run.hpp"

namespace karst {

struct PfemTimings;

RunResult run_poroelastic(const Model& model, const RunOptions& options);

/// stats.json's "biot" object: calls, iterations, remeshes, mean iterations, all converged.
nlohmann::json biot_stats(const PfemTimings& timings);

}  // namespace karst
