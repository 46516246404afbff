#pragma once
// The fragments' step (docs/method.md §4.5, §3 steps 6-7): contact springs, the sum of the forces
// on their members, rigid integration and the members' new positions, velocities and world
// permeability tensors; and the mass properties after pore water or members change.
#include "karst/sim/model.hpp"
#include "karst/sim/state.hpp"

namespace karst {

/// Stage: cuts fast closings (rigid/closing_speed_limit.hpp), then adds contact forces to
/// state.porous_scratch.force, integrates every free fragment under those forces and gravity,
/// then moves its members: x = c + R X, v = v_c + omega x (x - c), K = R K0 R^T (M12). Porous
/// particles leaving the domain are removed and counted.
void advance_fragments(const Model& model, State& state, Real dt);

/// Where each porous particle meets the others by contact: a member of an anchored structure on
/// its undeformed position (rest_x), every other particle where it is.
std::vector<Vec3> contact_positions(const State& state);

/// The elastic energy of the contact springs that touch, sum 1/2 s k_c (rest - r)^2 over pairs
/// of fragments and over fragments and walls, J: the potential energy of the contacts, which
/// the energy account counts (sim/energy.hpp).
Real contact_energy(const Model& model, const State& state);

/// A free rigid fragment of `members` in their current pose (rest orientation: body frame =
/// world frame): mass properties, and the linear and angular momentum the members carry, so
/// that neither changes. Writes the members' body-frame positions and tensors.
Fragment free_fragment(PorousParticles& p, const std::vector<Index>& members, Real spacing);

/// Mass, centre and inertia of every fragment from its members (M = sum m_s + m_p, wet mass
/// included). The rigid velocity field is kept: v moves to the new centre (v + omega x dc) and
/// L = I_w omega, so members that leave (dissolution) take exactly their own momentum.
/// `spacing` is dx (each member's own inertia, rigid/fragment.hpp).
void refresh_fragment_mass(State& state, Real spacing);

}  // namespace karst
