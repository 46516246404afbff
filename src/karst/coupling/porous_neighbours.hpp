#pragma once
// Neighbour search for porous particles (method.md §3 step 1): fluid-porous pairs within h for
// the Akinci boundary, porous-porous and porous-wall pairs within h for the Akinci volumes and
// contacts, and porous-fluid pairs within the longest kernel reach (M13) for absorption.
#include "karst/sim/model.hpp"
#include "karst/sim/state.hpp"

namespace karst {

/// Stage (after the fluid's neighbour search, which it relies on): fills
/// state.scratch.fluid_porous and the lists of state.porous_scratch.
void update_porous_neighbours(const Model& model, State& state);

}  // namespace karst
