#include "karst/rigid/closing_speed_limit.hpp"

#include "karst/core/parallel.hpp"
#include "karst/rigid/fragment_motion.hpp"

#include <algorithm>

namespace karst {

namespace {

/// One pair that may close past its core within the step: member k of free fragment a, and a
/// wall particle or member j of fragment b (b < 0: a wall or an anchored structure, which does
/// not move).
struct SpeculativePair {
    Index a = 0, b = -1;
    Index still_member = -1;     ///< the anchored structure's member on the other side, if any
    Vec3 normal = Vec3::Zero();  ///< from the other towards k
    Vec3 arm_a = Vec3::Zero(), arm_b = Vec3::Zero();  ///< contact point - centre
    Real target = 0;      ///< the slowest allowed normal velocity, m/s (<= 0: closing)
    Real approach = 0;    ///< the closing speed before the solve, m/s
    bool impact = false;  ///< closing fast enough to pass the core from its rest length
    Real inverse_mass = 0;
    Real impulse = 0;  ///< accumulated, N s (>= 0)
};

constexpr int k_sweeps = 20;

}  // namespace

Index limit_closing_speeds(const Model& model, State& state, const ContactLaw& law, Real dt,
                           std::vector<Vec3>& still_impulse) {
    PorousParticles& p = state.porous.particles;
    std::vector<Fragment>& fragments = state.porous.fragments;
    const PorousScratch& s = state.porous_scratch;
    const auto is_free = [&](Index f) { return !fragments[f].anchored && fragments[f].mass > 0; };
    std::vector<Mat3> inverse_inertia(fragments.size(), Mat3::Zero());
    std::vector<Vec3> omega(fragments.size(), Vec3::Zero());
    bool any_free = false;
    for (size_t f = 0; f < fragments.size(); ++f)
        if (is_free(Index(f))) {
            inverse_inertia[f] = fragments[f].world_inertia().inverse();
            omega[f] = inverse_inertia[f] * fragments[f].angular_momentum;
            any_free = true;
        }
    if (!any_free) return 0;
    const std::vector<Vec3> x = contact_positions(state);
    const Vec3 g = model.scene.gravity;
    const auto velocity = [&](Index f, const Vec3& arm) {
        return f < 0 ? Vec3(Vec3::Zero()) : Vec3(fragments[f].velocity + omega[f].cross(arm));
    };
    const auto response = [&](Index f, const Vec3& arm, const Vec3& n) {
        if (f < 0) return Real(0);
        const Vec3 rn = arm.cross(n);
        return 1 / fragments[f].mass + rn.dot(inverse_inertia[f] * rn);
    };
    // The normal velocity of a pair at the end of the step under gravity alone (< 0: closing).
    const auto closing_speed = [&](const SpeculativePair& c) {
        const Vec3 gravity_b = c.b >= 0 ? g : Vec3::Zero();
        return c.normal.dot(velocity(c.a, c.arm_a) - velocity(c.b, c.arm_b) + dt * (g - gravity_b));
    };
    // The pairs, in member order (each pair of two free fragments once, from its lower index):
    // those that would pass the core, and those that touch, which an impulse elsewhere in
    // their fragment can set closing.
    std::vector<SpeculativePair> pairs;
    bool any_passes = false;
    const auto consider = [&](Index k, const Vec3& other_x, Index other_fragment,
                              Index still_member, Real rest) {
        const Index a = p.fragment[k];
        const Vec3 d = x[k] - other_x;
        const Real r = d.norm();
        if (r == 0) return;
        SpeculativePair c;
        c.a = a, c.b = other_fragment, c.still_member = still_member, c.normal = d / r;
        c.arm_a = x[k] - fragments[a].centre;
        if (c.b >= 0) c.arm_b = other_x - fragments[c.b].centre;
        const Real closing = closing_speed(c);
        c.target = std::min(Real(0), -(r - k_contact_core * rest) / dt);
        const bool passes = closing < c.target;
        if (!passes && r >= rest) return;
        any_passes |= passes;
        c.approach = -closing;
        c.impact = passes && c.approach > (1 - k_contact_core) * rest / dt;
        c.inverse_mass = response(a, c.arm_a, c.normal) + response(c.b, c.arm_b, c.normal);
        pairs.push_back(c);
    };
    const std::span<const CrackContact> cracked = state.porous.crack_contacts;
    for (Index k = 0; k < p.size(); ++k) {
        const Index a = p.fragment[k];
        if (!is_free(a) || law.pair_scale(a, a) == 0) continue;
        s.porous_wall.for_each(
            k, [&](Index w) { consider(k, model.walls.x[w], -1, -1, law.rest_distance); });
        s.porous_porous.for_each(k, [&](Index j) {
            const Index b = p.fragment[j];
            if (b == a || p.origin[j] == p.origin[k]) return;
            if (is_free(b) && j < k) return;  // the pair once
            const Real rest =
                cracked.empty() ? law.rest_distance
                                : pair_rest_distance(cracked, p.id[k], p.id[j], law.rest_distance);
            consider(k, x[j], is_free(b) ? b : -1, is_free(b) ? -1 : j, rest);
        });
    }
    if (!any_passes) return 0;
    // Projected Gauss-Seidel on the accumulated impulses, serial and in pair order.
    const auto apply = [&](const SpeculativePair& c, Real impulse) {
        const Vec3 j = impulse * c.normal;
        Fragment& fa = fragments[c.a];
        fa.velocity += j / fa.mass;
        fa.angular_momentum += c.arm_a.cross(j);
        omega[c.a] = inverse_inertia[c.a] * fa.angular_momentum;
        if (c.b < 0) return;
        Fragment& fb = fragments[c.b];
        fb.velocity -= j / fb.mass;
        fb.angular_momentum -= c.arm_b.cross(j);
        omega[c.b] = inverse_inertia[c.b] * fb.angular_momentum;
    };
    const auto solve = [&] {
        for (int sweep = 0; sweep < k_sweeps; ++sweep)
            for (SpeculativePair& c : pairs) {
                const Real total =
                    std::max(Real(0), c.impulse + (c.target - closing_speed(c)) / c.inverse_mass);
                apply(c, total - c.impulse);
                c.impulse = total;
            }
    };
    solve();
    // Then the impacts that took an impulse rebound with the law's restitution, as the springs
    // give a slow contact: a separation of e times their closing speed before the solve. A pair
    // held only against gravity does not bounce.
    if (law.restitution > 0) {
        for (SpeculativePair& c : pairs)
            if (c.impulse > 0 && c.impact) c.target = law.restitution * c.approach;
        solve();
    }
    // An anchored structure takes the opposite impulse on its member, as the springs' forces
    // load it (its Biot call's loads).
    for (const SpeculativePair& c : pairs)
        if (c.still_member >= 0) still_impulse[c.still_member] -= c.impulse * c.normal;
    // The members move with their fragment's new rigid velocity field.
    parallel_for(p.size(), [&](Index k) {
        const Index f = p.fragment[k];
        if (is_free(f))
            p.v[k] = fragments[f].velocity + omega[f].cross(p.x[k] - fragments[f].centre);
    });
    return Index(std::count_if(pairs.begin(), pairs.end(),
                               [](const SpeculativePair& c) { return c.impulse > 0; }));
}

}  // namespace karst
