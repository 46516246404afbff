#pragma once
// Merging of wet fragments (docs/method.md §5.6, the paper's Fig. 7): two fragments whose
// touching particles are saturated and which press together slowly join into one, their weighted
// alpha shape across the contact holding at least N_m tets. A free fragment that merges into an
// anchored one becomes part of its structure (remeshed at the next Biot call); free fragments
// merge into one rigid body with their summed mass and linear momentum.
#include "karst/sim/model.hpp"
#include "karst/sim/state.hpp"

namespace karst {

/// N_m: tets of the union's alpha shape that must span the contact.
inline constexpr Index k_merge_spanning_tets = 3;

/// Returns true when fragments merged (the pore-flow pairs are then stale).
bool merge_fragments(const Model& model, State& state);

}  // namespace karst
