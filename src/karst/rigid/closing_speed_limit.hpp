#pragma once
// Speculative contacts (Catto's, as in Box2D) for fast free fragments: before the contact
// springs act, the closing speed of every pair that would come closer than a core distance
// within the step is cut so that it arrives there at most. The springs were made to hold a
// fragment at rest (k_c of docs/method.md §4.2), and a block that fell over half a metre went
// through the wall's particle layer and stayed locked in it.
#include "karst/rigid/contact.hpp"
#include "karst/sim/model.hpp"
#include "karst/sim/state.hpp"

namespace karst {

/// The pairs' core: a pair of rest length d may come no closer than this share of d within a
/// step. Above 1 / sqrt(2), a member cannot reach the plane of a square of wall particles, so
/// it cannot pass between them; below 0.99 (a spring's sink at rest), a resting contact never
/// meets the limit.
inline constexpr Real k_contact_core = 0.75;

/// Impulses on the free fragments (linear and angular momentum, equal and opposite between two
/// free fragments) such that no pair closes faster than its gap to the core over dt, gravity
/// over dt included; the members' velocities follow. A projected Gauss-Seidel solve of the
/// non-negative impulses, which only slow approaches; then the impacts rebound with the law's
/// restitution, a share e < 1 of their closing speed. The members of anchored structures that
/// were hit get the opposite impulses added to `still_impulse` (N s, per porous particle).
/// Returns the pairs that took an impulse.
Index limit_closing_speeds(const Model& model, State& state, const ContactLaw& law, Real dt,
                           std::vector<Vec3>& still_impulse);

}  // namespace karst
