#include "karst/porous/drained_fluid.hpp"

#include <limits>

namespace karst {

Index drain_fluid_particles(FluidParticles& fluid, PorousParticles& porous,
                            const std::vector<Index>& main_receiver,
                            const NeighbourLists& fluid_fluid, Real full_mass, Real threshold) {
    Index drained = 0;
    // Serial, in index order: a particle's solute may go to a neighbour drained later, which
    // then passes it on; the result does not depend on the thread count.
    for (Index i = 0; i < fluid.size(); ++i) {
        const Real water = fluid.water(i);
        if (fluid.mass[i] == 0 || water >= threshold * full_mass || main_receiver[i] < 0) continue;
        if (fluid.solute[i] > 0) {
            Index nearest = -1;
            Real best = std::numeric_limits<Real>::infinity();
            fluid_fluid.for_each(i, [&](Index j) {
                const Real d = (fluid.x[j] - fluid.x[i]).squaredNorm();
                if (fluid.mass[j] > 0 && d < best) best = d, nearest = j;
            });
            if (nearest < 0) continue;
            fluid.mass[nearest] += fluid.solute[i], fluid.solute[nearest] += fluid.solute[i];
            fluid.sph_mass[nearest] += fluid.solute[i] * (fluid.sph_mass[i] / fluid.mass[i]);
        }
        porous.absorbed_mass[main_receiver[i]] += water;
        fluid.mass[i] = 0, fluid.solute[i] = 0, fluid.drained[i] = 0;
        ++drained;
    }
    return drained;
}

}  // namespace karst
