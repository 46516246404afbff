#include "karst/sph/density.hpp"

#include "karst/core/parallel.hpp"

namespace karst {

void compute_density(const Model& model, const State& state, const std::vector<Vec3>& x,
                     std::vector<Real>& rho) {
    const FluidParticles& f = state.fluid;
    const FluidScratch& s = state.scratch;
    const CubicKernel& W = model.kernel;
    const std::vector<Vec3>& porous_x = state.porous.particles.x;
    const std::vector<Real>& psi = state.porous_scratch.psi;
    rho.resize(f.size());
    parallel_for(f.size(), [&](Index i) {
        const Vec3 xi = x[i];
        Real sum = f.sph_mass[i] * W.w0();
        s.fluid_fluid.for_each(i, [&](Index j) { sum += f.sph_mass[j] * W.w((xi - x[j]).norm()); });
        s.fluid_wall.for_each(
            i, [&](Index k) { sum += model.walls.psi[k] * W.w((xi - model.walls.x[k]).norm()); });
        s.fluid_porous.for_each(i,
                                [&](Index k) { sum += psi[k] * W.w((xi - porous_x[k]).norm()); });
        rho[i] = sum;
    });
}

void update_density(const Model& model, State& state) {
    compute_density(model, state, state.fluid.x, state.fluid.rho);
}

}  // namespace karst
