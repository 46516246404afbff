#pragma once
// Solute diffusion among fluid particles (docs/method.md §4.9, M18): the Cleary-Monaghan conduction
// operator applied as pairwise transfers of solute mass, so solute is conserved exactly.
#include "karst/sim/model.hpp"
#include "karst/sim/state.hpp"

namespace karst {

/// [D] The explicit sub-step of the diffusion, times dx^2 / D. Measured with a fixed step: stable
/// at 0.35, concentrations of 1e7 at 0.375; the sub-step of 0.1 h^2 / D = 0.4 dx^2 / D it
/// replaces let D >= 0.2 m^2/s at dx 0.02 diverge to infinities (bench/results/notes.md).
inline constexpr Real k_diffusion_substep = 0.15;

/// Most sub-steps of one step: more would stall the run (D = 1 m^2/s at dx 0.005 takes 1,334 in a
/// 5 ms step).
inline constexpr Real k_max_diffusion_substeps = 1e4;

/// Diffuses solute over dt (sub-stepped at k_diffusion_substep dx^2 / D), reading the densities
/// and fluid neighbour lists of this step. Does nothing when D = 0 or no particle carries solute.
/// Returns 0, or the sub-steps it would need when over k_max_diffusion_substeps (then nothing
/// was diffused).
Real diffuse_solute(const Model& model, State& state, Real dt);

}  // namespace karst
