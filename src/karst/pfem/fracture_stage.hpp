#pragma once
// Algorithm 2 l.8-21 on State (docs/method.md §5.5-5.6): after a Biot call, every structure is
// tested for Rankine cracks (M25-M26); the links they cut break, nodes whose elements fall apart
// split into new porous particles (M27), and the pieces no longer held by an anchor become free
// rigid fragments. Mass, pore water and the linear and angular momentum are kept exactly.
#include "karst/sim/model.hpp"
#include "karst/sim/state.hpp"

#include <span>
#include <vector>

namespace karst {

/// Cracks made at `time` are recorded with it and their call's fracture `round` (CrackRecord).
/// Returns true when some structure changed (new particles or fragments): the pore-flow pairs
/// are then stale.
bool fracture_structures(const Model& model, State& state, Real time, int round = 0);

/// Per node of structure `s`, the factor on its material's strengths from its saturation (the
/// wet strength at S = 1); empty when the material has no wet strength. `index_of` maps a
/// particle id to its index (index_by_id).
std::vector<Real> strength_scale(const Model& model, const State& state, const Structure& s,
                                 std::span<const Index> index_of);

/// Whether some fragment moves (free, with mass): a poroelastic-only run then needs the CFL step.
bool any_free_fragment(const State& state);

}  // namespace karst
