#include "karst/sph/integrate.hpp"

#include "karst/core/parallel.hpp"
#include "karst/scene/wall_crossing.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace karst {

Real integrate_fluid(const Model& model, State& state, Real dt) {
    FluidParticles& f = state.fluid;
    const FluidScratch& s = state.scratch;
    const Index n = f.size();
    std::vector<char> keep(n);
    std::vector<Index> escaped(n, 0), pushed(n, 0);
    parallel_for(n, [&](Index i) {
        f.v[i] += dt * (s.a_other[i] + s.a_pressure[i]);
        f.x[i] += dt * f.v[i];
        pushed[i] = push_back_through_walls(model.scene.walls, model.dx, f.x[i], f.v[i]);
        // Particles drained into the porous solid (mass 0, porous/drained_fluid.hpp) go too.
        const bool inside = model.domain.contains(f.x[i]);
        escaped[i] = !inside && f.mass[i] > 0;
        keep[i] = inside && f.mass[i] > 0;
    });
    const Real a_max = parallel_max(n, 0.0, [&](Index i) { return s.a_other[i].norm(); });
    for (Index p : pushed) state.pushed_back += p;
    const Index kept = std::count(keep.begin(), keep.end(), 1);
    if (kept != n) {
        for (Index e : escaped) state.removed += e;
        keep_attributes(f, keep);
    }
    return a_max;
}

void update_solver_time_step_limit(State& state, Real dt, bool shortened, bool converged,
                                   Real dt_max, Real dt_rate) {
    if (!converged)
        state.dt_solver_limit = std::max(0.5 * dt, std::min(dt, dt_rate));
    else if (shortened)
        state.dt_solver_limit = dt;
    else if (state.dt_solver_limit < dt_max)
        state.dt_solver_limit *= 1.1;
}

Real artificial_kinematic_viscosity(const FluidSettings& fluid, Real dx) {
    const Real h = 2 * dx;  // the support radius, as Model::h
    return fluid.artificial_viscosity * h * fluid.sound_speed / 20;
}

Real viscous_step_limit(const FluidSettings& fluid, Real dx) {
    const Real nu = fluid.viscosity + artificial_kinematic_viscosity(fluid, dx);
    return nu > 0 ? k_viscous_step * dx * dx / nu : std::numeric_limits<Real>::infinity();
}

Real sound_crossing_time(const FluidSettings& fluid, Real dx) {
    return dx / fluid.sound_speed;
}

Real solve_rate_fraction(const FluidSettings& fluid, Real dx, Real dt) {
    return dt > 0 ? std::min(Real(1), dt / sound_crossing_time(fluid, dx)) : Real(1);
}

Real cfl_time_step(const Model& model, const State& state) {
    const TimeSettings& t = model.scene.time;
    if (t.fixed_dt) return *t.fixed_dt;
    const FluidParticles& f = state.fluid;
    const PorousParticles& p = state.porous.particles;
    const Real v_max = std::sqrt(
        std::max(parallel_max(f.size(), 0.0, [&](Index i) { return f.v[i].squaredNorm(); }),
                 parallel_max(p.size(), 0.0, [&](Index i) { return p.v[i].squaredNorm(); })));
    Real dt = t.dt_max;
    if (f.size() > 0) dt = std::min(dt, viscous_step_limit(model.scene.fluid, model.dx));
    if (v_max > 0) dt = std::min(dt, t.cfl * model.dx / v_max);
    if (state.a_max > 0) dt = std::min(dt, 0.25 * std::sqrt(model.dx / state.a_max));
    const Real p_max = parallel_max(f.size(), 0.0, [&](Index i) { return f.p[i]; });
    if (p_max > 0) dt = std::min(dt, 0.5 * model.dx * std::sqrt(model.rho0 / p_max));
    return std::min(dt, state.dt_solver_limit);
}

}  // namespace karst
