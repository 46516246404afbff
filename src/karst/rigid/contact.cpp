#include "karst/rigid/contact.hpp"

#include "karst/core/parallel.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace karst {

ContactLaw ContactLaw::for_fragments(Real spacing, Real fragment_mass, Real gravity,
                                     Real particle_mass, Real restitution) {
    ContactLaw law;
    law.rest_distance = spacing;
    law.restitution = restitution;
    law.stiffness = fragment_mass * gravity / (0.01 * spacing);
    // A damped oscillator of reduced mass m/2 rebounds with e = exp(-pi zeta / sqrt(1 - zeta^2)).
    const Real log_e = std::log(restitution);
    const Real zeta = -log_e / std::sqrt(std::numbers::pi * std::numbers::pi + log_e * log_e);
    law.damping = 2 * zeta * std::sqrt(law.stiffness * 0.5 * particle_mass);
    return law;
}

Real pair_rest_distance(std::span<const CrackContact> sorted, Index a, Index b, Real d0) {
    const CrackContact key{std::min(a, b), std::max(a, b), 0};
    const auto it = std::lower_bound(sorted.begin(), sorted.end(), key);
    return it != sorted.end() && it->lo == key.lo && it->hi == key.hi ? it->rest : d0;
}

void rest_after_split(std::vector<CrackContact>& pairs, const PorousParticles& p,
                      const std::vector<Fragment>& fragments, const SplitParticles& split,
                      Real d0) {
    const auto first = std::find(split.body.begin(), split.body.end(), 1);
    if (first == split.body.end()) return;
    const auto moves = [&](Index i) {
        const Fragment& f = fragments[size_t(p.fragment[i])];
        return !f.anchored && f.mass > 0;
    };
    // The particles within d0 of the body's box, in a grid of cell 2 d0 (= h, as the fluid's).
    const std::span<const Vec3> x = split.after;
    Aabb box{x[first - split.body.begin()], x[first - split.body.begin()]};
    for (Index i = 0; i < p.size(); ++i)
        if (split.body[i]) box.extend(x[i]);
    box = box.padded(d0);
    std::vector<Index> near;
    std::vector<Vec3> near_x;
    for (Index i = 0; i < p.size(); ++i)
        if (box.contains(x[i])) near.push_back(i), near_x.push_back(x[i]);
    const UniformGrid grid(box, 2 * d0);
    CellRanges cells;
    sort_into_cells(grid, near_x, cells);
    std::vector<CrackContact> fresh;
    for (Index i = 0; i < p.size(); ++i) {
        if (!split.body[i]) continue;
        for_each_within(grid, cells, x[i], d0, [&](Index k, const Vec3& xj) {
            const Index j = near[size_t(k)];
            if (p.fragment[i] == p.fragment[j] || p.origin[i] == p.origin[j]) return;
            if (!moves(i) && !moves(j)) return;              // no spring
            if (split.body[j] && p.id[j] < p.id[i]) return;  // each pair of the body once
            const Real r = (xj - x[i]).norm();
            Real rest = r;
            // The body was anchored, so only a pair with a free fragment had a spring.
            if (!split.body[j] && !split.copy[i] && moves(j)) {
                const Real closed = (split.before[j] - split.before[i]).norm() - r;
                rest = pair_rest_distance(pairs, p.id[i], p.id[j], d0) - std::max(closed, Real(0));
                if (rest >= d0) return;
            }
            fresh.push_back({std::min(p.id[i], p.id[j]), std::max(p.id[i], p.id[j]), rest});
        });
    }
    std::sort(fresh.begin(), fresh.end());
    std::vector<CrackContact> merged;
    merged.reserve(pairs.size() + fresh.size());
    std::set_union(fresh.begin(), fresh.end(), pairs.begin(), pairs.end(),
                   std::back_inserter(merged));  // equal keys: the fresh entry
    pairs = std::move(merged);
}

void forget_parted_pairs(std::vector<CrackContact>& pairs, const PorousParticles& p,
                         std::span<const Vec3> x, Real d0) {
    if (pairs.empty()) return;
    const size_t ids = p.size() > 0 ? size_t(*std::ranges::max_element(p.id)) + 1 : 0;
    const std::vector<Index> index_of = index_by_id(p, ids);
    const auto at = [&](Index id) { return size_t(id) < ids ? index_of[size_t(id)] : Index(-1); };
    std::erase_if(pairs, [&](const CrackContact& c) {
        const Index i = at(c.lo), j = at(c.hi);
        return i < 0 || j < 0 || p.fragment[i] == p.fragment[j] || (x[i] - x[j]).norm() >= d0;
    });
}

Index add_contact_forces(const PorousParticles& p, const NeighbourLists& neighbours,
                         const ContactLaw& law, std::vector<Vec3>& force,
                         std::span<const Vec3> still_x, std::span<const CrackContact> cracked) {
    const bool still = !still_x.empty() && !law.scale.empty();
    const auto at = [&](Index k) {
        return still && law.scale[size_t(p.fragment[k])] == 0 ? still_x[k] : p.x[k];
    };
    const auto velocity = [&](Index k) {
        return still && law.scale[size_t(p.fragment[k])] == 0 ? Vec3::Zero() : p.v[k];
    };
    std::vector<Index> touching(p.size(), 0);
    parallel_for(p.size(), [&](Index i) {
        Vec3 sum = Vec3::Zero();
        neighbours.for_each(i, [&](Index j) {
            if (p.fragment[i] == p.fragment[j] || p.origin[i] == p.origin[j]) return;
            // Evaluated in (min, max) order so that the pair's two forces are bitwise opposite.
            const Index lo = std::min(i, j), hi = std::max(i, j);
            const Vec3 x = at(lo) - at(hi);
            const Real scale = law.pair_scale(p.fragment[i], p.fragment[j]);
            const Real r = x.norm();
            if (r >= law.rest_distance || r == 0 || scale == 0) return;
            const Real rest =
                cracked.empty() ? law.rest_distance
                                : pair_rest_distance(cracked, p.id[i], p.id[j], law.rest_distance);
            if (r >= rest) return;
            const Vec3 on_lo = law.force(x, velocity(lo) - velocity(hi), scale, rest);
            sum += i == lo ? on_lo : Vec3(-on_lo);
            ++touching[i];
        });
        force[i] += sum;
    });
    Index pairs = 0;
    for (Index t : touching) pairs += t;
    return pairs / 2;
}

Index add_wall_contact_forces(const PorousParticles& p, const NeighbourLists& walls,
                              const std::vector<Vec3>& wall_x, const ContactLaw& law,
                              std::vector<Vec3>& force) {
    std::vector<Index> touching(p.size(), 0);
    parallel_for(p.size(), [&](Index i) {
        Vec3 sum = Vec3::Zero();
        const Real scale = law.pair_scale(p.fragment[i], p.fragment[i]);
        if (scale == 0) return;
        walls.for_each(i, [&](Index k) {
            const Vec3 x = p.x[i] - wall_x[k];
            if (const Real r = x.norm(); r >= law.rest_distance || r == 0) return;
            sum += law.force(x, p.v[i], scale);
            ++touching[i];
        });
        force[i] += sum;
    });
    Index pairs = 0;
    for (Index t : touching) pairs += t;
    return pairs;
}

}  // namespace karst
