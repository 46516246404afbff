#pragma once
#include "karst/sim/model.hpp"
#include "karst/sim/state.hpp"

namespace karst {

/// Stage (method.md §4.4): symplectic Euler v += dt (a_other + a_p), x += dt v; then removes the
/// particles that left the domain (counted in state.removed) and those drained into porous
/// solids (mass 0). Returns the largest non-pressure acceleration (m/s^2), for the next step's
/// M11 bound.
///
/// [D] M11 bounds dt by the whole acceleration. The PCISPH pressure acceleration is not an
/// explicit force, though: it is whatever undoes the density error within the step, about
/// error dx / dt^2, so bounding dt by it shrinks dt, which raises the next correction, which
/// shrinks dt again. After a burst of dissolution in a soaking block dt fell from 1 ms to 40 us
/// in four steps and a particle reached 112 m/s. The bound now covers the explicit forces
/// (gravity, viscosity, surface tension, adhesion, friction); the pressure is held by the
/// velocity CFL.
Real integrate_fluid(const Model& model, State& state, Real dt);

/// M11: dt = min(lambda_v dx / v_max, 0.25 sqrt(dx / a_max)) clamped to [dt_min, dt_max], or the
/// scene's fixed step. v_max is the largest fluid or porous speed now; a_max that of the last step.
Real cfl_time_step(const Model& model, const State& state);

}  // namespace karst
