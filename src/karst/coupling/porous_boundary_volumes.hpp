#pragma once
// Akinci volumes of porous particles (method.md §4.1): recomputed every step, because fragments
// move relative to each other and to the walls.
#include "karst/sim/model.hpp"
#include "karst/sim/state.hpp"

namespace karst {

/// Stage: Psi_k = gamma rho0 V_b,k with V_b,k = 1 / sum_l W_kl over the porous and wall
/// particles l within h, k included; gamma is the thick-wall calibration of sim/model.cpp.
void update_porous_boundary_volumes(const Model& model, State& state);

}  // namespace karst
