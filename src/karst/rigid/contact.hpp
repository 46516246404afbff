#pragma once
// Contact springs between porous particles of different fragments (docs/method.md §4.2):
//   F_{i<-j} = [k_c (d0 - r) - c_c (v_ij . r_hat)] r_hat   for r < d0 = dx,
// applied in equal and opposite pairs. Springs inside one fragment would cancel in its rigid sum,
// so only pairs across fragments count; and none between the halves of one split particle (M27),
// which overlap by construction.
#include "karst/porous/pore_water.hpp"
#include "karst/rigid/fragment.hpp"
#include "karst/sph/neighbour_grid.hpp"

#include <algorithm>
#include <span>
#include <vector>

namespace karst {

struct ContactLaw {
    Real rest_distance = 0.02;  ///< d0 = dx, m
    Real stiffness = 0;         ///< k_c, N/m
    Real damping = 0;           ///< c_c, N s/m
    Real restitution = 0;       ///< e, the normal restitution c_c was made for
    /// k_c = M g / (0.01 dx) for a fragment of mass M (docs/method.md §4.2), and the
    /// damping that gives a normal restitution e for two particles of mass m_pair each.
    static ContactLaw for_fragments(Real spacing, Real fragment_mass, Real gravity,
                                    Real particle_mass, Real restitution = 0.2);
    /// Per fragment, the factor on k_c and c_c of its pairs: its own M / N^(2/3) over the one the
    /// law was made for (0 for a fragment that does not move). Empty: 1 for every fragment.
    std::vector<Real> scale;
    /// The factor of a pair between fragments a and b (a wall: b = a): that of the lighter one
    /// that moves (0 when neither does). The lighter one's own springs then give it the
    /// frequency of its own law, so a crumb does not set the contact sub-steps of a block on it.
    Real pair_scale(Index a, Index b) const {
        if (scale.empty()) return 1;
        const Real sa = scale[size_t(a)], sb = scale[size_t(b)];
        return sa == 0 ? sb : sb == 0 ? sa : std::min(sa, sb);
    }
    /// The spring on particle a from b at offset x = x_a - x_b with relative velocity
    /// v = v_a - v_b (N), for 0 < |x| < rest, times the pair's factor s.
    Vec3 force(const Vec3& x, const Vec3& v, Real s, Real rest) const {
        const Real r = x.norm();
        const Vec3 n = x / r;
        return (s * (stiffness * (rest - r) - damping * v.dot(n))) * n;
    }
    Vec3 force(const Vec3& x, const Vec3& v, Real s = 1) const {
        return force(x, v, s, rest_distance);
    }
};

/// A pair of porous particles, by id (lo < hi), that a crack left closer than d0, and the rest
/// length of its spring (rest_after_split): the distance the crack left them at, or, for a
/// loaded pair against a free fragment, its old rest less what the crack closed it. M27's
/// offsets can bring lattice neighbours across a crack closer than d0; with the law's d0 their
/// springs would throw the pieces apart with energy no crack released. The entry holds until
/// the pair parts by d0, comes to share a fragment or loses a particle (forget_parted_pairs).
struct CrackContact {
    Index lo = 0, hi = 0;
    Real rest = 0;
    friend bool operator<(const CrackContact& a, const CrackContact& b) {
        return a.lo != b.lo ? a.lo < b.lo : a.hi < b.hi;
    }
};

/// The rest length of the pair of particle ids a and b: its entry's in `sorted` (ordered by
/// (lo, hi)), else d0.
Real pair_rest_distance(std::span<const CrackContact> sorted, Index a, Index b, Real d0);

/// What a split did to the particles of one anchored body (M27), per porous particle.
struct SplitParticles {
    std::span<const char> body;    ///< a particle of the body (one fragment before the split)
    std::span<const char> copy;    ///< a copy the split made (a new id)
    std::span<const Vec3> before;  ///< contact positions before the split (others: unmoved)
    std::span<const Vec3> after;   ///< and after it
};

/// The rest lengths after a split, so that it loads no spring. A spring that acts now starts
/// unloaded (its rest is its distance) unless it acted before with a load, which it keeps: a
/// pair between a particle that keeps its id and a free fragment's, whose rest shortens by what
/// the split's offsets closed it. Pairs between anchored fragments have no spring and no entry.
/// Entries made here replace older ones.
void rest_after_split(std::vector<CrackContact>& pairs, const PorousParticles& particles,
                      const std::vector<Fragment>& fragments, const SplitParticles& split, Real d0);

/// Forgets the pairs that parted by d0 at positions `x` (one per particle), that now share a
/// fragment, or whose particles are gone (the run calls it every step there are entries).
void forget_parted_pairs(std::vector<CrackContact>& pairs, const PorousParticles& particles,
                         std::span<const Vec3> x, Real d0);

/// Adds the contact forces (N) into `force` (one per particle); `neighbours` lists particles
/// within at least d0 (any fragment). Where `still_x` is given (one per particle), a particle of a
/// fragment that does not move (scale 0) meets the others at still_x, at rest. A pair listed in
/// `cracked` (sorted) takes its rest length there. Returns the number of touching pairs.
Index add_contact_forces(const PorousParticles& particles, const NeighbourLists& neighbours,
                         const ContactLaw& law, std::vector<Vec3>& force,
                         std::span<const Vec3> still_x = {},
                         std::span<const CrackContact> cracked = {});

/// The same springs against static wall particles at `wall_x` (the walls take no reaction);
/// `walls` lists, per porous particle, wall particles within at least d0. Returns the touching
/// pairs.
Index add_wall_contact_forces(const PorousParticles& particles, const NeighbourLists& walls,
                              const std::vector<Vec3>& wall_x, const ContactLaw& law,
                              std::vector<Vec3>& force);

}  // namespace karst
