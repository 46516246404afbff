#pragma once
// Solute diffusion among fluid particles (docs/method.md §4.9, M18): the Cleary-Monaghan conduction
// operator applied as pairwise transfers of solute mass, so solute is conserved exactly.
#include "karst/sim/model.hpp"
#include "karst/sim/state.hpp"

namespace karst {

/// Diffuses solute over dt (sub-stepped at 0.1 h^2 / D), reading the densities and fluid
/// neighbour lists of this step. Does nothing when D = 0 or no particle carries solute.
void diffuse_solute(const Model& model, State& state, Real dt);

}  // namespace karst
