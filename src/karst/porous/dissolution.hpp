#pragma once
// Dissolution into muddy fluid (docs/method.md §4.8): saturated, high-porosity porous particles
// become fluid particles carrying their grains as solute, conserving mass and momentum.
#include "karst/porous/pore_water.hpp"
#include "karst/sim/state.hpp"
#include "karst/sph/neighbour_grid.hpp"

#include <span>

namespace karst {

/// When a material dissolves (per material, like PoreWaterLaw).
struct DissolutionThreshold {
    Real saturation = 0.98;     ///< S_diss
    Real porosity = 0.6;        ///< phi_diss
    Real grain_density = 2650;  ///< rho_s, kg/m^3: sets the muddy particle's volume
};

struct DissolutionSettings {
    std::vector<DissolutionThreshold> thresholds;  ///< per material (PorousParticles::material)
    Real fluid_particle_mass;                      ///< m_f0 = rho0 dx^3, kg
    Real spacing;                                  ///< dx, m (pieces are set 0.1 dx apart)
};

/// exposed[k] = 1 where a fluid particle (of mass > 0) lies within h of porous particle k and
/// none closer than 0.6 dx; `porous_fluid` lists each porous particle's fluid partners within h.
/// [D] So the grains leave the rock at its surface, into open water. An interior particle turned
/// into fluid sits in a one-site cavity among boundary particles, and its pressure blew a soaking
/// block apart (151 m/s within 0.6 s); a fluid particle pressed closer than 0.6 dx would overlap
/// the new one (0.2 dx was seen), with the same result.
void mark_exposed(const PorousParticles& porous, const FluidParticles& fluid,
                  const NeighbourLists& porous_fluid, Real h, Real spacing,
                  std::vector<char>& exposed);

struct DissolutionReport {
    Index dissolved = 0;      ///< porous particles converted
    Index fluid_created = 0;  ///< fluid particles made from them
};

/// Converts every porous particle with S >= S_diss and phi >= phi_diss of its material, and in
/// `exposed` (all when empty; see mark_exposed), into fluid: mass m_s + m_p, solute m_s, the
/// particle's velocity, and volume m_p / rho0 + m_s / rho_s, so a saturated particle keeps its
/// own volume and the slurry is denser than water [D: the sheet's V = m / rho0 put 1.5 lattice
/// volumes into one site, 16 % over-dense, and blew it out at 250 m/s]. It is split into
/// ceil(m / m_f0) pieces when m > 2 m_f0; the porous particle is removed (its fragment must then
/// update its mass properties and remesh, docs/method.md §4.8). New fluid ids continue from
/// `next_id`.
DissolutionReport dissolve(PorousParticles& porous, FluidParticles& fluid,
                           std::span<const PoreWaterLaw> laws, const DissolutionSettings& settings,
                           std::int64_t& next_id, const std::vector<char>& exposed = {});

}  // namespace karst
