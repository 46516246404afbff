#include "karst/sph/pressure_acceleration.hpp"

#include "karst/core/parallel.hpp"

#include <algorithm>

namespace karst {

void pressure_pair_coefficients(const Model& model, State& state) {
    const FluidParticles& f = state.fluid;
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
    parallel_for(f.size(), [&](Index i) {
        Vec3 gradient = Vec3::Zero(), hydrostatic = Vec3::Zero();
        Real lowest = 0;
        const auto add = [&](Real c, Real h, const Vec3& xik) {
            gradient += c * xik, hydrostatic += (c * h) * xik, lowest = std::min(lowest, h);
        };
        int k = 0;
        s.fluid_fluid.for_each(i, [&](Index j) {
            s.pair_coefficient[i * cap_f + k++] =
                f.sph_mass[j] * inv_rho0_2 * W.dw_over_r((f.x[i] - f.x[j]).norm());
        });
        k = 0;
        s.fluid_wall.for_each(i, [&](Index w) {
            const Vec3 xik = f.x[i] - model.walls.x[w];
            s.wall_coefficient[i * cap_w + k] =
                boundary_pressure_coefficient(model.walls.psi[w], inv_rho0_2, W, xik);
            s.wall_hydrostatic[i * cap_w + k] = -rho0_g.dot(xik);
            add(s.wall_coefficient[i * cap_w + k], s.wall_hydrostatic[i * cap_w + k], xik);
            ++k;
        });
        k = 0;
        s.fluid_porous.for_each(i, [&](Index w) {
            const Vec3 xik = f.x[i] - porous.x[w];
            s.porous_coefficient[i * cap_p + k] =
                boundary_pressure_coefficient(psi[w], inv_rho0_2, W, xik);
            s.porous_hydrostatic[i * cap_p + k] = -rho0_g.dot(xik);
            add(s.porous_coefficient[i * cap_p + k], s.porous_hydrostatic[i * cap_p + k], xik);
            ++k;
        });
        sums.gradient[i] = gradient, sums.hydrostatic[i] = hydrostatic, sums.lowest[i] = lowest;
    });
}

}  // namespace karst
