#include "karst/sph/integrate.hpp"

#include "karst/core/parallel.hpp"

#include <algorithm>
#include <cmath>

namespace karst {

namespace {

/// How far a particle pushed back through a wall lands inside its surface, in spacings: the
/// fluid lattice starts half a spacing inside, so a quarter keeps it clear of the wall skin.
constexpr Real k_push_back_depth = 0.25;

/// The outward normal of a wall's fluid side at x: the gradient of the signed distance of the
/// region the fluid may not enter (central differences; unit length or zero).
Vec3 outward_normal(const Wall& wall, const Vec3& x, Real step) {
    const Real sign = wall.kind == Wall::Kind::Container ? 1 : -1;
    Vec3 g;
    for (int d = 0; d < 3; ++d) {
        Vec3 e = Vec3::Zero();
        e[d] = step;
        g[d] = sign * (wall.shape.signed_distance(x + e) - wall.shape.signed_distance(x - e));
    }
    const Real norm = g.norm();
    return norm > 0 ? Vec3(g / norm) : Vec3::Zero();
}

/// A fluid particle that crossed a wall's surface in this step (a container's cavity left, an
/// obstacle entered) is put back a quarter spacing inside and loses its outward normal velocity,
/// an inelastic contact that cannot add energy. Returns whether it was.
bool push_back_through_walls(const Model& model, Vec3& x, Vec3& v) {
    bool pushed = false;
    for (const Wall& wall : model.scene.walls) {
        const Real d = wall.shape.signed_distance(x);
        const Real outside =
            wall.kind == Wall::Kind::Container ? d : -d;  // > 0: on the wall's side
        if (!(outside > 0)) continue;
        const Vec3 n = outward_normal(wall, x, 0.1 * model.dx);
        x -= (outside + k_push_back_depth * model.dx) * n;
        v -= std::max(v.dot(n), Real(0)) * n;
        pushed = true;
    }
    return pushed;
}

}  // namespace

Real integrate_fluid(const Model& model, State& state, Real dt) {
    FluidParticles& f = state.fluid;
    const FluidScratch& s = state.scratch;
    const Index n = f.size();
    std::vector<char> keep(n);
    std::vector<Index> escaped(n, 0), pushed(n, 0);
    parallel_for(n, [&](Index i) {
        f.v[i] += dt * (s.a_other[i] + s.a_pressure[i]);
        f.x[i] += dt * f.v[i];
        pushed[i] = push_back_through_walls(model, f.x[i], f.v[i]);
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
                                   Real dt_max) {
    if (!converged)
        state.dt_solver_limit = 0.5 * dt;
    else if (shortened)
        state.dt_solver_limit = dt;
    else if (state.dt_solver_limit < dt_max)
        state.dt_solver_limit *= 1.1;
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
    if (v_max > 0) dt = std::min(dt, t.cfl * model.dx / v_max);
    if (state.a_max > 0) dt = std::min(dt, 0.25 * std::sqrt(model.dx / state.a_max));
    return std::min(dt, state.dt_solver_limit);
}

}  // namespace karst
