#include "karst/sph/non_pressure_forces.hpp"

#include "karst/core/parallel.hpp"
#include "karst/coupling/boundary_pair.hpp"

namespace karst {

namespace {

/// Akinci 2013 surface normal n_i = h sum_j (m_j / rho_j) grad W_ij (dimensionless).
void compute_normals(const Model& model, State& state) {
    const FluidParticles& f = state.fluid;
    FluidScratch& s = state.scratch;
    s.normal.resize(f.size());
    parallel_for(f.size(), [&](Index i) {
        Vec3 n = Vec3::Zero();
        s.fluid_fluid.for_each(i, [&](Index j) {
            n += (f.sph_mass[j] / f.rho[j]) * model.kernel.gradient(f.x[i] - f.x[j]);
        });
        s.normal[i] = model.h * n;
    });
}

}  // namespace

void compute_non_pressure_forces(const Model& model, State& state) {
    const FluidSettings& fs = model.scene.fluid;
    const bool tension = fs.surface_tension > 0;
    const BoundaryShear shear{fs.wall_friction, fs.adhesion, fs.sound_speed, model.h};
    const PorousParticles& porous = state.porous.particles;
    const std::vector<Real>& psi = state.porous_scratch.psi;
    if (tension) compute_normals(model, state);
    const FluidParticles& f = state.fluid;
    FluidScratch& s = state.scratch;
    const CubicKernel& W = model.kernel;
    const Real h = model.h, eps = 0.01 * h * h, rho0 = model.rho0;
    const Real visc = (3 + 2) * fs.viscosity;
    // Becker & Teschner 2007: Pi_ij = -nu_a min(v_ij.x_ij, 0) / (r^2 + 0.01 h^2) with
    // nu_a = 2 alpha_v h c_s / (rho_i + rho_j); a_i = -sum_j m_j Pi_ij grad W_ij.
    const Real artificial = 2 * fs.artificial_viscosity * h * fs.sound_speed;
    const Real rho0_2 = rho0 * rho0;
    const int cap_f = s.fluid_fluid.capacity;
    s.a_other.resize(f.size());
    parallel_for(f.size(), [&](Index i) {
        const Vec3 xi = f.x[i], vi = f.v[i];
        const Real rho_i = f.rho[i];
        Vec3 a = Vec3::Zero();
        // m_j grad W_ij from the step's pair factors (pressure_acceleration.hpp).
        const Real* cf = s.pair_coefficient.data() + i * cap_f;
        int k = 0;
        s.fluid_fluid.for_each(i, [&](Index j) {
            const Vec3 xij = xi - f.x[j];
            const Real r2 = xij.squaredNorm();
            const Vec3 m_grad = (rho0_2 * cf[k++]) * xij;
            const Real vx = (vi - f.v[j]).dot(xij);
            a += (visc * (1 / rho_i + 1 / f.rho[j]) * vx / (r2 + eps)) * m_grad;
            if (vx < 0) a += (artificial / (rho_i + f.rho[j]) * vx / (r2 + eps)) * m_grad;
            if (tension) {
                // Akinci 2013: K_ij (cohesion + curvature), per unit mass of i.
                const Real r = std::sqrt(r2);
                const Real k_ij = 2 * rho0 / (rho_i + f.rho[j]);
                Vec3 fc = Vec3::Zero();
                if (r > 1e-9 * h)
                    fc = (-fs.surface_tension * f.sph_mass[j] * cohesion_kernel(r, h) / r) * xij;
                fc -= fs.surface_tension * (s.normal[i] - s.normal[j]);
                a += k_ij * fc;
            }
        });
        if (shear.any()) {
            // Friction and adhesion with walls (at rest) and porous particles (moving with their
            // fragment); the porous reactions are summed in coupling/fluid_reactions.cpp.
            s.fluid_wall.for_each(i, [&](Index k) {
                a += boundary_shear_acceleration(shear, W, xi - model.walls.x[k], vi, rho_i,
                                                 model.walls.psi[k]);
            });
            s.fluid_porous.for_each(i, [&](Index k) {
                a += boundary_shear_acceleration(shear, W, xi - porous.x[k], vi - porous.v[k],
                                                 rho_i, psi[k]);
            });
        }
        // Forces per unit rho0 V act on the true mass; gravity on every kilogram.
        s.a_other[i] = model.scene.gravity + (f.sph_mass[i] / f.mass[i]) * a;
    });
}

}  // namespace karst
