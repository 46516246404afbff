#pragma once
// The stages of Algorithm 2 (docs/method.md §5) on State::structures, in the order sim/step.cpp
// calls them: loads -> the particles follow u -> remesh triggers (§4.10) -> Biot (M22) ->
// feedback (§5.4). Every anchored fragment of a permeable solid has a structure: in a coupled
// run its loads are the fluid's reactions and the contact forces on its particles; a
// poroelastic-only solid is such a fragment with no fluid around it.
#include "karst/io/frame_writer.hpp"
#include "karst/sim/model.hpp"
#include "karst/sim/state.hpp"

namespace karst {

/// The solver of structure `slot`, built (and its mobility brought to the last feedback) when
/// the cache has none for the current mesh.
BiotSolver& solver_of(const Model& model, State& state, size_t slot);

/// The structure's fields with u measured from the unloaded mesh: u plus the displacement of
/// the rest state under the solid's weight (StructureState::weight_u). Its stress is the one
/// the solid carries.
BiotFields fields_with_weight(const StructureState& st, const Structure& s);

/// Meshes every anchored fragment of a permeable solid on its particles' rest positions and
/// builds its Biot problem (t = 0).
void build_structures(const Model& model, State& state);

/// Adds this step's forces on the porous particles (PorousScratch::force: fluid reactions and
/// contacts) times dt to the loads of the next Biot call.
void add_structure_loads(State& state, Real dt);

/// Moves the particles the fraction (time since the last call) / dt_B of the way from
/// X + u^{n-1} to X + u^n, at the velocity of that change.
void follow_structure_displacement(const Model& model, State& state);

/// dt_B (/poroelastic/time_step) has passed since the last Biot call.
bool biot_call_due(const Model& model, const State& state);

/// Time until the next Biot call is due, s (infinite without structures): the run lands a step
/// on it, so that every call covers exactly dt_B.
Real time_to_next_biot_call(const Model& model, const State& state);

/// §4.10: remeshes a structure that has lost over 1 % of its nodes (to dissolution or the
/// domain), or whose last call left a distorted element (on its deformed shape, which becomes
/// the new rest state, standing under its weight).
void remesh_structures(const Model& model, State& state);

/// One Biot call per structure over the time since the last (M22), ending at `time`: loaded by
/// the mean force since then (§5.3) and the constraints' values at `time` (time tables), with
/// p^n from the pore water (M5) unless the Biot pressure is carried. `again`: the call repeated
/// at once after a fracture (counted apart).
void solve_structures(const Model& model, State& state, Real time, bool again = false);

/// The largest displacement of a node in the last call (from where its particle was), m.
Real largest_call_displacement(const State& state);

/// Ends the call: the loads summed since the last one are spent (a call repeated at once after
/// a fracture solves the same interval under the same loads).
void end_biot_call(State& state);

/// §5.4: porosity (M23), bulk volume V0 (1 + eps_v) and permeability (M24) into the particles
/// and the next call's mobility. Returns true when some particle's volume or permeability moved
/// by over 1 % since the pore-flow pairs were built on them (the pairs are then stale).
bool feed_back_structures(const Model& model, State& state);

/// Drops the solvers that solve a cracked mesh through an older factor (BiotSplitOf), once the
/// call that cracked it is over: they serve its repeated solves, and the next call factorises
/// the mesh afresh, as a run resumed from a checkpoint in between does (resumes are exact).
void release_split_solvers(State& state);

/// Appends every structure's mesh and fields (nodes at their rest positions X) to `frame`.
void append_structure_meshes(const Model& model, State& state, MeshFrame& frame);

/// Every solid's supports over its structures (biot_setup.hpp support_loads), one row per solid
/// and support: forces and node counts summed, displacements averaged over the nodes. `time` is
/// that of the last Biot call (a platen's applied force).
std::vector<SupportLog> structure_supports(const Model& model, const State& state, Real time);

/// Elements and mesh-quality figures summed over the structures.
MeshQuality structure_mesh_quality(const State& state);

}  // namespace karst
