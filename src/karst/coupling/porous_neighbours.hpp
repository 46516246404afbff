#pragma once
// Neighbour search for porous particles (docs/method.md §3 step 1), all within h: fluid-porous
// pairs for the Akinci boundary, porous-porous and porous-wall pairs for the Akinci volumes and
// contacts, porous-fluid pairs for the reactions and absorption.
//
// [D] Absorption pairs stop at h, not at the porous kernel's longest reach (M13, 2 h for a
// layering ratio of 4): the sheet's reach gave a surface particle about 100 fluid partners, and
// the soak benchmark spent 115 ms per step in the pore flow against 10 ms in the density pass.
// Transport inside the rock keeps the full anisotropic kernel.
#include "karst/sim/model.hpp"
#include "karst/sim/state.hpp"

namespace karst {

/// Stage (after the fluid's neighbour search, which it relies on): fills
/// state.scratch.fluid_porous and the lists of state.porous_scratch.
void update_porous_neighbours(const Model& model, State& state);

}  // namespace karst
