#pragma once
#include "karst/sim/model.hpp"
#include "karst/sim/state.hpp"

namespace karst {

/// M7 (Akinci 2012): rho_i = sum_j m_j W_ij (self included) + sum_k Psi_k W_ik over walls and
/// porous particles,
/// evaluated at `x` with the current neighbour lists. Writes rho (n), kg/m^3.
void compute_density(const Model& model, const State& state, const std::vector<Vec3>& x,
                     std::vector<Real>& rho);

/// Stage: densities of the current positions into state.fluid.rho.
void update_density(const Model& model, State& state);

}  // namespace karst
