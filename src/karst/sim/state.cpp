#include "karst/sim/state.hpp"

#include "karst/core/soa.hpp"
#include "karst/pfem/structure_stages.hpp"
#include "karst/sim/model.hpp"
#include "karst/sim/porous_materials.hpp"

namespace karst {

void FluidParticles::keep(const std::vector<char>& flag) {
    keep_flagged(x, flag), keep_flagged(v, flag), keep_flagged(mass, flag), keep_flagged(solute, flag), keep_flagged(drained, flag);
    keep_flagged(sph_mass, flag);
    keep_flagged(rho, flag), keep_flagged(p, flag), keep_flagged(p_divergence, flag), keep_flagged(id, flag);
}

void FluidParticles::permute(const std::vector<std::uint32_t>& perm) {
    apply_permutation(x, perm), apply_permutation(v, perm), apply_permutation(mass, perm), apply_permutation(solute, perm);
    apply_permutation(drained, perm), apply_permutation(sph_mass, perm);
    apply_permutation(rho, perm), apply_permutation(p, perm), apply_permutation(p_divergence, perm), apply_permutation(id, perm);
}

namespace {

/// Porous particles of every solid (method.md §2) and one fragment per solid (§4.5), at rest or
/// with a free solid's initial velocity and spin.
void make_porous(const Model& model, PorousState& porous) {
    PorousParticles& p = porous.particles;
    for (const PorousBody& body : model.porous) {
        const PorousSolid& solid = model.scene.porous_solids[body.solid];
        const Index first = p.size(), fragment = Index(porous.fragments.size());
        p.append(porous_particles_at_rest(model, body, fragment));
        const Index n = p.size() - first;
        for (Index i = first; i < p.size(); ++i) p.id[i] = i;
        std::vector<Real> mass(n);
        for (Index i = 0; i < n; ++i) mass[i] = p.solid_mass[first + i] + p.absorbed_mass[first + i];
        std::vector<Vec3> rest;
        Fragment f = fragment_at_rest({p.x.data() + first, size_t(n)}, mass, rest, model.dx);
        std::copy(rest.begin(), rest.end(), p.rest.begin() + first);
        f.anchored = solid.anchored;
        if (!f.anchored) {
            f.velocity = solid.velocity;
            f.angular_momentum = f.world_inertia() * solid.angular_velocity;
            for (Index i = first; i < p.size(); ++i) p.v[i] = f.point_velocity(p.x[i]);
        }
        porous.fragments.push_back(f);
    }
}

}  // namespace

State make_initial_state(const Model& model) {
    State s;
    const size_t n = model.initial_x.size();
    s.fluid.x = model.initial_x;
    s.fluid.v = model.initial_v;
    s.fluid.mass.assign(n, model.particle_mass);
    s.fluid.solute.resize(n);
    s.fluid.drained.assign(n, 0);
    s.fluid.sph_mass = s.fluid.mass;
    for (size_t i = 0; i < n; ++i) s.fluid.solute[i] = model.initial_concentration[i] * model.particle_mass;
    s.fluid.rho.assign(n, model.rho0);
    s.fluid.p.assign(n, 0);
    s.fluid.p_divergence.assign(n, 0);
    s.fluid.id.resize(n);
    for (size_t i = 0; i < n; ++i) s.fluid.id[i] = std::int64_t(i);
    s.next_id = std::int64_t(n);
    make_porous(model, s.porous);
    build_structures(model, s);
    return s;
}

}  // namespace karst
