#include "karst/rigid/fragment_motion.hpp"

#include "karst/core/parallel.hpp"
#include "karst/core/soa.hpp"
#include "karst/rigid/closing_speed_limit.hpp"
#include "karst/rigid/contact.hpp"

#include <Eigen/Eigenvalues>

#include <cmath>

namespace karst {

namespace {

/// The contact law of docs/method.md §4.2, per free fragment (mass M, N members).
/// [D] The sheet's k_c = M g / (0.01 dx) holds a fragment on one particle. A fragment resting on
/// a face touches about N^(2/3) particles, which is N^(2/3) times stiffer: omega^2 = N^(2/3) g /
/// (0.01 dx), so omega dt = 9 for a 1000-particle cube at a 5 ms step, and explicit steps blow
/// up. Dividing k_c by N^(2/3) keeps a face's sink at 0.01 dx and omega dt near 1; the damping
/// gives e = 0.2 for that face against a wall (reduced mass M / N^(2/3)).
/// [D] Each fragment has its own law, and a pair of fragments takes the lighter one's
/// (ContactLaw::pair_scale): one law for the lightest fragment let a block sink through the
/// floor once a crack had chipped a few particles off somewhere, and the heavier one's made a
/// crumb under a block ring so fast that the contact sub-steps stalled the run.
ContactLaw fragment_contact_law(const Model& model, const State& state) {
    const std::vector<Fragment>& fragments = state.porous.fragments;
    std::vector<Index> members(fragments.size(), 0);
    for (Index f : state.porous.particles.fragment) ++members[f];
    std::vector<Real> per_face(fragments.size(), 0);
    Real lightest = 0;
    for (size_t f = 0; f < members.size(); ++f) {
        if (fragments[f].anchored || members[f] == 0 || fragments[f].mass <= 0) continue;
        per_face[f] = fragments[f].mass / std::pow(Real(members[f]), 2.0 / 3.0);
        if (lightest == 0 || per_face[f] < lightest) lightest = per_face[f];
    }
    if (lightest == 0) {  // only anchored fragments: they touch but do not move
        ContactLaw none;
        none.rest_distance = model.dx;
        return none;
    }
    const Real g =
        std::max(model.scene.gravity.norm(), Real(9.81));  // weightless scenes still collide
    ContactLaw law = ContactLaw::for_fragments(model.dx, lightest, g, 2 * lightest);
    law.scale.resize(fragments.size());
    for (size_t f = 0; f < fragments.size(); ++f) law.scale[f] = per_face[f] / lightest;
    return law;
}

/// The highest contact frequency of the free fragments over the next dt, rad/s: per fragment the
/// square root of the largest eigenvalue of M6^-1 K6, K6 = sum_pairs k [n; r x n][n; r x n]^T
/// over its pairs that touch or may touch within dt at their closing speed (r from its centre,
/// n along the pair), M6 = diag(M I, I_w). A pair between two free fragments counts twice (their
/// reduced mass is at most half of either).
Real contact_frequency(const Model& model, const State& state, const ContactLaw& law, Real dt) {
    using Mat6 = Eigen::Matrix<Real, 6, 6>;
    using Vec6 = Eigen::Matrix<Real, 6, 1>;
    const PorousParticles& p = state.porous.particles;
    const std::vector<Fragment>& fragments = state.porous.fragments;
    const PorousScratch& s = state.porous_scratch;
    auto is_free = [&](Index f) { return !fragments[f].anchored && fragments[f].mass > 0; };
    std::vector<Mat6> stiffness(fragments.size(), Mat6::Zero());
    std::vector<char> touching(fragments.size(), 0);
    auto add = [&](Index k, const Vec3& x, const Vec3& v, Real weight) {
        const Index f = p.fragment[k];
        const Real r = x.norm();
        if (r == 0 || r >= law.rest_distance + dt * std::max(-v.dot(x) / r, Real(0))) return;
        Vec6 j;
        j << x / r, (p.x[k] - fragments[f].centre).cross(x / r);
        stiffness[f] += (weight * law.stiffness) * j * j.transpose();
        touching[f] = 1;
    };
    for (Index k = 0; k < p.size(); ++k) {  // serial: a few pairs per touching member
        const Index f = p.fragment[k];
        if (!is_free(f)) continue;
        s.porous_porous.for_each(k, [&](Index j) {
            if (p.fragment[j] == f || p.origin[j] == p.origin[k]) return;
            add(k, p.x[k] - p.x[j], p.v[k] - p.v[j],
                (is_free(p.fragment[j]) ? 2 : 1) * law.pair_scale(f, p.fragment[j]));
        });
        s.porous_wall.for_each(
            k, [&](Index w) { add(k, p.x[k] - model.walls.x[w], p.v[k], law.pair_scale(f, f)); });
    }
    Real highest = 0;
    for (size_t f = 0; f < fragments.size(); ++f) {
        if (!touching[f]) continue;
        Mat6 mass = Mat6::Zero();
        mass.topLeftCorner<3, 3>() = fragments[f].mass * Mat3::Identity();
        mass.bottomRightCorner<3, 3>() = fragments[f].world_inertia();
        const Eigen::GeneralizedSelfAdjointEigenSolver<Mat6> modes(stiffness[f], mass,
                                                                   Eigen::EigenvaluesOnly);
        highest = std::max(highest, std::sqrt(std::max(modes.eigenvalues().maxCoeff(), Real(0))));
    }
    return highest;
}

/// The longest stable contact sub-step, s: symplectic Euler on a spring with damping rate
/// 2 zeta omega is stable for omega h <= 2 (sqrt(1 + zeta^2) - zeta); here every pair's damping is
/// c/k times its stiffness, so zeta = (c/k) omega / 2 in every mode, and the stiffest mode binds.
/// Three quarters of that, for the estimate's pairs that come and go within the step.
Real contact_sub_step(Real omega, const ContactLaw& law) {
    const Real zeta = 0.5 * law.damping / law.stiffness * omega;
    return 0.75 * 2 * (std::sqrt(1 + zeta * zeta) - zeta) / omega;
}

/// Every free fragment moves as a rigid body under `force` (per member), `torque` and gravity
/// over h, and its members follow: x = c + R X, v = v_c + omega x (x - c), K = R K0 R^T.
void move_fragments(const Model& model, State& state, const std::vector<Vec3>& force, Real h) {
    PorousParticles& p = state.porous.particles;
    std::vector<Fragment>& fragments = state.porous.fragments;
    // F_r = sum_k F_k + M g, tau_r = sum_k (x_k - c) x F_k (§4.5), summed in particle order.
    const size_t nf = fragments.size();
    std::vector<Vec3> total(nf, Vec3::Zero()), torque(nf, Vec3::Zero());
    for (Index k = 0; k < p.size(); ++k) {
        const Index f = p.fragment[k];
        total[f] += force[k];
        torque[f] += (p.x[k] - fragments[f].centre).cross(force[k]);
    }
    std::vector<Mat3> rotation(nf);
    std::vector<Vec3> omega(nf);
    for (size_t f = 0; f < nf; ++f) {
        Fragment& fr = fragments[f];
        if (fr.mass > 0 && !fr.anchored)
            integrate_fragment(fr, total[f] + fr.mass * model.scene.gravity, torque[f], h);
        rotation[f] = fr.rotation_matrix();
        omega[f] = fr.mass > 0 ? fr.angular_velocity() : Vec3::Zero();
    }
    parallel_for(p.size(), [&](Index k) {
        const Index f = p.fragment[k];
        const Fragment& fr = fragments[f];
        if (fr.anchored) return;
        const Mat3& R = rotation[f];
        p.x[k] = fr.centre + R * p.rest[k];
        p.v[k] = fr.velocity + omega[f].cross(p.x[k] - fr.centre);
        p.permeability[k] = R * p.body_permeability[k] * R.transpose();
    });
}

}  // namespace

void advance_fragments(const Model& model, State& state, Real dt) {
    PorousParticles& p = state.porous.particles;
    PorousScratch& s = state.porous_scratch;
    const ContactLaw law = fragment_contact_law(model, state);
    s.contacts = 0;
    if (law.stiffness == 0) {
        move_fragments(model, state, s.force, dt);
    } else {
        // [D] The springs are explicit: a light fragment pressed between others rang up and
        // flew off with energy it never had, so the contacts take sub-steps short enough for
        // the stiffest contact mode, under the step's fixed fluid reactions.
        // Fast approaches first, which the springs would let through the wall's layer.
        std::vector<Vec3> still_impulse(p.size(), Vec3::Zero());
        limit_closing_speeds(model, state, law, dt, still_impulse);
        const Real omega = contact_frequency(model, state, law, dt);
        const int substeps =
            omega > 0 ? std::max(1, int(std::ceil(dt / contact_sub_step(omega, law) - 1e-9))) : 1;
        const Real h = dt / substeps;
        const std::vector<Vec3> fluid = s.force;
        const std::vector<Vec3> still_x = contact_positions(state);
        std::vector<Vec3> force(p.size()), mean(p.size(), Vec3::Zero());
        for (int sub = 0; sub < substeps; ++sub) {
            force = fluid;
            Index touching = add_contact_forces(p, s.porous_porous, law, force, still_x,
                                                state.porous.crack_contacts);
            touching += add_wall_contact_forces(p, s.porous_wall, model.walls.x, law, force);
            if (sub == 0) s.contacts = touching;
            move_fragments(model, state, force, h);
            for (Index k = 0; k < p.size(); ++k) mean[k] += force[k] / substeps;
        }
        // What the members felt on average, the impacts' impulses included: the Biot loads.
        for (Index k = 0; k < p.size(); ++k) mean[k] += still_impulse[k] / dt;
        s.force = std::move(mean);
    }
    if (!state.porous.crack_contacts.empty())
        forget_parted_pairs(state.porous.crack_contacts, p, contact_positions(state), model.dx);
    std::vector<char> inside(p.size(), 1);
    parallel_for(p.size(), [&](Index k) {
        inside[k] = state.porous.fragments[p.fragment[k]].anchored || model.domain.contains(p.x[k]);
    });
    const Index kept = std::count(inside.begin(), inside.end(), 1);
    if (kept != p.size()) {
        state.porous.removed += p.size() - kept;
        keep_attributes(p, inside);
        keep_flagged(s.exposed, inside);
        s.pairs_stale = true;
        refresh_fragment_mass(state, model.dx);
    }
}

/// [D] Where a free fragment meets an anchored structure: the structure's undeformed surface
/// (rest_x), at rest, as linear elasticity poses its loads on the undeformed body. A contact that
/// followed u fed the spring's answer to u back into the next Biot call's loads, which rang a
/// nearly cut-off part of a cracked body up by decimetres within three calls; and a surface that
/// moved with u did work on the fragments resting on it (followed up to 0.1 dx, the collapsing
/// demo gained 12 % of the energy it had released).
std::vector<Vec3> contact_positions(const State& state) {
    const PorousParticles& p = state.porous.particles;
    const StructureState& st = state.structures;
    std::vector<Vec3> x = p.x;
    if (st.empty()) return x;
    parallel_for(p.size(), [&](Index k) {
        const Index id = p.id[k];
        if (size_t(id) < st.node_of.size() && st.node_of[id].first >= 0) x[k] = st.rest_x[id];
    });
    return x;
}

Real contact_energy(const Model& model, const State& state) {
    const PorousParticles& p = state.porous.particles;
    if (p.size() == 0) return 0;
    const ContactLaw law = fragment_contact_law(model, state);
    if (law.stiffness == 0) return 0;
    const std::vector<Vec3> x = contact_positions(state);
    Aabb box{x[0], x[0]};
    for (const Vec3& y : x) box.extend(y);
    const UniformGrid grid(box.padded(model.h), model.h);  // cells of h >= d0: few, for any spread
    CellRanges cells;
    sort_into_cells(grid, x, cells);
    const std::span<const CrackContact> cracked = state.porous.crack_contacts;
    const auto spring = [&](Real scale, Real rest, Real r) {
        return scale > 0 && r > 0 && r < rest
                   ? 0.5 * scale * law.stiffness * (rest - r) * (rest - r)
                   : 0;
    };
    return deterministic_sum(p.size(), Real(0), [&](Index i) {
        Real e = 0;
        for_each_within(grid, cells, x[i], law.rest_distance, [&](Index j, const Vec3& xj) {
            if (j <= i || p.fragment[i] == p.fragment[j] || p.origin[i] == p.origin[j]) return;
            const Real rest = pair_rest_distance(cracked, p.id[i], p.id[j], law.rest_distance);
            e += spring(law.pair_scale(p.fragment[i], p.fragment[j]), rest, (xj - x[i]).norm());
        });
        const Real scale = law.pair_scale(p.fragment[i], p.fragment[i]);
        if (scale > 0 && !model.walls.cells.start.empty())
            for_each_within(model.grid, model.walls.cells, x[i], law.rest_distance,
                            [&](Index, const Vec3& xw) {
                                e += spring(scale, law.rest_distance, (xw - x[i]).norm());
                            });
        return e;
    });
}

Fragment free_fragment(PorousParticles& p, const std::vector<Index>& members, Real spacing) {
    std::vector<Vec3> x, body;
    std::vector<Real> mass;
    for (Index i : members)
        x.push_back(p.x[i]), mass.push_back(p.solid_mass[i] + p.absorbed_mass[i]);
    Fragment f = fragment_at_rest(x, mass, body, spacing);
    Vec3 momentum = Vec3::Zero(), angular = Vec3::Zero();
    for (size_t k = 0; k < members.size(); ++k) {
        const Vec3& v = p.v[members[k]];
        momentum += mass[k] * v, angular += mass[k] * body[k].cross(v);
        p.rest[members[k]] = body[k], p.body_permeability[members[k]] = p.permeability[members[k]];
    }
    f.velocity = momentum / f.mass, f.angular_momentum = angular;
    f.anchored = false;
    return f;
}

void refresh_fragment_mass(State& state, Real spacing) {
    PorousParticles& p = state.porous.particles;
    std::vector<Fragment>& fragments = state.porous.fragments;
    const size_t nf = fragments.size();
    std::vector<Real> mass(nf, 0);
    std::vector<Vec3> moment(nf, Vec3::Zero());
    for (Index k = 0; k < p.size(); ++k) {
        const Real m = p.solid_mass[k] + p.absorbed_mass[k];
        mass[p.fragment[k]] += m, moment[p.fragment[k]] += m * p.x[k];
    }
    std::vector<Mat3> inertia(nf, Mat3::Zero());
    std::vector<Vec3> centre(nf);
    std::vector<Mat3> rotation(nf);
    for (size_t f = 0; f < nf; ++f) {
        centre[f] = mass[f] > 0 ? Vec3(moment[f] / mass[f]) : fragments[f].centre;
        rotation[f] = fragments[f].rotation_matrix();
    }
    for (Index k = 0; k < p.size(); ++k) {
        const Index f = p.fragment[k];
        const Vec3 X = rotation[f].transpose() * (p.x[k] - centre[f]);
        p.rest[k] = X;
        inertia[f] += member_inertia(p.solid_mass[k] + p.absorbed_mass[k], X, spacing);
    }
    for (size_t f = 0; f < nf; ++f) {
        Fragment& fr = fragments[f];
        const Vec3 omega = fr.mass > 0 ? fr.angular_velocity() : Vec3::Zero();
        if (mass[f] > 0) fr.velocity += omega.cross(centre[f] - fr.centre);
        fr.centre = centre[f], fr.mass = mass[f];
        if (mass[f] == 0) {
            fr.velocity.setZero(), fr.angular_momentum.setZero();
            continue;
        }
        fr.body_inertia = inertia[f];
        fr.angular_momentum = fr.world_inertia() * omega;
    }
}

}  // namespace karst
