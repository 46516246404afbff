// THE order of the stages of one time step (method.md §3, style.md P2). Every stage is timed
// into the profile and followed by the watchdog's check of what it wrote.
#include "karst/sim/step.hpp"

#include "karst/core/timer.hpp"
#include "karst/sim/watchdog.hpp"
#include "karst/sph/density.hpp"
#include "karst/sph/fluid_neighbours.hpp"
#include "karst/sph/integrate.hpp"
#include "karst/sph/non_pressure_forces.hpp"
#include "karst/sph/pcisph.hpp"
#include "karst/sph/solute_diffusion.hpp"

namespace karst {

namespace {
template <class F>
auto timed(StepProfile& profile, Stage stage, const F& f) {
    Stopwatch watch;
    if constexpr (std::is_void_v<decltype(f())>) {
        f();
        profile[stage] += watch.seconds();
    } else {
        auto r = f();
        profile[stage] += watch.seconds();
        return r;
    }
}
}  // namespace

StepReport step(const Model& model, State& state, Real dt, StepProfile& profile) {
    const Real t = state.time;
    const auto& id = state.fluid.id;

    // 1. Neighbour search (and periodic Morton reordering).
    timed(profile, Stage::Neighbours, [&] { update_fluid_neighbours(model, state); });

    // 2. Fluid densities with the wall contribution (M7).
    timed(profile, Stage::Density, [&] { update_density(model, state); });
    check_scalars(state.fluid.rho, id, Stage::Density, t, "density");

    // 2b. Solute diffusion among fluid particles (M18), on this step's densities and lists.
    timed(profile, Stage::SoluteDiffusion, [&] { diffuse_solute(model, state, dt); });
    check_scalars(state.fluid.solute, id, Stage::SoluteDiffusion, t, "solute mass");

    // 3. Gravity, viscosity, surface tension, adhesion, wall friction (§4.2).
    timed(profile, Stage::NonPressureForces, [&] { compute_non_pressure_forces(model, state); });
    check_vectors(state.scratch.a_other, id, Stage::NonPressureForces, t, "acceleration");

    // 4. PCISPH predict-correct loop (§4.3, M8).
    const PcisphReport pcisph = timed(profile, Stage::PressureSolve, [&] { return solve_pressure_pcisph(model, state, dt); });
    check_vectors(state.scratch.a_pressure, id, Stage::PressureSolve, t, "pressure acceleration");

    // 5. Symplectic Euler; particles leaving the domain are removed (§4.4).
    state.a_max = timed(profile, Stage::Integrate, [&] { return integrate_fluid(model, state, dt); });
    check_vectors(state.fluid.v, state.fluid.id, Stage::Integrate, t + dt, "velocity", model.scene.max_speed);
    check_vectors(state.fluid.x, state.fluid.id, Stage::Integrate, t + dt, "position");

    state.time = t + dt;
    state.dt = dt;
    ++state.steps;
    return {dt, pcisph.iterations, pcisph.max_density_error};
}

}  // namespace karst
