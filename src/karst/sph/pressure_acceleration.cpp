#include "karst/sph/pressure_acceleration.hpp"

#include "karst/core/parallel.hpp"

#include <algorithm>

namespace karst {

void update_density_and_pair_coefficients(const Model& model, State& state) {
    FluidParticles& f = state.fluid;
    FluidScratch& s = state.scratch;
    const CubicKernel& W = model.kernel;
    const Real inv_rho0_2 = 1 / (model.rho0 * model.rho0);
    const Vec3 rho0_g = model.rho0 * model.scene.gravity;
    const PorousParticles& porous = state.porous.particles;
    const std::vector<Real>& psi = state.porous_scratch.psi;
    const int cap_f = s.fluid_fluid.capacity, cap_w = s.fluid_wall.capacity,
              cap_p = s.fluid_porous.capacity;
    s.pair_coefficient.resize(size_t(f.size()) * cap_f);
    s.wall_coefficient.resize(size_t(f.size()) * cap_w);
    s.wall_hydrostatic.resize(size_t(f.size()) * cap_w);
    s.porous_coefficient.resize(size_t(f.size()) * cap_p);
    s.porous_hydrostatic.resize(size_t(f.size()) * cap_p);
    BoundarySums& sums = s.boundary_sums;
    sums.gradient.resize(f.size()), sums.hydrostatic.resize(f.size()), sums.lowest.resize(f.size());
    f.rho.resize(f.size());
    parallel_for(f.size(), [&](Index i) {
        const Vec3 xi = f.x[i];
        Real rho = f.sph_mass[i] * W.w0();
        Vec3 gradient = Vec3::Zero(), hydrostatic = Vec3::Zero();
        Real lowest = 0;
        // One boundary pair: its density share, its coefficient c and h, and the sums of both.
        const auto boundary = [&](Real psi_k, const Vec3& xik, Real& c, Real& h) {
            const CubicKernel::ValueAndSlope ws = W.w_and_dw_over_r(xik.norm());
            rho += psi_k * ws.w;
            c = psi_k * inv_rho0_2 * ws.dw_over_r, h = -rho0_g.dot(xik);
            gradient += c * xik, hydrostatic += (c * h) * xik, lowest = std::min(lowest, h);
        };
        int k = 0;
        s.fluid_fluid.for_each(i, [&](Index j) {
            const CubicKernel::ValueAndSlope ws = W.w_and_dw_over_r((xi - f.x[j]).norm());
            rho += f.sph_mass[j] * ws.w;
            s.pair_coefficient[i * cap_f + k++] = f.sph_mass[j] * inv_rho0_2 * ws.dw_over_r;
        });
        k = 0;
        s.fluid_wall.for_each(i, [&](Index w) {
            boundary(model.walls.psi[w], xi - model.walls.x[w], s.wall_coefficient[i * cap_w + k],
                     s.wall_hydrostatic[i * cap_w + k]);
            ++k;
        });
        k = 0;
        s.fluid_porous.for_each(i, [&](Index w) {
            boundary(psi[w], xi - porous.x[w], s.porous_coefficient[i * cap_p + k],
                     s.porous_hydrostatic[i * cap_p + k]);
            ++k;
        });
        f.rho[i] = rho;
        sums.gradient[i] = gradient, sums.hydrostatic[i] = hydrostatic, sums.lowest[i] = lowest;
    });
}

}  // namespace karst
