#include "karst/sim/state.hpp"

#include "karst/core/soa.hpp"
#include "karst/sim/model.hpp"

namespace karst {

void FluidParticles::keep(const std::vector<char>& flag) {
    keep_flagged(x, flag), keep_flagged(v, flag), keep_flagged(mass, flag), keep_flagged(solute, flag);
    keep_flagged(rho, flag), keep_flagged(p, flag), keep_flagged(id, flag);
}

void FluidParticles::permute(const std::vector<std::uint32_t>& perm) {
    apply_permutation(x, perm), apply_permutation(v, perm), apply_permutation(mass, perm), apply_permutation(solute, perm);
    apply_permutation(rho, perm), apply_permutation(p, perm), apply_permutation(id, perm);
}

State make_initial_state(const Model& model) {
    State s;
    const size_t n = model.initial_x.size();
    s.fluid.x = model.initial_x;
    s.fluid.v = model.initial_v;
    s.fluid.mass.assign(n, model.particle_mass);
    s.fluid.solute.resize(n);
    for (size_t i = 0; i < n; ++i) s.fluid.solute[i] = model.initial_concentration[i] * model.particle_mass;
    s.fluid.rho.assign(n, model.rho0);
    s.fluid.p.assign(n, 0);
    s.fluid.id.resize(n);
    for (size_t i = 0; i < n; ++i) s.fluid.id[i] = std::int64_t(i);
    s.next_id = std::int64_t(n);
    return s;
}

}  // namespace karst
