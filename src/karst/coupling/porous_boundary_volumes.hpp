#pragma once
// Akinci volumes of porous particles (docs/method.md §4.1): recomputed every step, because
// fragments move relative to each other and to the walls.
#include "karst/sim/model.hpp"
#include "karst/sim/state.hpp"

namespace karst {

/// Stage: Psi_k = rho0 min(V_lattice, V_b,k) with the Akinci volume V_b,k = 1 / sum_l W_kl over
/// the porous and wall particles l within h, k included: a solid is a lattice block, so each
/// particle stands for one lattice cell, less where particles crowd (two fragments or a
/// fragment and a wall pressed together). sim/model.cpp says why the lattice volume.
void update_porous_boundary_volumes(const Model& model, State& state);

}  // namespace karst
