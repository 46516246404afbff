#pragma once
#include "karst/sim/model.hpp"
#include "karst/sim/state.hpp"

#include <algorithm>

namespace karst {

/// Stage (docs/method.md §4.4): symplectic Euler v += dt (a_other + a_p), x += dt v; a particle
/// that crossed a wall's surface is put back inside it (counted in state.pushed_back); then removes
/// the particles that left the domain (counted in state.removed) and those drained into porous
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

/// [D] The pressure solve's own bound on the step: a solve that left over 1 % compression
/// (sim/step.cpp) even when halved bounds the next step by half of it; a step that had to be
/// halved to converge bounds the next ones by its length; each step that converged at once lets
/// the bound grow by 10 %. `dt` is the step taken, `shortened` whether it was cut to converge.
/// Why: the Jacobi-type solves relax the pressure over the neighbourhoods, so what a step's
/// motion compresses (about g dt^2 per layer, summed down a column) is what they must undo in
/// their iterations; an unconverged solve leaves that compression, and the next impact throws it
/// back out.
/// `dt_rate` = sound_crossing_time: an unconverged solve does not bound the step below it, where
/// the bands shrink with the step (solve_rate_fraction) and a shorter step no longer helps the
/// solve.
void update_solver_time_step_limit(State& state, Real dt, bool shortened, bool converged,
                                   Real dt_max, Real dt_rate);

/// [D] The viscous terms are explicit, so a step is stable only below k_viscous_step dx^2 /
/// nu_eff, nu_eff = nu + artificial_kinematic_viscosity. Measured at a fixed 1 ms step (dx 0.01
/// and 0.02): stable up to 0.11 dx^2 / nu; at 0.125 the energy of a collapsing block rose 1.3 to
/// 4 times within 0.5 s, at 0.1375 35 times (Morris et al. 1997 give 0.125 l^2 / nu for a
/// smoothing length l = dx). 0.05 keeps a factor of two (bench/results/notes.md). Wall friction
/// is left out: it only brakes approach to a resting wall, and held at sigma_f = 8 with a 1 ms
/// step. Infinite without viscosity.
inline constexpr Real k_viscous_step = 0.05;
Real viscous_step_limit(const FluidSettings& fluid, Real dx);

/// The artificial viscosity's share of nu_eff, alpha_v h c_s / 20, m^2/s (h the support radius).
/// Its pair term equals the viscosity's for nu = alpha_v h c_s / (2 (d + 2))
/// (sph/non_pressure_forces.cpp), but it acts on approaching pairs only, and in a collapsing
/// block it was stable to about twice that nu (alpha_v c_s = 20 m/s held at 1 ms and dx 0.02,
/// 32 m/s diverged).
Real artificial_kinematic_viscosity(const FluidSettings& fluid, Real dx);

/// s = min(1, dt c_s / dx): the share of the sound's crossing time of a spacing that a step of dt
/// is (c_s = /fluid/sound_speed). The pressure solves read their bands as rates through it
/// (docs/method.md §4.3): a step at s < 1 is held to s times each band, and its density solve
/// removes the share s of a compression. At dt >= dx / c_s nothing changes; 1 for dt <= 0.
/// [D] Read per step, the bands let a short step compress and release more per second than a
/// long one: the density solve removed a whole compression e in one step, at about e dx / dt, and
/// water stepped far below dx / c_s (viscous fluids, fixed short steps) gained energy
/// (bench/results/notes.md). A weakly compressible fluid releases a compression at e c_s.
Real solve_rate_fraction(const FluidSettings& fluid, Real dx, Real dt);

/// dx / c_s, s: below it the pressure solves' bands shrink with the step.
Real sound_crossing_time(const FluidSettings& fluid, Real dx);

/// The density solve's target at the share s of solve_rate_fraction: rho0, or the share s of the
/// way there from a compressed rho_i.
inline Real rate_density_target(Real rho_i, Real rho0, Real s) {
    return std::max(rho0, rho_i - s * (rho_i - rho0));
}

/// M11: dt = min(lambda_v dx / v_max, 0.25 sqrt(dx / a_max), dt_max), or the scene's fixed step
/// (the run stops when it falls below dt_min). v_max is the largest fluid or porous speed now;
/// a_max that of the last step; also at most the pressure solve's bound
/// (update_solver_time_step_limit), 0.5 dx sqrt(rho0 / p_max) and viscous_step_limit.
/// [D] The p_max bound: the pressure force's geometric stiffness, about p / (rho0 dx^2) per unit
/// mass, is integrated explicitly (a particle that moves changes the force the pressure gives
/// it), and deep water at the M11 step rang up (a 1 m column at dx 0.01 stopped on the watchdog
/// at t = 1.2 s; with the bound it comes to rest, bench/results/notes.md).
Real cfl_time_step(const Model& model, const State& state);

}  // namespace karst
