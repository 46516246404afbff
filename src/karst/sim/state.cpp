#include "karst/sim/state.hpp"

#include "karst/core/soa.hpp"
#include "karst/pfem/structure_stages.hpp"
#include "karst/sim/model.hpp"
#include "karst/sim/porous_materials.hpp"

namespace karst {

namespace {

/// Porous particles of every solid (docs/method.md §2) and one fragment per solid (§4.5), at rest
/// or with a free solid's initial velocity and spin.
void make_porous(const Model& model, PorousState& porous, std::int64_t& next_id) {
    PorousParticles& p = porous.particles;
    for (const PorousBody& body : model.porous) {
        const PorousSolid& solid = model.scene.porous_solids[body.solid];
        const Index first = p.size(), fragment = Index(porous.fragments.size());
        append_attributes(p, porous_particles_at_rest(model, body, fragment));
        const Index n = p.size() - first;
        for (Index i = first; i < p.size(); ++i) p.id[i] = p.origin[i] = next_id++;
        std::vector<Real> mass(n);
        for (Index i = 0; i < n; ++i)
            mass[i] = p.solid_mass[first + i] + p.absorbed_mass[first + i];
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
    // Porous particles take the first ids, so the structure side's per-id arrays stay short.
    make_porous(model, s.porous, s.next_id);
    const size_t n = model.initial_x.size();
    FluidParticles& f = s.fluid;
    resize_attributes(f, n);
    f.x = model.initial_x;
    f.v = model.initial_v;
    for (size_t i = 0; i < n; ++i) {
        f.mass[i] = f.sph_mass[i] = model.particle_mass;
        f.solute[i] = model.initial_concentration[i] * model.particle_mass;
        f.rho[i] = model.rho0;
        f.id[i] = s.next_id++;
    }
    build_structures(model, s);
    return s;
}

}  // namespace karst
