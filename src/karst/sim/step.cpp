// THE order of the stages of one time step: Algorithm 1 (docs/method.md §3) and, after the rigid
// update, Algorithm 2 (§5). Every stage is timed into the profile and followed by the watchdog's
// check of what it wrote. Numbers are the sheet's §3 steps; two run earlier than the sheet
// lists them: solute diffusion (10) and the pore flow (8) use the neighbour lists of the step's
// start positions, so they run before anything moves (5-7).
#include "karst/sim/step.hpp"

#include "karst/core/check.hpp"
#include "karst/core/timer.hpp"
#include "karst/coupling/fluid_reactions.hpp"
#include "karst/coupling/porous_boundary_volumes.hpp"
#include "karst/coupling/porous_neighbours.hpp"
#include "karst/pfem/fracture_stage.hpp"
#include "karst/pfem/merge_stage.hpp"
#include "karst/pfem/structure_stages.hpp"
#include "karst/porous/dissolution.hpp"
#include "karst/porous/drained_fluid.hpp"
#include "karst/porous/pore_flow.hpp"
#include "karst/rigid/fragment_motion.hpp"
#include "karst/sim/watchdog.hpp"
#include "karst/sph/fluid_neighbours.hpp"
#include "karst/sph/integrate.hpp"
#include "karst/sph/non_pressure_forces.hpp"
#include "karst/sph/pcisph.hpp"
#include "karst/sph/pressure_acceleration.hpp"
#include "karst/sph/solute_diffusion.hpp"

#include <fmt/format.h>

#include <cmath>

namespace karst {

namespace {

/// How often a step whose pressure solve did not converge is retried at half its length.
constexpr int k_max_step_halvings = 4;
/// A step is repeated shorter when its solve leaves more compression than this (or than the
/// scene's tolerance, if looser): halving a step undoes the compression its motion makes, not
/// compression the fluid already had, which a shorter step removes faster and throws out harder.
/// So a tolerance stricter than 1 % buys iterations, never shorter steps.
constexpr Real k_step_density_error = 0.01;

/// [D] How often a Biot call is repeated at once after a fracture (each time with up to N_crack
/// new cracks per structure): a crack runs on while the stress at its tip stays over the
/// strength, and a piece hanging by a neck of a few elements breaks off in the call instead of
/// swinging metres out under a small-strain solution. Up to k_fracture_rounds always, and up to
/// k_max_fracture_rounds while some node would move over a spacing in the call.
constexpr int k_fracture_rounds = 4, k_max_fracture_rounds = 32;

/// Runs one stage of the step at time t, timed into the profile; a numerical failure in it
/// becomes the watchdog's error, naming the stage.
template <class F>
auto timed(StepProfile& profile, Real t, Stage stage, const F& f) {
    Stopwatch watch;
    try {
        if constexpr (std::is_void_v<decltype(f())>) {
            f();
            profile[stage] += watch.seconds();
        } else {
            auto r = f();
            profile[stage] += watch.seconds();
            return r;
        }
    } catch (const NumericalFailure& e) {
        throw WatchdogError(k_stage_names[size_t(stage)], t, e.what());
    }
}

/// §3 step 8 at the step's start positions (where the neighbour lists were built): the pore
/// flow among porous particles and with fluid particles, then the deletion of drained fluid.
void pore_flow_and_absorption(const Model& model, State& state, Real dt) {
    PorousState& porous = state.porous;
    PorousScratch& s = state.porous_scratch;
    FluidExchange fluid{state.fluid, s.porous_fluid, model.particle_mass};
    if (!s.flow)
        s.flow.emplace(model.pore_laws, model.h, model.dx,
                       model.scene.paper_eq20 ? PairFlux::PaperEq20 : PairFlux::Darcy);
    PoreFlow& flow = *s.flow;
    if (s.pairs_stale) {
        CellRanges cells;
        NeighbourLists candidates;
        sort_into_cells(model.porous_grid, porous.particles.x, cells);
        find_neighbours(model.porous_grid, porous.particles.x, cells, true, candidates);
        s.fragment_pairs = flow.pairs(porous.particles, candidates, PairSelection::SameFragment);
        s.pairs_stale = false;
    }
    // Fragments in contact exchange water too (r < 1.1 dx), through pairs found anew each step.
    const bool several = state.porous.fragments.size() > 1;
    const PoreFlowReport report =
        several ? flow.advance(
                      porous.particles,
                      merge_pairs(s.fragment_pairs, flow.pairs(porous.particles, s.porous_porous,
                                                               PairSelection::AcrossFragments)),
                      dt, &fluid)
                : flow.advance(porous.particles, s.fragment_pairs, dt, &fluid);
    porous.absorbed += report.absorbed;
    porous.pore_substeps += report.substeps;
    if (report.substeps_needed > 0)
        throw WatchdogError(
            k_stage_names[size_t(Stage::PoreFlow)], state.time,
            fmt::format("the pore flow needs {:.3g} explicit sub-steps in a step of {:.3g} s (at "
                        "most {:g}): the pore water is too stiff for its mobility (lower "
                        "pore_stiffness or permeability, or raise darcy_viscosity)",
                        report.substeps_needed, dt, k_max_pore_substeps));
    porous.fluid_deleted +=
        drain_fluid_particles(state.fluid, porous.particles, report.main_receiver,
                              state.scratch.fluid_fluid, model.particle_mass);
    // Which porous particles may dissolve later in the step, while the lists hold.
    mark_exposed(porous.particles, state.fluid, s.porous_fluid, model.h, model.dx, s.exposed);
}

/// §3 step 9: saturated, porous-enough particles become muddy fluid; their fragments lose them.
void dissolve_particles(const Model& model, State& state) {
    DissolutionSettings settings{model.dissolution, model.particle_mass, model.dx};
    const DissolutionReport r = dissolve(state.porous.particles, state.fluid, model.pore_laws,
                                         settings, state.next_id, state.porous_scratch.exposed);
    state.porous.dissolved += r.dissolved;
    if (r.dissolved > 0) state.porous_scratch.pairs_stale = true;
}

/// Step length that reaches `target` in a whole number of steps no longer than dt_bound, so
/// frames and Biot calls land on their exact times without a sliver step.
Real step_towards(Real dt_bound, Real now, Real target) {
    const Real remaining = target - now;
    const Real n = std::max(Real(1), std::ceil(remaining / dt_bound - 1e-9));
    return remaining / n;
}

}  // namespace

Real next_step_length(const Model& model, const State& state, Real target) {
    if (model.poroelastic_only() && !any_free_fragment(state)) {
        target = std::min(target, state.time + time_to_next_biot_call(model, state));
        return step_towards(model.scene.poroelastic.time_step, state.time, target);
    }
    const Real dt = cfl_time_step(model, state);
    const TimeSettings& time = model.scene.time;
    if (!time.fixed_dt && dt < time.dt_min)
        throw WatchdogError("time step", state.time,
                            fmt::format("the step fell to {:.3g} s, below /time/dt_min = {:.3g} s "
                                        "(the flow is too fast or too stiff for the spacing)",
                                        dt, time.dt_min));
    // A fixed step is shortened only to end the run on its end time.
    if (time.fixed_dt) return std::min(dt, std::max(time.end - state.time, Real(0)));
    target = std::min(target, state.time + time_to_next_biot_call(model, state));
    return std::isfinite(target) ? step_towards(dt, state.time, target) : dt;
}

StepReport step(const Model& model, State& state, Real dt_wanted, StepProfile& profile) {
    const Real t = state.time;
    const auto& id = state.fluid.id;
    const bool porous = state.porous.size() > 0;
    Real dt = dt_wanted;

    // 1. Neighbour search (and periodic Morton reordering of the fluid), porous pairs after.
    timed(profile, t, Stage::Neighbours, [&] {
        update_fluid_neighbours(model, state);
        if (porous) update_porous_neighbours(model, state);
    });

    // 2. Akinci volumes of the porous particles (§4.1), fluid densities with the boundary (M7),
    //    and the per-pair kernel gradient factors that the forces and the pressure solve share.
    timed(profile, t, Stage::Density, [&] {
        if (porous) update_porous_boundary_volumes(model, state);
        update_density_and_pair_coefficients(model, state);
    });
    check_scalars(state.fluid.rho, id, Stage::Density, t, "density");

    // 3. Gravity, viscosity, surface tension, adhesion, boundary friction (§4.2).
    timed(profile, t, Stage::NonPressureForces, [&] { compute_non_pressure_forces(model, state); });
    check_vectors(state.scratch.a_other, id, Stage::NonPressureForces, t, "acceleration");

    // 4. Pressure solve with walls and porous particles as boundary: DFSPH (divergence, then
    //    constant density; sph/dfsph.hpp) or the paper's PCISPH loop (§4.3, M8). A solve that
    //    leaves over 1 % compression (its residual, read as a rate) is repeated with half the step
    //    (sph/integrate.hpp says why), unless the step is fixed; nothing has moved yet, so only the
    //    step length changes.
    const FluidSettings& fs = model.scene.fluid;
    const Real dt_sound = sound_crossing_time(fs, model.dx);
    PressureSolveReport pressure;
    bool converged = false;
    timed(profile, t, Stage::PressureSolve, [&] {
        for (int halvings = 0;; ++halvings) {
            pressure = fs.solver == FluidSettings::Solver::Dfsph
                           ? solve_pressure_dfsph(model, state, dt)
                           : solve_pressure_pcisph(model, state, dt);
            converged =
                pressure.max_density_error <= std::max(fs.max_density_error, k_step_density_error);
            // Below dx / c_s the bands shrink with the step (sph/integrate.hpp), so a shorter
            // step no longer makes the solve easier.
            if (converged || model.scene.time.fixed_dt || halvings == k_max_step_halvings ||
                dt / 2 < model.scene.time.dt_min || dt / 2 < dt_sound)
                break;
            dt /= 2;
        }
    });
    check_vectors(state.scratch.a_pressure, id, Stage::PressureSolve, t, "pressure acceleration");
    update_solver_time_step_limit(state, dt, dt < dt_wanted, converged, model.scene.time.dt_max,
                                  dt_sound);

    // 10. Solute diffusion among fluid particles (M18), on this step's densities and lists.
    timed(profile, t, Stage::SoluteDiffusion, [&] {
        if (const Real needed = diffuse_solute(model, state, dt); needed > 0)
            throw WatchdogError(
                k_stage_names[size_t(Stage::SoluteDiffusion)], state.time,
                fmt::format("the solute diffusion needs {:.3g} explicit sub-steps in a step of "
                            "{:.3g} s (at most {:g}): lower /fluid/solute_diffusivity or "
                            "/time/dt_max, or raise particle_spacing",
                            needed, dt, k_max_diffusion_substeps));
    });
    check_scalars(state.fluid.solute, id, Stage::SoluteDiffusion, t, "solute mass");

    if (porous) {
        // 3b. The fluid's last pressure, friction and adhesion act back on the porous particles.
        timed(profile, t, Stage::FluidReactions, [&] { compute_fluid_reactions(model, state); });
        // 8. Pore flow, absorption and drained fluid (§4.7), before anything moves.
        timed(profile, t, Stage::PoreFlow, [&] { pore_flow_and_absorption(model, state, dt); });
        check_scalars(state.porous.particles.absorbed_mass, {}, Stage::PoreFlow, t,
                      "absorbed mass");
    }

    // 5. Symplectic Euler; particles leaving the domain, or drained, are removed (§4.4).
    state.a_max =
        timed(profile, t, Stage::Integrate, [&] { return integrate_fluid(model, state, dt); });
    check_vectors(state.fluid.v, state.fluid.id, Stage::Integrate, t + dt, "velocity",
                  model.scene.max_speed);
    check_vectors(state.fluid.x, state.fluid.id, Stage::Integrate, t + dt, "position");

    if (porous) {
        // 6-7. Fragments: contacts, rigid integration, members follow (§4.5).
        timed(profile, t, Stage::Fragments, [&] { advance_fragments(model, state, dt); });
        // 11a. Loads of the next Biot call (§5.3): this step's forces on the porous particles,
        //      the fluid's reactions and the contacts, summed over the call's interval (here,
        //      while the force array still matches the particles dissolution may remove).
        timed(profile, t, Stage::Structure, [&] { add_structure_loads(state, dt); });
        // 9. Dissolution into muddy fluid (§4.8); the fragments' mass properties follow the
        //    pore water and the members they lost.
        timed(profile, t, Stage::Dissolution, [&] {
            dissolve_particles(model, state);
            refresh_fragment_mass(state, model.dx);
        });
        // 12. Wet fragments in slow contact merge (§5.6, Fig. 7); one merged into an anchored
        //     fragment joins its structure at the next Biot call's remesh.
        timed(profile, t, Stage::Fracture, [&] {
            if (!merge_fragments(model, state)) return;
            state.porous_scratch.pairs_stale = true;
            refresh_fragment_mass(state, model.dx);
        });
        // 11. Algorithm 2 on the anchored fragments every dt_B (§5): the members move toward the
        //     last call's X + u (7, elastic part); when a call is due, remesh triggers (§4.10),
        //     the Biot call on the mean loads (M22), fracture (§5.5-5.6: cracks, split nodes,
        //     new free fragments) and the feedback into the pores (§5.4).
        //     Fracture (§5.5-5.6) tests the call's stress before the feedback reads it; a
        //     structure that cracked is solved again at once under the same loads (§4.10), and
        //     tested again, so that a crack runs as far as the load drives it within the call.
        const bool called = timed(profile, t, Stage::Structure, [&] {
            follow_structure_displacement(model, state);
            if (!biot_call_due(model, state)) return false;
            remesh_structures(model, state);
            solve_structures(model, state, t + dt);
            return true;
        });
        if (called) check_structures(state.structures, Stage::Structure, t + dt);
        if (called) {
            // Beyond k_fracture_rounds, only while a node would still move over a spacing in
            // the call: a piece hanging by a neck, which small strain cannot carry.
            for (int round = 0; round < k_max_fracture_rounds; ++round) {
                if (round >= k_fracture_rounds && largest_call_displacement(state) <= model.dx)
                    break;
                if (!timed(profile, t, Stage::Fracture,
                           [&] { return fracture_structures(model, state, t + dt, round); }))
                    break;
                state.porous_scratch.pairs_stale = true;
                timed(profile, t, Stage::Structure,
                      [&] { solve_structures(model, state, t + dt, true); });
                check_structures(state.structures, Stage::Structure, t + dt);
            }
            timed(profile, t, Stage::Structure, [&] {
                end_biot_call(state);
                if (feed_back_structures(model, state)) state.porous_scratch.pairs_stale = true;
                release_split_solvers(state);
            });
        }
        check_vectors(state.porous.particles.x, state.porous.particles.id, Stage::Structure, t + dt,
                      "porous position");
        // The speed limit holds for the solid too: a fragment thrown through a wall in one
        // step would otherwise leave the domain and vanish.
        check_vectors(state.porous.particles.v, state.porous.particles.id, Stage::Fragments, t + dt,
                      "porous velocity", model.scene.max_speed);
    }

    state.time = t + dt;
    state.dt = dt;
    ++state.steps;
    return {dt, pressure.iterations, pressure.divergence_iterations, pressure.max_density_error};
}

}  // namespace karst
