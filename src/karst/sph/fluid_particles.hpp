#pragma once
// The fluid particles' physical state, one array per attribute (style.md P3/P4).
#include "karst/core/types.hpp"

#include <cstdint>
#include <vector>

namespace karst {

/// The physical state of the fluid: everything needed to restart or write a frame.
struct FluidParticles {
    std::vector<Vec3> x;     ///< (n) position, m
    std::vector<Vec3> v;     ///< (n) velocity, m/s
    std::vector<Real> mass;  ///< (n) kg
    /// (n) rho0 V: the mass of water filling the particle's volume, kg. SPH sums weigh
    /// neighbours by it, and forces per unit of it act on the true mass. It equals m for water;
    /// muddy particles are smaller, V = m_water / rho0 + m_grains / rho_s (porous/dissolution.hpp).
    std::vector<Real> sph_mass;
    std::vector<Real> solute;  ///< (n) solute mass m_sol, kg; concentration C = m_sol / m
    /// (n) water already soaked into porous solids that the particle still carries as SPH mass,
    /// kg: its water is m - m_sol - drained (porous/drained_fluid.hpp says why).
    std::vector<Real> drained;
    std::vector<Real> rho;  ///< (n) density of the last step (M7), kg/m^3
    std::vector<Real> p;    ///< (n) pressure of the last step's density solve, Pa
    /// (n) pressure of the last step's DFSPH divergence solve (a velocity-level pressure whose
    /// impulse dt a keeps dense fluid from compressing), Pa; 0 with PCISPH. The fluid's pressure
    /// is p + p_divergence (pressure()).
    std::vector<Real> p_divergence;
    std::vector<std::int64_t> id;  ///< (n) stable particle id (export only)
    Index size() const { return Index(x.size()); }
    /// The fluid's pressure at particle i: p + p_divergence, Pa.
    Real pressure(Index i) const { return p[i] + p_divergence[i]; }
    /// The water particle i holds: m - m_sol - drained, kg.
    Real water(Index i) const { return mass[i] - solute[i] - drained[i]; }
    /// Calls f(a.attr, b.attr, ...) for every attribute of the sets (core/soa.hpp).
    template <class F, class... Sets>
    static void for_each_attribute(F&& f, Sets&... s) {
        f(s.x...), f(s.v...), f(s.mass...), f(s.sph_mass...), f(s.solute...), f(s.drained...),
            f(s.rho...), f(s.p...);
        f(s.p_divergence...), f(s.id...);
    }
};

}  // namespace karst
