#pragma once
// The pore-water state of porous particles and its constitutive laws (docs/method.md §2, M3-M6).
#include "karst/core/soa.hpp"
#include "karst/core/types.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace karst {

/// Porous particles as structure-of-arrays (docs/method.md §2). Mass of pore water m_p is the
/// conserved quantity. `rest` and `material` may stay empty for a set of one material that
/// belongs to no rigid fragment (the poroelastic-only solver, unit tests).
struct PorousParticles {
    std::vector<Vec3> x;              ///< world position, m
    std::vector<Real> volume;         ///< bulk volume V, m^3
    std::vector<Real> porosity;       ///< phi
    std::vector<Real> absorbed_mass;  ///< m_p, kg
    std::vector<Real> solid_mass;     ///< m_s = rho_s (1 - phi0) V0, kg
    std::vector<Vec3> v;              ///< world velocity (from the fragment), m/s
    std::vector<Mat3> permeability;   ///< world tensor K (M12), m^2
    std::vector<Index> fragment;      ///< pairs in different fragments exchange only in contact
    std::vector<Vec3> rest;       ///< X, position in the fragment's body frame about its centre, m
    std::vector<Index> material;  ///< index of the material's PoreWaterLaw (the scene's solid)
    std::vector<Mat3> body_permeability;  ///< K0 in the body frame (M12), m^2
    std::vector<Index> id;  ///< stable over removals (the PFEM mesh's node -> particle map)
    /// The id of the particle this one was split from by fracture (M27), its own id if none:
    /// the halves of one particle overlap and push each other by no contact spring.
    std::vector<Index> origin;
    Index size() const { return Index(x.size()); }
    Index material_of(Index i) const { return material.empty() ? 0 : material[i]; }
    /// Calls f(a.attr, b.attr, ...) for every attribute of the sets (core/soa.hpp).
    template <class F, class... Sets>
    static void for_each_attribute(F&& f, Sets&... s) {
        f(s.x...), f(s.volume...), f(s.porosity...), f(s.absorbed_mass...), f(s.solid_mass...),
            f(s.v...);
        f(s.permeability...), f(s.fragment...), f(s.rest...), f(s.material...),
            f(s.body_permeability...), f(s.id...), f(s.origin...);
    }
};

/// Particle index of each porous particle id below `ids` (every id present must be below it),
/// -1 for ids no longer present.
inline std::vector<Index> index_by_id(const PorousParticles& p, size_t ids) {
    std::vector<Index> index(ids, -1);
    for (Index i = 0; i < p.size(); ++i) index[size_t(p.id[i])] = i;
    return index;
}

/// Below this porosity a particle is impermeable (M3) and takes part in no transfer.
inline constexpr Real k_min_porosity = 1e-4;

/// Material constants of the pore water (docs/method.md §8.2 defaults).
struct PoreWaterLaw {
    Real rest_density = 1000;       ///< rho0, kg/m^3
    Real capillary_scale = 2000;    ///< k^c, Pa
    Real capillary_exponent = 0.5;  ///< alpha of M4, (0, 1]
    Real pore_stiffness = 1.4e4;    ///< k^p, Pa
    Real tait_exponent = 7;         ///< gamma of M5
    Real saturation_exponent = 2;   ///< beta: k_r = S^beta
    Real darcy_viscosity = 0.1;     ///< eta, Pa s
    Real absorption_factor = 1;     ///< chi_abs of M15: scales fluid-porous pairs
    Vec3 gravity{0, 0, -9.81};      ///< m/s^2

    /// M3: S = m_p / (rho0 phi V).
    Real saturation(Real m_p, Real phi, Real V) const { return m_p / (rest_density * phi * V); }
    /// M4: P^c = k^c (1 - min(S, 1))^alpha.
    Real capillary_potential(Real S) const {
        return capillary_scale * std::pow(1 - std::min(S, Real(1)), capillary_exponent);
    }
    /// M5: P^p = k^p S max(0, S^gamma - 1).
    Real pore_pressure(Real S) const {
        return pore_stiffness * S * std::max(Real(0), std::pow(S, tait_exponent) - 1);
    }
    /// M6: Phi = P^p - P^c - rho0 g.x.
    Real flow_potential(Real S, const Vec3& x) const {
        return pore_pressure(S) - capillary_potential(S) - rest_density * gravity.dot(x);
    }
    /// M17: the pore (interstitial) velocity v_p = -(k_r K / (phi eta)) grad Phi, m/s.
    Vec3 pore_velocity(Real kr, Real phi, const Mat3& K, const Vec3& grad_potential) const {
        return -(kr / (phi * darcy_viscosity)) * (K * grad_potential);
    }
    /// dPhi/dS (for the sub-step limit, §4.7.5), with dP^c/dS taken at max(1 - S, 0.01).
    Real potential_slope(Real S) const {
        const Real dry = std::max(1 - S, Real(0.01));
        const Real capillary =
            capillary_scale * capillary_exponent * std::pow(dry, capillary_exponent - 1);
        const Real pore =
            S > 1 ? pore_stiffness * ((tait_exponent + 1) * std::pow(S, tait_exponent) - 1) : 0;
        return pore + capillary;
    }
};

}  // namespace karst
