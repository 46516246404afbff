#pragma once
#include "karst/sim/model.hpp"
#include "karst/sim/state.hpp"

namespace karst {

/// Stage: every `sort_interval` steps reorder the fluid arrays along the Morton curve, then
/// rebuild the fluid-fluid and fluid-wall neighbour lists (docs/method.md §3 step 1).
void update_fluid_neighbours(const Model& model, State& state);

}  // namespace karst
