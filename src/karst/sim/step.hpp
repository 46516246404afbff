#pragma once
#include "karst/sim/model.hpp"
#include "karst/sim/state.hpp"
#include "karst/sim/step_profile.hpp"

namespace karst {

struct StepReport {
    Real dt = 0;                 ///< s
    int pressure_iterations = 0;
    int divergence_iterations = 0;  ///< DFSPH only
    Real max_density_error = 0;  ///< fraction of rho0
};

class FragmentStructures;

/// Advances the state by one step of length dt (method.md §3), or a half, quarter ... of it when
/// the pressure solve does not converge (StepReport::dt says which). `structures`, when given, runs
/// the Biot step of the anchored fragments (§5). Throws WatchdogError if a stage produces a NaN
/// or a runaway speed.
StepReport step(const Model& model, State& state, Real dt, StepProfile& profile, FragmentStructures* structures = nullptr);

}  // namespace karst
