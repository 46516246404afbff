#pragma once
// Dynamic porosity and permeability from the Biot solution (docs/method.md §5.4).
#include "karst/core/types.hpp"

#include <algorithm>
#include <cmath>

namespace karst {

/// M23 (the paper's Eq. 8, exact): phi = [phi0 + eps_v + (1 - phi0) dp/K_s] / (1 + eps_v),
/// clamped to [phi_min, 0.95]. eps_v is the volumetric strain from the fragment's rest state and
/// dp the gauge pore pressure.
inline Real dynamic_porosity(Real phi0, Real volumetric_strain, Real pressure,
                             Real solid_bulk_modulus, Real phi_min = 1e-3) {
    const Real phi = (phi0 + volumetric_strain + (1 - phi0) * pressure / solid_bulk_modulus) /
                     (1 + volumetric_strain);
    return std::clamp(phi, phi_min, Real(0.95));
}

/// M24, Kozeny-Carman consistent with M23: k = k0 (phi/phi0)^3 ((1 - phi0)/(1 - phi))^2.
/// It replaces the paper's Eq. 9, whose pressure term has the wrong sign; at dp = 0 both give
/// k0 (1 + eps_v/phi0)^3 / (1 + eps_v).
inline Real kozeny_carman_permeability(Real k0, Real phi0, Real phi) {
    const Real r = phi / phi0, s = (1 - phi0) / (1 - phi);
    return k0 * r * r * r * s * s;
}

}  // namespace karst
