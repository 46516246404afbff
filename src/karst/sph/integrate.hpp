#pragma once
#include "karst/sim/model.hpp"
#include "karst/sim/state.hpp"

namespace karst {

/// Stage (method.md §4.4): symplectic Euler v += dt (a_other + a_p), x += dt v; then removes the
/// particles that left the domain (counted in state.removed) and those drained into porous
/// solids (mass 0). Returns the largest
/// acceleration (m/s^2), for the next step's M11 bound.
Real integrate_fluid(const Model& model, State& state, Real dt);

/// M11: dt = min(lambda_v dx / v_max, 0.25 sqrt(dx / a_max)) clamped to [dt_min, dt_max], or the
/// scene's fixed step. v_max is the largest fluid or porous speed now; a_max that of the last step.
Real cfl_time_step(const Model& model, const State& state);

}  // namespace karst
