#include "karst/sph/non_pressure_forces.hpp"

#include "karst/core/parallel.hpp"

namespace karst {

namespace {

/// Akinci 2013 surface normal n_i = h sum_j (m_j / rho_j) grad W_ij (dimensionless).
void compute_normals(const Model& model, State& state) {
    const FluidParticles& f = state.fluid;
    FluidScratch& s = state.scratch;
    s.normal.resize(f.size());
    parallel_for(f.size(), [&](Index i) {
        Vec3 n = Vec3::Zero();
        s.fluid_fluid.for_each(i, [&](Index j) { n += (f.mass[j] / f.rho[j]) * model.kernel.gradient(f.x[i] - f.x[j]); });
        s.normal[i] = model.h * n;
    });
}

}  // namespace

void compute_non_pressure_forces(const Model& model, State& state) {
    const FluidSettings& fs = model.scene.fluid;
    const bool tension = fs.surface_tension > 0, adhesion = fs.adhesion > 0, friction = fs.wall_friction > 0;
    if (tension) compute_normals(model, state);
    const FluidParticles& f = state.fluid;
    FluidScratch& s = state.scratch;
    const CubicKernel& W = model.kernel;
    const Real h = model.h, eps = 0.01 * h * h, rho0 = model.rho0;
    const Real visc = (3 + 2) * fs.viscosity;
    s.a_other.resize(f.size());
    parallel_for(f.size(), [&](Index i) {
        const Vec3 xi = f.x[i], vi = f.v[i];
        const Real rho_i = f.rho[i];
        Vec3 a = model.scene.gravity;
        s.fluid_fluid.for_each(i, [&](Index j) {
            const Vec3 xij = xi - f.x[j];
            const Real r2 = xij.squaredNorm();
            const Vec3 grad = xij * W.dw_over_r(std::sqrt(r2));
            const Real vx = (vi - f.v[j]).dot(xij);
            a += (visc * f.mass[j] * (1 / rho_i + 1 / f.rho[j]) * vx / (r2 + eps)) * grad;
            if (tension) {
                // Akinci 2013: K_ij (cohesion + curvature), per unit mass of i.
                const Real r = std::sqrt(r2);
                const Real k_ij = 2 * rho0 / (rho_i + f.rho[j]);
                Vec3 fc = Vec3::Zero();
                if (r > 1e-9 * h) fc = (-fs.surface_tension * f.mass[j] * cohesion_kernel(r, h) / r) * xij;
                fc -= fs.surface_tension * (s.normal[i] - s.normal[j]);
                a += k_ij * fc;
            }
        });
        if (adhesion || friction) {
            // Akinci 2012 friction: nu_b = sigma_f h c_s / (2 rho_i).
            const Real nu_b = fs.wall_friction * h * fs.sound_speed / (2 * rho_i);
            s.fluid_wall.for_each(i, [&](Index k) {
                const Vec3 xik = xi - model.walls.x[k];
                const Real r2 = xik.squaredNorm(), r = std::sqrt(r2);
                const Real psi = model.walls.psi[k];
                if (friction) {
                    const Real pi_ik = -nu_b * std::min(vi.dot(xik), Real(0)) / (r2 + eps);
                    a -= (psi * pi_ik * W.dw_over_r(r)) * xik;
                }
                if (adhesion && r > 1e-9 * h) a -= (fs.adhesion * psi * adhesion_kernel(r, h) / r) * xik;
            });
        }
        s.a_other[i] = a;
    });
}

}  // namespace karst
