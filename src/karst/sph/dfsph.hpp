#pragma once
#include "karst/sim/model.hpp"
#include "karst/sim/state.hpp"

namespace karst {

struct PressureSolveReport {
    int iterations = 0;             ///< density-solve iterations (PCISPH: predictor-corrector)
    int divergence_iterations = 0;  ///< DFSPH divergence-solve iterations; 0 for PCISPH
    /// The density solve's last residual over solve_rate_fraction (sph/integrate.hpp), a
    /// fraction of rho0: the predicted compression beyond the target, or the over-pressure a
    /// particle could give back where the fluid expands. At most /fluid/max_density_error once
    /// converged.
    Real max_density_error = 0;
};

/// Stage (docs/method.md §4.3, replaced): divergence-free SPH after Bender & Koschier 2017, with
/// the Akinci boundary of walls and porous particles. Two solves on the velocities, each a relaxed
/// Jacobi iteration on the pressures p_i >= 0 of the linearised density
///   rho*_i = rho_i + dt sum_j m_j (v*_i - v*_j).grad W_ij + 2 dt sum_k Psi_k (v*_i - v*_k).grad
///   W_ik
/// (the boundary twice, as the pressure force has it; dfsph.cpp says why), where the porous
/// members of free fragments move with the reaction of the pressures (v*_k; interlinked
/// coupling, coupling/fragment_response.hpp) and gravity:
/// 1. divergence: v* = v + dt a^p(p_div), until no particle at or above rho0 is compressed
///    further (rho*_i <= max(rho_i, rho0) within /fluid/max_divergence_error);
/// 2. constant density: v* = v + dt (a_div + a_other + a^p(p)), until rho*_i <= rho0 (1 + eta).
/// A step shorter than dx / c_s reads both bands as rates (sph/integrate.hpp, solve_rate_fraction).
/// The stopping test reads the complementarity residual (compression, or over-pressure that
/// p_i could give back). The divergence solve starts from zero, the density solve from half the
/// last step's pressure where the fluid would compress (dfsph.cpp says why). Writes state.fluid.p
/// and p_divergence (Pa) and scratch.a_pressure = a_div + a^p(p) (m/s^2); reads the step's pair
/// factors (update_density_and_pair_coefficients).
PressureSolveReport solve_pressure_dfsph(const Model& model, State& state, Real dt);

}  // namespace karst
