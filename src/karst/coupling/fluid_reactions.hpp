#pragma once
// The fluid's reactions on porous particles (docs/method.md §4.3 end, §4.2): the last PCISPH
// boundary pressure, friction and adhesion, each pair evaluated by the same function as on the
// fluid side, so that the fragments receive exactly what the fluid lost.
#include "karst/sim/model.hpp"
#include "karst/sim/state.hpp"

namespace karst {

/// Stage (after the pressure solve): state.porous_scratch.force = the fluid's force on each
/// porous particle, N. These are also the nodal loads a later Biot step would take (§5.3).
void compute_fluid_reactions(const Model& model, State& state);

}  // namespace karst
