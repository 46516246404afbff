#include "karst/rigid/contact.hpp"

#include "karst/core/parallel.hpp"

#include <cmath>
#include <numbers>

namespace karst {

ContactLaw ContactLaw::for_fragments(Real spacing, Real fragment_mass, Real gravity,
                                     Real particle_mass, Real restitution) {
    ContactLaw law;
    law.rest_distance = spacing;
    law.stiffness = fragment_mass * gravity / (0.01 * spacing);
    // A damped oscillator of reduced mass m/2 rebounds with e = exp(-pi zeta / sqrt(1 - zeta^2)).
    const Real log_e = std::log(restitution);
    const Real zeta = -log_e / std::sqrt(std::numbers::pi * std::numbers::pi + log_e * log_e);
    law.damping = 2 * zeta * std::sqrt(law.stiffness * 0.5 * particle_mass);
    return law;
}

Index add_contact_forces(const PorousParticles& p, const NeighbourLists& neighbours,
                         const ContactLaw& law, std::vector<Vec3>& force,
                         std::span<const Vec3> still_x) {
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
            if (const Real r = x.norm(); r >= law.rest_distance || r == 0 || scale == 0) return;
            const Vec3 on_lo = law.force(x, velocity(lo) - velocity(hi), scale);
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
