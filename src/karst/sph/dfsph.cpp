#include "karst/sph/dfsph.hpp"

#include "karst/core/parallel.hpp"
#include "karst/coupling/fragment_response.hpp"
#include "karst/sph/integrate.hpp"
#include "karst/sph/pressure_acceleration.hpp"

#include <algorithm>

namespace karst {

namespace {

/// -d rho*_i / d p_i = dt^2 / rho0^2 (|G_i|^2 + m_i sum_j m_j |grad W_ij|^2 + m_i mobility_i),
/// with G_i = sum_j m_j grad W_ij + 2 sum_k Psi_k grad W_ik, the gradient of both the predicted
/// density (density_change) and the pressure force, and the free fragments' mobility
/// (coupling/fragment_response.hpp). Fixed for the step.
void compute_diagonal(const Model& model, State& state, Real dt) {
    const FluidParticles& f = state.fluid;
    FluidScratch& s = state.scratch;
    const Real rho0_2 = model.rho0 * model.rho0, scale = dt * dt / rho0_2;
    const FragmentMobility mobility(state);
    s.diagonal.resize(f.size());
    parallel_for(f.size(), [&](Index i) {
        const FluidGradientSums fluid = fluid_gradient_sums(model, state, i);
        const Vec3 boundary = rho0_2 * s.boundary_sums.gradient[i];  // sum_k Psi_k grad W_ik
        // sum_j m_i m_j |grad W_ij|^2, read as (m_i / m_0) sum_j |m_j grad W_ij|^2 (equal for
        // water).
        const Real own = (fluid.sum + 2 * boundary).squaredNorm();
        s.diagonal[i] = scale * (own + fluid.squares * f.sph_mass[i] / model.particle_mass +
                                 f.sph_mass[i] * mobility.at(model, state, i));
    });
}

/// dt D_i(v) = dt (sum_j m_j (v_i - v_j).grad W_ij + 2 sum_k Psi_k (v_i - v_k).grad W_ik): the
/// density change that the fluid velocities v and the porous members' velocities v_porous would
/// make over dt, kg/m^3, as the solves predict it.
/// [D] The boundary counts twice, as in the pressure force, where a boundary neighbour pushes with
/// p_i + p_ik and p_ik rises with p_i (pressure_acceleration.hpp). The force's part linear in p is
/// then minus the transpose of this rate, and each solve projects the velocities orthogonally,
/// which takes kinetic energy away; with the boundary once (the density sum's own rate) the
/// projection was oblique, and deep water at rest gained energy and never settled
/// (bench/results/notes.md). Moving boundaries keep this property only with their inertia in
/// the solve (coupling/fragment_response.hpp). The price: next to a wall the density reaches rho0
/// over a few steps instead of one.
Real density_change(const Model& model, const State& state, const std::vector<Vec3>& v,
                    const std::vector<Vec3>& v_porous, Index i, Real dt) {
    const FluidParticles& f = state.fluid;
    const FluidScratch& s = state.scratch;
    const Real rho0_2 = model.rho0 * model.rho0;
    const int cap_f = s.fluid_fluid.capacity, cap_p = s.fluid_porous.capacity;
    const Vec3 xi = f.x[i], vi = v[i];
    Real fluid = 0;
    const Real* cf = s.pair_coefficient.data() + i * cap_f;
    int k = 0;
    s.fluid_fluid.for_each(i, [&](Index j) { fluid += cf[k++] * (vi - v[j]).dot(xi - f.x[j]); });
    // sum_k c_ik (v_i - v_k).x_ik: v_i against the step's sum, the moving porous members apart.
    Real boundary = vi.dot(s.boundary_sums.gradient[i]);
    const std::vector<Vec3>& porous_x = state.porous.particles.x;
    const Real* cp = s.porous_coefficient.data() + i * cap_p;
    k = 0;
    s.fluid_porous.for_each(
        i, [&](Index w) { boundary -= cp[k++] * v_porous[w].dot(xi - porous_x[w]); });
    return dt * rho0_2 * (fluid + 2 * boundary);
}

/// One relaxed Jacobi solve for p >= 0 with rho*_i(v*) <= target_i within tolerance rho0, where
/// v*_i = base_i + dt a^p_i(p) and the free fragments take the reaction of p (`fragments`);
/// a_out gets a^p(p). Returns the iterations and the last residual.
struct SolveResult {
    int iterations = 0;
    Real max_error = 0;
};

template <class Target>
SolveResult relax(const Model& model, State& state, Real dt, std::vector<Real>& p,
                  const std::vector<Vec3>& base, BoundaryPressure boundary,
                  const FragmentResponse& fragments, std::vector<Vec3>& a_out, const Target& target,
                  Real tolerance, int max_iterations) {
    const FluidParticles& f = state.fluid;
    FluidScratch& s = state.scratch;
    const Index n = f.size();
    SolveResult r;
    for (;;) {
        parallel_for(n, [&](Index i) {
            a_out[i] = pressure_acceleration(model, state, p, i, boundary);
            s.v_pred[i] = base[i] + dt * a_out[i];
        });
        if (fragments.active())
            fragments.member_velocities(model, state, p, boundary, s.porous_v_pred);
        // The complementarity residual: compression where p_i = 0 is allowed to rise, and as much
        // over-pressure as p_i could give back where the fluid expands. A warm start that pushes
        // the fluid apart is thus corrected, not accepted because nothing is compressed.
        r.max_error =
            parallel_max(n, 0.0,
                         [&](Index i) {
                             const Real e = s.rho_err[i] =
                                 f.rho[i] +
                                 density_change(model, state, s.v_pred, s.porous_v_pred, i, dt) -
                                 target(i);
                             return e > 0 ? e : std::min(-e, s.diagonal[i] * p[i]);
                         }) /
            model.rho0;
        ++r.iterations;
        if (r.max_error <= tolerance || r.iterations >= max_iterations) break;
        parallel_for(n, [&](Index i) {
            if (s.diagonal[i] > 0)
                p[i] =
                    std::max(p[i] + k_pressure_relaxation * s.rho_err[i] / s.diagonal[i], Real(0));
        });
    }
    return r;
}

}  // namespace

PressureSolveReport solve_pressure_dfsph(const Model& model, State& state, Real dt) {
    FluidParticles& f = state.fluid;
    FluidScratch& s = state.scratch;
    const Index n = f.size();
    const FluidSettings& fs = model.scene.fluid;
    const Real rho0 = model.rho0;
    // The tolerances and the density target as rates: a step of the share `rate` of the sound's
    // crossing time may compress or relax that share of what a whole one may (sph/integrate.hpp).
    const Real rate = solve_rate_fraction(fs, model.dx, dt);
    compute_diagonal(model, state, dt);
    s.v_pred.resize(n), s.rho_err.resize(n), s.a_divergence.resize(n), s.a_pressure.resize(n);

    PressureSolveReport report;
    // 1. Divergence, from zero: fluid at or above rho0 may not compress further, lighter fluid up
    //    to rho0. Warm-started from the last step's p_div, a resting column kept moving.
    f.p_divergence.assign(n, 0);
    s.porous_v_pred = state.porous.particles.v;
    const FragmentResponse still(model, state, dt, false, nullptr);
    const SolveResult div = relax(
        model, state, dt, f.p_divergence, f.v, BoundaryPressure::Mirrored, still, s.a_divergence,
        [&](Index i) { return std::max(f.rho[i], rho0); }, rate * fs.max_divergence_error,
        fs.max_iterations);
    report.divergence_iterations = div.iterations;

    // 2. Constant density, with the non-pressure forces (gravity on the fragments too).
    std::vector<Vec3>& base = s.x_pred;  // reused as the velocity before the density pressure
    base.resize(n);
    parallel_for(n, [&](Index i) { base[i] = f.v[i] + dt * (s.a_divergence[i] + s.a_other[i]); });
    // Warm start as SPlisHSPlasH's DFSPH does: half the last pressure where the fluid would
    // compress without it, zero elsewhere. The full last pressure kept a resting column moving
    // (the solve accepts it unchanged inside its tolerance band); zero cannot hold deep water,
    // whose pressure a Jacobi iteration rebuilds only a layer or two per iteration.
    const FragmentResponse falling(model, state, dt, true, &f.p_divergence);
    if (falling.active())
        falling.member_velocities(model, state, std::vector<Real>(n, 0),
                                  BoundaryPressure::Hydrostatic, s.porous_v_pred);
    else
        s.porous_v_pred = state.porous.particles.v;
    const auto target = [&](Index i) { return rate_density_target(f.rho[i], rho0, rate); };
    parallel_for(n, [&](Index i) {
        const bool compressed =
            f.rho[i] + density_change(model, state, base, s.porous_v_pred, i, dt) > target(i);
        f.p[i] = compressed ? 0.5 * f.p[i] : 0;
    });
    const SolveResult density =
        relax(model, state, dt, f.p, base, BoundaryPressure::Hydrostatic, falling, s.a_pressure,
              target, rate * fs.max_density_error, fs.max_iterations);
    report.iterations = density.iterations;
    report.max_density_error = density.max_error / rate;
    parallel_for(n, [&](Index i) { s.a_pressure[i] += s.a_divergence[i]; });
    return report;
}

}  // namespace karst
