#include "karst/coupling/fragment_response.hpp"

#include "karst/core/parallel.hpp"
#include "karst/coupling/boundary_pair.hpp"

namespace karst {

FragmentResponse::FragmentResponse(const Model& model, const State& state, Real dt,
                                   bool with_gravity, const std::vector<Real>* earlier)
    : m_dt(dt) {
    const std::vector<Fragment>& fragments = state.porous.fragments;
    const PorousParticles& porous = state.porous.particles;
    for (Index k = 0; k < porous.size() && !m_active; ++k) {
        const Fragment& fr = fragments[porous.fragment[k]];
        m_active = !fr.anchored && fr.mass > 0 && state.porous_scratch.porous_fluid.count[k] > 0;
    }
    if (!m_active) return;
    const size_t nf = fragments.size();
    m_velocity.resize(nf), m_angular_momentum.resize(nf), m_inverse_inertia.resize(nf);
    for (size_t f = 0; f < nf; ++f) {
        const Fragment& fr = fragments[f];
        m_velocity[f] =
            fr.velocity + (with_gravity ? Vec3(dt * model.scene.gravity) : Vec3::Zero());
        m_angular_momentum[f] = fr.angular_momentum;
        m_inverse_inertia[f] = fr.mass > 0 ? Mat3(fr.world_inertia().inverse()) : Mat3::Zero();
    }
    if (earlier) {
        std::vector<Vec3> force(nf, Vec3::Zero()), torque(nf, Vec3::Zero());
        add_reactions(model, state, *earlier, BoundaryPressure::Mirrored, force, torque);
        for (size_t f = 0; f < nf; ++f) {
            if (fragments[f].anchored || fragments[f].mass <= 0) continue;
            m_velocity[f] += dt * force[f] / fragments[f].mass;
            m_angular_momentum[f] += dt * torque[f];
        }
    }
}

void FragmentResponse::add_reactions(const Model& model, const State& state,
                                     const std::vector<Real>& p, BoundaryPressure boundary,
                                     std::vector<Vec3>& force, std::vector<Vec3>& torque) const {
    const FluidParticles& fluid = state.fluid;
    const PorousParticles& porous = state.porous.particles;
    const PorousScratch& s = state.porous_scratch;
    const std::vector<Fragment>& fragments = state.porous.fragments;
    const CubicKernel& W = model.kernel;
    const Real inv_rho0_2 = 1 / (model.rho0 * model.rho0);
    const Vec3 rho0_g = model.rho0 * model.scene.gravity;
    const bool hydrostatic = boundary == BoundaryPressure::Hydrostatic;
    m_member_force.assign(porous.size(), Vec3::Zero());
    // The same pair term as the fluid side's a_i^p (and coupling/fluid_reactions.cpp), so the
    // fragment is predicted to take exactly what the fluid loses.
    parallel_for(porous.size(), [&](Index k) {
        const Fragment& fr = fragments[porous.fragment[k]];
        if (fr.anchored || fr.mass <= 0) return;
        Vec3 sum = Vec3::Zero();
        s.porous_fluid.for_each(k, [&](Index i) {
            if (p[i] == 0) return;
            const Vec3 x_ik = fluid.x[i] - porous.x[k];
            const Real c = boundary_pressure_coefficient(s.psi[k], inv_rho0_2, W, x_ik);
            sum += fluid.sph_mass[i] *
                   boundary_pressure_term(p[i], c, hydrostatic ? -rho0_g.dot(x_ik) : 0, x_ik);
        });
        m_member_force[k] = sum;
    });
    for (Index k = 0; k < porous.size(); ++k) {
        const Index f = porous.fragment[k];
        force[f] += m_member_force[k];
        torque[f] += (porous.x[k] - fragments[f].centre).cross(m_member_force[k]);
    }
}

void FragmentResponse::member_velocities(const Model& model, const State& state,
                                         const std::vector<Real>& p, BoundaryPressure boundary,
                                         std::vector<Vec3>& v) const {
    const PorousParticles& porous = state.porous.particles;
    const std::vector<Fragment>& fragments = state.porous.fragments;
    const size_t nf = fragments.size();
    std::vector<Vec3> force(nf, Vec3::Zero()), torque(nf, Vec3::Zero());
    add_reactions(model, state, p, boundary, force, torque);
    std::vector<Vec3> velocity(nf), omega(nf);
    for (size_t f = 0; f < nf; ++f) {
        if (fragments[f].anchored || fragments[f].mass <= 0) continue;
        velocity[f] = m_velocity[f] + m_dt * force[f] / fragments[f].mass;
        omega[f] = m_inverse_inertia[f] * (m_angular_momentum[f] + m_dt * torque[f]);
    }
    v.resize(porous.size());
    parallel_for(porous.size(), [&](Index k) {
        const Index f = porous.fragment[k];
        const Fragment& fr = fragments[f];
        v[k] = fr.anchored || fr.mass <= 0
                   ? porous.v[k]
                   : Vec3(velocity[f] + omega[f].cross(porous.x[k] - fr.centre));
    });
}

FragmentMobility::FragmentMobility(const State& state) {
    const std::vector<Fragment>& fragments = state.porous.fragments;
    m_inverse_inertia.assign(fragments.size(), Mat3::Zero());
    for (size_t q = 0; q < fragments.size(); ++q)
        if (!fragments[q].anchored && fragments[q].mass > 0)
            m_inverse_inertia[q] = fragments[q].world_inertia().inverse();
}

Real FragmentMobility::at(const Model& model, const State& state, Index i) const {
    const FluidScratch& s = state.scratch;
    const PorousParticles& porous = state.porous.particles;
    const std::vector<Fragment>& fragments = state.porous.fragments;
    const Real rho0_2 = model.rho0 * model.rho0;
    const Vec3 xi = state.fluid.x[i];
    const Real* cp = s.porous_coefficient.data() + i * s.fluid_porous.capacity;
    int k = 0;
    // The free fragments touched, in list order (a particle touches one or two).
    Index touched[4];
    Vec3 push[4], turn[4];
    int n_touched = 0;
    s.fluid_porous.for_each(i, [&](Index w) {
        const Vec3 g = (rho0_2 * cp[k++]) * (xi - porous.x[w]);  // Psi_k grad W_ik
        const Index q = porous.fragment[w];
        if (fragments[q].anchored || fragments[q].mass <= 0) return;
        int slot = 0;
        while (slot < n_touched && touched[slot] != q) ++slot;
        if (slot == n_touched) {
            if (n_touched == 4) return;  // more: the mobility is a little small
            touched[slot] = q, push[slot] = turn[slot] = Vec3::Zero(), ++n_touched;
        }
        push[slot] += 2 * g;
        turn[slot] += (porous.x[w] - fragments[q].centre).cross(2 * g);
    });
    Real mobility = 0;
    for (int slot = 0; slot < n_touched; ++slot)
        mobility += push[slot].squaredNorm() / fragments[touched[slot]].mass +
                    turn[slot].dot(m_inverse_inertia[touched[slot]] * turn[slot]);
    return mobility;
}

}  // namespace karst
