#pragma once
// Dissolution into muddy fluid (method.md §4.8): saturated, high-porosity porous particles
// become fluid particles carrying their grains as solute, conserving mass and momentum.
#include "karst/porous/pore_water.hpp"
#include "karst/sim/state.hpp"

#include <span>

namespace karst {

/// When a material dissolves (per material, like PoreWaterLaw).
struct DissolutionThreshold {
    Real saturation = 0.98;      ///< S_diss
    Real porosity = 0.6;         ///< phi_diss
    Real grain_density = 2650;   ///< rho_s, kg/m^3: sets the muddy particle's volume
};

struct DissolutionSettings {
    std::vector<DissolutionThreshold> thresholds;  ///< per material (PorousParticles::material)
    Real fluid_particle_mass;    ///< m_f0 = rho0 dx^3, kg
    Real spacing;                ///< dx, m (pieces are set 0.1 dx apart)
};

struct DissolutionReport {
    Index dissolved = 0;      ///< porous particles converted
    Index fluid_created = 0;  ///< fluid particles made from them
};

/// Converts every porous particle with S >= S_diss and phi >= phi_diss of its material into fluid of mass
/// m_s + m_p with solute m_s, volume m_p / rho0 + m_s / rho_s (so a saturated particle keeps its
/// own volume and the slurry is denser than water; the sheet's V = m / rho0 put 1.5 lattice
/// volumes of fluid into one lattice site, 16 % over-dense, and blew it out at 250 m/s) and the particle's velocity, split into ceil(m / m_f0) pieces when
/// m > 2 m_f0; the porous particle is removed (its fragment must then update its mass
/// properties and remesh, method.md §4.8). New fluid ids continue from `next_id`.
/// [D] Only particles in `exposed` (all when empty) dissolve: those with fluid within h and none
/// closer than 0.6 dx (sim/step.cpp), so the grains leave the rock at its surface into open
/// water. A fluid particle pressed closer than that would overlap the new one (0.2 dx was seen)
/// and the pressure needed to part them blew the block apart. A saturated interior particle turned into fluid sits in a one-site
/// cavity among boundary particles, about 16 % over-dense, and its pressure blew a soaking
/// block apart (151 m/s within 0.6 s); from the surface inward, the rock erodes layer by layer.
DissolutionReport dissolve(PorousParticles& porous, FluidParticles& fluid, std::span<const PoreWaterLaw> laws,
                           const DissolutionSettings& settings, std::int64_t& next_id,
                           const std::vector<char>& exposed = {});

}  // namespace karst
