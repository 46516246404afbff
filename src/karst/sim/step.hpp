#pragma once
#include "karst/sim/model.hpp"
#include "karst/sim/state.hpp"
#include "karst/sim/step_profile.hpp"

namespace karst {

struct StepReport {
    Real dt = 0;  ///< s
    int pressure_iterations = 0;
    int divergence_iterations = 0;  ///< DFSPH only
    Real max_density_error = 0;     ///< fraction of rho0
};

/// Advances the state by one step of length dt (docs/method.md §3, and §5 for the anchored
/// fragments' Biot problems), or a half, quarter ... of it when the pressure solve does not
/// converge (StepReport::dt says which). Throws WatchdogError if a stage produces a NaN or a
/// runaway speed.
StepReport step(const Model& model, State& state, Real dt, StepProfile& profile);

/// The next step's length as a run takes it: the CFL step (M11) where fluid or free fragments
/// move, dt_B in a poroelastic-only scene (nothing moves between its Biot calls, and the pore
/// flow sub-steps by itself, §4.7.5), shortened so that a whole number of steps lands on
/// `target` (a frame time) and on the next Biot call. A fixed step stays fixed in a coupled scene.
Real next_step_length(const Model& model, const State& state, Real target);

}  // namespace karst
