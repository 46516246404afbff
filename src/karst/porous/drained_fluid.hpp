#pragma once
// Deletion of drained fluid particles (docs/method.md §4.7.3): a fluid particle whose water has
// almost all soaked into the porous solid gives the rest to the porous particle that took most
// of it, and its solute to its nearest fluid neighbour.
//
// [D] While it drains, a fluid particle keeps its SPH mass and records the water it gave in
// FluidParticles::drained. Lowering the SPH mass instead (the sheet's m_i += dt q) makes light
// particles: a particle of 0.46 m_f0 on the lattice reads its density (1 - 0.46) m_f0 W(0), 17 %,
// below rho0, sits at p = 0 and is squeezed into its neighbours until the pressure spikes; in
// a soaking block such particles in the gap beside the block reached 151 m/s within 0.6 s.
#include "karst/porous/pore_water.hpp"
#include "karst/sph/fluid_particles.hpp"
#include "karst/sph/neighbour_grid.hpp"

namespace karst {

/// For each fluid particle with water m - m_sol - drained below `threshold` m_f0 and a main
/// receiver (PoreFlowReport::main_receiver): its water goes to that porous particle, its solute (as
/// mass and solute) to the nearest fluid neighbour in `fluid_fluid`, and its mass becomes 0 so the
/// integration stage drops it. A particle with solute and no fluid neighbour is kept. Returns the
/// number of particles drained this way. Totals of water and solute are unchanged.
Index drain_fluid_particles(FluidParticles& fluid, PorousParticles& porous,
                            const std::vector<Index>& main_receiver,
                            const NeighbourLists& fluid_fluid, Real full_mass,
                            Real threshold = 0.1);

}  // namespace karst
