#pragma once
// The pressure acceleration shared by both pressure solvers (PCISPH, DFSPH):
//   a_i^p = -sum_j m_j (p_i + p_j) / rho0^2 grad W_ij - sum_k Psi_k (p_i + p_ik) / rho0^2 grad W_ik
// over fluid neighbours j and boundary neighbours k (walls and porous particles, §4.3), with the
// boundary pressure p_ik extrapolated hydrostatically (coupling/boundary_pair.hpp) or mirrored.
#include "karst/coupling/boundary_pair.hpp"
#include "karst/sim/model.hpp"
#include "karst/sim/state.hpp"

namespace karst {

/// Under-relaxation of both solvers' Jacobi pressure updates (IISPH's relaxed Jacobi, Ihmsen
/// et al. 2014): the diagonal alone (M8's delta, DFSPH's -d rho*_i / d p_i) assumes the
/// neighbours keep their pressure while a particle's own rises, and over-shoots once they
/// respond too; in impacts the full update threw water out with energy it never had.
inline constexpr Real k_pressure_relaxation = 0.5;

/// Per pair, the parts of a_i^p that stay fixed through a step's iterations: m_j / rho0^2 dW/dr / r
/// (fluid), Psi_k / rho0^2 dW/dr / r and -rho0 g.x_ik (walls, porous). Computed once per step
/// (sim/step.cpp), they save a square root, a division and the kernel in every iteration of
/// either solver and in the viscosity of the non-pressure forces. The densities of M7
/// (update_density, sph/density.hpp) come from the same pass: one distance per pair for both.
void update_density_and_pair_coefficients(const Model& model, State& state);

/// Over the fluid neighbours j of i, from the step's pair factors (m_j grad W_ij = rho0^2 c_ij
/// x_ij): sum_j m_j grad W_ij and sum_j |m_j grad W_ij|^2, the fluid's parts of both solvers'
/// diagonals (M8's delta_i, DFSPH's -d rho*_i / d p_i).
struct FluidGradientSums {
    Vec3 sum = Vec3::Zero();  ///< kg/m^4
    Real squares = 0;         ///< kg^2/m^8
};
inline FluidGradientSums fluid_gradient_sums(const Model& model, const State& state, Index i) {
    const FluidParticles& f = state.fluid;
    const FluidScratch& s = state.scratch;
    const Real rho0_2 = model.rho0 * model.rho0;
    const Real* c = s.pair_coefficient.data() + i * s.fluid_fluid.capacity;
    FluidGradientSums sums;
    int k = 0;
    s.fluid_fluid.for_each(i, [&](Index j) {
        const Vec3 g = (rho0_2 * c[k++]) * (f.x[i] - f.x[j]);
        sums.sum += g;
        sums.squares += g.squaredNorm();
    });
    return sums;
}

/// How the pressure of a boundary particle is read in a_i^p.
enum class BoundaryPressure {
    Hydrostatic,  ///< p_ik = max(p_i - rho0 g.x_ik, 0): the density solve (pcisph.cpp says why)
    Mirrored,     ///< p_ik = p_i: a velocity-level (divergence) pressure, which has no weight
};

/// a_i^p of fluid particle i for the pressures p (Pa), from the coefficients of this step; per
/// unit rho0 V, scaled to act on the true mass. Boundary terms vanish where p_i = 0.
inline Vec3 pressure_acceleration(const Model& model, const State& state,
                                  const std::vector<Real>& p, Index i, BoundaryPressure boundary) {
    const FluidParticles& f = state.fluid;
    const FluidScratch& s = state.scratch;
    const int cap_f = s.fluid_fluid.capacity, cap_w = s.fluid_wall.capacity,
              cap_p = s.fluid_porous.capacity;
    const Vec3 xi = f.x[i];
    const Real pi = p[i];
    Vec3 a = Vec3::Zero();
    const Real* cf = s.pair_coefficient.data() + i * cap_f;
    int k = 0;
    s.fluid_fluid.for_each(i, [&](Index j) { a -= ((pi + p[j]) * cf[k++]) * (xi - f.x[j]); });
    if (pi == 0) return a * (f.sph_mass[i] / f.mass[i]);
    const bool hydrostatic = boundary == BoundaryPressure::Hydrostatic;
    const BoundarySums& sums = s.boundary_sums;
    if (pi + (hydrostatic ? sums.lowest[i] : 0) >= 0) {
        // No p_ik is clamped: the sum is linear, 2 p_i sum_k c_ik x_ik + sum_k c_ik h_ik x_ik.
        a -= 2 * pi * sums.gradient[i];
        if (hydrostatic) a -= sums.hydrostatic[i];
        return a * (f.sph_mass[i] / f.mass[i]);
    }
    const Real* cw = s.wall_coefficient.data() + i * cap_w;
    const Real* hw = s.wall_hydrostatic.data() + i * cap_w;
    k = 0;
    s.fluid_wall.for_each(i, [&](Index w) {
        a -= boundary_pressure_term(pi, cw[k], hydrostatic ? hw[k] : 0, xi - model.walls.x[w]);
        ++k;
    });
    // Porous particles are boundary particles like walls (§4.3); their reaction is the same
    // term, summed on the fragment side (coupling/fluid_reactions.cpp).
    const std::vector<Vec3>& porous_x = state.porous.particles.x;
    const Real* cp = s.porous_coefficient.data() + i * cap_p;
    const Real* hp = s.porous_hydrostatic.data() + i * cap_p;
    k = 0;
    s.fluid_porous.for_each(i, [&](Index w) {
        a -= boundary_pressure_term(pi, cp[k], hydrostatic ? hp[k] : 0, xi - porous_x[w]);
        ++k;
    });
    return a * (f.sph_mass[i] / f.mass[i]);  // a force per unit rho0 V acting on the true mass
}

}  // namespace karst
