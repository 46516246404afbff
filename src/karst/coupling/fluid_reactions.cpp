#include "karst/coupling/fluid_reactions.hpp"

#include "karst/core/parallel.hpp"
#include "karst/coupling/boundary_pair.hpp"

namespace karst {

void compute_fluid_reactions(const Model& model, State& state) {
    const FluidParticles& f = state.fluid;
    const PorousParticles& porous = state.porous.particles;
    PorousScratch& s = state.porous_scratch;
    const FluidSettings& fs = model.scene.fluid;
    const BoundaryShear shear{fs.wall_friction, fs.adhesion, fs.sound_speed, model.h};
    const CubicKernel& W = model.kernel;
    const Real inv_rho0_2 = 1 / (model.rho0 * model.rho0);
    const Vec3 rho0_g = model.rho0 * model.scene.gravity;
    s.force.assign(porous.size(), Vec3::Zero());
    parallel_for(porous.size(), [&](Index k) {
        Vec3 force = Vec3::Zero();
        // The porous-fluid list reaches at least h; pairs beyond h carry no force.
        s.porous_fluid.for_each(k, [&](Index i) {
            const Vec3 x_ik = f.x[i] - porous.x[k];
            Vec3 a_on_i = Vec3::Zero();
            if (f.p[i] != 0 || f.p_divergence[i] != 0) {
                const Real c = boundary_pressure_coefficient(s.psi[k], inv_rho0_2, W, x_ik);
                if (f.p[i] != 0)
                    a_on_i -= boundary_pressure_term(f.p[i], c, -rho0_g.dot(x_ik), x_ik);
                // DFSPH's divergence pressure acts on the boundary mirrored
                // (sph/pressure_acceleration.hpp).
                if (f.p_divergence[i] != 0)
                    a_on_i -= boundary_pressure_term(f.p_divergence[i], c, 0, x_ik);
            }
            if (shear.any())
                a_on_i += boundary_shear_acceleration(shear, W, x_ik, f.v[i] - porous.v[k],
                                                      f.rho[i], s.psi[k]);
            force -= f.sph_mass[i] * a_on_i;  // = m_i times the fluid side's acceleration
        });
        s.force[k] = force;
    });
}

}  // namespace karst
