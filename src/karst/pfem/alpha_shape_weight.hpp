#pragma once
// The weight of the weighted alpha shape, shared by the mesher and the scene's mesh check.
#include "karst/core/types.hpp"

namespace karst {

/// The weight of the weighted alpha shape (docs/method.md §5.1), m^2: w = (omega_S S + omega_m
/// m/m_bar) (dx/2)^2 for a saturated, uniform-mass solid (S = 1, m = m_bar).
inline Real alpha_shape_weight(Real dx) {
    return (1.0 + 0.2) * 0.25 * dx * dx;
}

}  // namespace karst
