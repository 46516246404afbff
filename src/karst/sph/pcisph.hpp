#pragma once
#include "karst/sim/model.hpp"
#include "karst/sph/dfsph.hpp"
#include "karst/sim/state.hpp"

namespace karst {

/// Stage (docs/method.md §4.3, Solenthaler & Pajarola 2009): the predict-correct loop. Starting
/// from p = 0 it predicts x* with the non-pressure and pressure accelerations, predicts rho* (M7)
/// at x* with the boundary's change counted twice (pcisph.cpp says why) and the free fragments'
/// members moved with the reaction of the current p, updates p <- max(p + delta_i (rho* -
/// rho0), 0) (delta_i: M8 per particle, see pcisph.cpp), and recomputes the pressure
/// acceleration (walls with the hydrostatically extrapolated pressure), while (it < it_min or
/// max_i max(rho*_i - rho0, 0) > eta_rho rho0) and it < it_max. Writes state.fluid.p (Pa) and
/// scratch.a_pressure (m/s^2); reads the step's pair factors
/// (update_density_and_pair_coefficients).
PressureSolveReport solve_pressure_pcisph(const Model& model, State& state, Real dt);

}  // namespace karst
