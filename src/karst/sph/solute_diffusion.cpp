#include "karst/sph/solute_diffusion.hpp"

#include "karst/core/parallel.hpp"

#include <cmath>

namespace karst {

Real diffuse_solute(const Model& model, State& state, Real dt) {
    FluidParticles& f = state.fluid;
    const Real D = model.scene.fluid.solute_diffusivity;
    const Index n = f.size();
    if (D <= 0 || n == 0) return 0;
    const bool any = parallel_max(n, Real(0), [&](Index i) { return f.solute[i]; }) > 0;
    if (!any) return 0;

    const CubicKernel& W = model.kernel;
    const Real eps = 0.01 * model.h * model.h;
    const Real needed = std::ceil(dt / (k_diffusion_substep * model.dx * model.dx / D));
    if (needed > k_max_diffusion_substeps) return needed;
    const int substeps = std::max(1, int(needed));
    const Real h_sub = dt / substeps;
    std::vector<Real> concentration(n), rate(n);
    for (int s = 0; s < substeps; ++s) {
        parallel_for(n, [&](Index i) { concentration[i] = f.solute[i] / f.mass[i]; });
        // M18 as a transfer into i: m_i m_j / (rho_i rho_j) 4 k_i k_j / (k_i + k_j)
        // (C_i - C_j) x_ij.grad W_ij / (r^2 + 0.01 h^2), kappa = rho D. The pair's terms are
        // evaluated in (min, max) index order, so both sides get bitwise opposite transfers.
        parallel_for(n, [&](Index i) {
            Real sum = 0;
            state.scratch.fluid_fluid.for_each(i, [&](Index j) {
                const Index lo = std::min(i, j), hi = std::max(i, j);
                const Vec3 x = f.x[lo] - f.x[hi];
                const Real r2 = x.squaredNorm();
                const Real x_grad_w = W.dw_over_r(std::sqrt(r2)) * r2;  // x.grad W = r dW/dr
                const Real kappa_lo = f.rho[lo] * D, kappa_hi = f.rho[hi] * D;
                const Real into_lo = f.mass[lo] * f.mass[hi] / (f.rho[lo] * f.rho[hi]) *
                                     (4 * kappa_lo * kappa_hi / (kappa_lo + kappa_hi)) *
                                     (concentration[lo] - concentration[hi]) * x_grad_w /
                                     (r2 + eps);
                sum += i == lo ? into_lo : -into_lo;
            });
            rate[i] = sum;
        });
        parallel_for(n, [&](Index i) { f.solute[i] += h_sub * rate[i]; });
    }
    return 0;
}

}  // namespace karst
