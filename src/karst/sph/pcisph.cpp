#include "karst/sph/pcisph.hpp"

#include "karst/core/parallel.hpp"
#include "karst/coupling/boundary_pair.hpp"
#include "karst/coupling/fragment_response.hpp"
#include "karst/sph/density.hpp"
#include "karst/sph/integrate.hpp"
#include "karst/sph/pressure_acceleration.hpp"

namespace karst {

namespace {

/// a_i^p at the current pressures (sph/pressure_acceleration.hpp), then the prediction
/// x*_i = x_i + dt (v_i + dt (a_other + a_p)) for the next density pass.
///
/// Wall pressure [D]: docs/method.md §4.3 writes the wall term with p_i alone; the variant it
/// names, mirroring (p_ik = p_i), is needed because with p_i alone a wall-adjacent particle must
/// carry about twice the hydrostatic pressure. Plain mirroring still assumes a flat pressure inside
/// the wall, so next to a side wall the particle loses the vertical gradient its missing fluid
/// neighbours would have given, and a narrow column settles over rho0 g depth. So the mirrored
/// pressure is extrapolated
/// hydrostatically, p_ik = max(p_i + rho0 g.(x_k - x_i), 0), after Band et al. 2018 ("Pressure
/// boundaries for implicit incompressible SPH", their extrapolation without the acceleration
/// term). The pair force stays equal and opposite, so the reaction on the wall is exact.
void pressure_acceleration_and_prediction(const Model& model, State& state, Real dt) {
    const FluidParticles& f = state.fluid;
    FluidScratch& s = state.scratch;
    parallel_for(f.size(), [&](Index i) {
        const Vec3 a = pressure_acceleration(model, state, f.p, i, BoundaryPressure::Hydrostatic);
        s.a_pressure[i] = a;
        s.x_pred[i] = f.x[i] + dt * (f.v[i] + dt * (s.a_other[i] + a));
    });
}

/// Per-particle scaling factor delta_i (Pa per kg/m^3), M8 evaluated on the particle's own
/// neighbourhood, with the boundary twice as in the predicted density (boundary_density), and
/// capped at the prototype value:
///   delta_i = rho0^2 / (2 dt^2 (|sum_j m_j grad W_ij + 2 sum_k Psi_k grad W_ik|^2 + sum_j m_j^2
///   |grad W_ij|^2)).
/// Why [D]: M8's prototype (full fluid neighbourhood) omits the stiffness that Akinci wall
/// neighbours add; at wall corners |2 sum_k Psi_k grad W_ik|^2 is several times the prototype's
/// sum, the prototype delta over-relaxes there, and with the maximum-error stopping rule the loop
/// diverges. Capping keeps the prototype everywhere it is stable (the interior, free surface).
/// Then under-relaxed by k_pressure_relaxation [D] (sph/pressure_acceleration.hpp says why).
/// The free fragments that give way to p_i add m_i times their mobility to the denominator, as
/// in DFSPH's diagonal (coupling/fragment_response.hpp).
/// Reads the step's pair factors (update_density_and_pair_coefficients).
void compute_delta(const Model& model, const State& state, Real dt, std::vector<Real>& delta) {
    const FluidParticles& f = state.fluid;
    const FluidScratch& s = state.scratch;
    const Real rho0_2 = model.rho0 * model.rho0;
    const Real prototype = model.pcisph_delta(dt);
    const Real scale = rho0_2 / (2 * dt * dt);
    const FragmentMobility mobility(state);
    delta.resize(f.size());
    parallel_for(f.size(), [&](Index i) {
        // The boundary's sum_k Psi_k grad W_ik = rho0^2 sum_k c_ik x_ik is summed once a step.
        const FluidGradientSums fluid = fluid_gradient_sums(model, state, i);
        const Real denominator =
            (fluid.sum + 2 * rho0_2 * s.boundary_sums.gradient[i]).squaredNorm() + fluid.squares +
            f.sph_mass[i] * mobility.at(model, state, i);
        delta[i] = k_pressure_relaxation *
                   (denominator > 0 ? std::min(prototype, scale / denominator) : prototype);
    });
}

/// sum_k Psi_k W(|x - x_k|) over fluid particle i's wall and porous neighbours (the step's
/// lists): the boundary's part of M7's density at x, kg/m^3. Walls stay put during the solve;
/// porous members move on by dt v_porous[k] when given (free fragments in the solve).
Real boundary_density(const Model& model, const State& state, Index i, const Vec3& x, Real dt = 0,
                      const std::vector<Vec3>* v_porous = nullptr) {
    const FluidScratch& s = state.scratch;
    const CubicKernel& W = model.kernel;
    const PorousParticles& porous = state.porous.particles;
    const std::vector<Real>& psi = state.porous_scratch.psi;
    Real rho = 0;
    s.fluid_wall.for_each(
        i, [&](Index k) { rho += model.walls.psi[k] * W.w((x - model.walls.x[k]).norm()); });
    s.fluid_porous.for_each(i, [&](Index k) {
        const Vec3 xk = v_porous ? Vec3(porous.x[k] + dt * (*v_porous)[k]) : porous.x[k];
        rho += psi[k] * W.w((x - xk).norm());
    });
    return rho;
}

}  // namespace

PressureSolveReport solve_pressure_pcisph(const Model& model, State& state, Real dt) {
    FluidParticles& f = state.fluid;
    FluidScratch& s = state.scratch;
    const Index n = f.size();
    const FluidSettings& fs = model.scene.fluid;
    const Real rho0 = model.rho0;
    const CubicKernel& W = model.kernel;

    // p starts at 0 every step (docs/method.md §4.3). A warm start from the last step's pressure
    // (signed update, p >= 0) was tried: it smooths the pressure but left a resting column
    // moving at 0.1-0.2 m/s RMS, so it is not used.
    f.p.assign(n, 0);
    f.p_divergence.assign(n, 0);
    s.x_pred.resize(n);
    s.rho_err.resize(n);
    compute_delta(model, state, dt, s.delta);
    s.a_pressure.assign(n, Vec3::Zero());
    s.rho_boundary.resize(n);
    parallel_for(n,
                 [&](Index i) { s.rho_boundary[i] = boundary_density(model, state, i, f.x[i]); });
    parallel_for(n, [&](Index i) { s.x_pred[i] = f.x[i] + dt * (f.v[i] + dt * s.a_other[i]); });
    // Free fragments in the solve (coupling/fragment_response.hpp): their members move on with
    // gravity and the reaction of the current pressures, so the fluid under a landing fragment
    // is not squeezed as if the fragment were infinitely heavy.
    // Anchored members stay put, as without free fragments.
    const FragmentResponse fragments(model, state, dt, true, nullptr);
    const std::vector<Vec3>* moving = fragments.active() ? &s.porous_v_pred : nullptr;
    const auto predict_members = [&] {
        fragments.member_velocities(model, state, f.p, BoundaryPressure::Hydrostatic,
                                    s.porous_v_pred);
        const PorousParticles& porous = state.porous.particles;
        parallel_for(porous.size(), [&](Index k) {
            if (state.porous.fragments[porous.fragment[k]].anchored)
                s.porous_v_pred[k] = Vec3::Zero();
        });
    };
    if (moving) predict_members();

    // The tolerance and the density target as rates: a step of the share `rate` of the sound's
    // crossing time removes that share of a compression, within that share of the band
    // (sph/integrate.hpp).
    const Real rate = solve_rate_fraction(fs, model.dx, dt);
    const auto target = [&](Index i) { return rate_density_target(f.rho[i], rho0, rate); };
    PressureSolveReport report;
    while (report.iterations < fs.max_iterations) {
        // Predicted density at x*, the boundary's change counted twice (docs/method.md §4.3):
        // a boundary neighbour pushes with p_i + p_ik, which rises with p_i, so the pressure
        // force's part linear in p is minus the transpose of this prediction's, and the solve
        // projects orthogonally. With the boundary once, narrow and deep columns at rest were
        // launched by a pressure that grew every iteration (bench/results/notes.md).
        parallel_for(n, [&](Index i) {
            const Vec3 xi = s.x_pred[i];
            Real rho = f.sph_mass[i] * W.w0();
            s.fluid_fluid.for_each(
                i, [&](Index j) { rho += f.sph_mass[j] * W.w((xi - s.x_pred[j]).norm()); });
            rho += 2 * boundary_density(model, state, i, xi, dt, moving) - s.rho_boundary[i];
            // Signed error from the target, p clamped at 0 (docs/method.md §4.3); the stopping
            // test reads the compression, or the over-pressure p_i could give back where the
            // fluid expands.
            const Real e = rho - target(i);
            s.rho_err[i] = e > 0 ? e : std::min(-e, f.p[i] / s.delta[i]);
            f.p[i] = std::max(f.p[i] + s.delta[i] * e, Real(0));
        });
        report.max_density_error =
            parallel_max(n, 0.0, [&](Index i) { return s.rho_err[i]; }) / (rate * rho0);
        pressure_acceleration_and_prediction(model, state, dt);
        ++report.iterations;
        // Stopping rule (docs/method.md §4.3; the paper's l.13 never ends).
        if (report.iterations >= fs.min_iterations &&
            report.max_density_error <= fs.max_density_error)
            break;
        if (moving) predict_members();
    }
    return report;
}

}  // namespace karst
