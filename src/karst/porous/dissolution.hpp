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
/// m_s + m_p with solute m_s and the particle's velocity, split into ceil(m / m_f0) pieces when
/// m > 2 m_f0; the porous particle is removed (its fragment must then update its mass
/// properties and remesh, method.md §4.8). New fluid ids continue from `next_id`.
DissolutionReport dissolve(PorousParticles& porous, FluidParticles& fluid, std::span<const PoreWaterLaw> laws,
                           const DissolutionSettings& settings, std::int64_t& next_id);

}  // namespace karst
