#pragma once
#include "karst/sim/model.hpp"
#include "karst/sim/state.hpp"

namespace karst {

/// Stage (docs/method.md §4.2): gravity, viscosity, Akinci 2013 surface tension (M9) and adhesion
/// (M10), and Akinci 2012 wall friction, into scratch.a_other (m/s^2). Reads the step's fluid
/// pair factors (update_density_and_pair_coefficients) for the kernel gradients.
///
/// Viscosity uses the symmetrised Monaghan form
///   a_i = (d + 2) nu sum_j m_j (1/rho_i + 1/rho_j) (v_ij . x_ij) / (r^2 + 0.01 h^2) grad W_ij,
/// which equals docs/method.md's 2 (d + 2) nu sum_j (m_j / rho_j) ... when rho_i = rho_j, and makes
/// the pair forces m_i a_i exactly opposite, so linear momentum is conserved to round-off.
void compute_non_pressure_forces(const Model& model, State& state);

}  // namespace karst
