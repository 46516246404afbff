#include "karst/sph/pcisph.hpp"

#include "karst/core/parallel.hpp"
#include "karst/coupling/boundary_pair.hpp"
#include "karst/sph/density.hpp"

namespace karst {

namespace {

/// a_i^p = -sum_j m_j (p_i + p_j) / rho0^2 grad W_ij - sum_k Psi_k (p_i + p_ik) / rho0^2 grad W_ik
/// (k: walls and porous particles) at the current positions, then the prediction x*_i = x_i + dt (v_i + dt (a_other + a_p)) for
/// the next density pass.
///
/// Wall pressure [D]: method.md §4.3 writes the wall term with p_i alone; the variant it names,
/// mirroring (p_ik = p_i), is needed because with p_i alone a wall-adjacent particle must carry
/// twice the hydrostatic pressure (measured: 9970 Pa against 4807 Pa in the first layer). Plain
/// mirroring still assumes a flat pressure inside the wall, so next to a side wall the particle
/// loses the vertical gradient its missing fluid neighbours would have given: in a 10-particle
/// wide column the z-gradient normalisation sum_j V_j x_ji,z dW/dz fell to 0.93 and the whole
/// column settled 5 % over rho0 g depth. So the mirrored pressure is extrapolated
/// hydrostatically, p_ik = max(p_i + rho0 g.(x_k - x_i), 0), after Band et al. 2018 ("Pressure
/// boundaries for implicit incompressible SPH", their extrapolation without the acceleration
/// term). The pair force stays equal and opposite, so the reaction on the wall is exact.
void pressure_acceleration_and_prediction(const Model& model, State& state, Real dt) {
    const FluidParticles& f = state.fluid;
    FluidScratch& s = state.scratch;
    const std::vector<Vec3>& porous_x = state.porous.particles.x;
    const int cap_f = s.fluid_fluid.capacity, cap_w = s.fluid_wall.capacity, cap_p = s.fluid_porous.capacity;
    parallel_for(f.size(), [&](Index i) {
        const Vec3 xi = f.x[i];
        const Real pi = f.p[i];
        Vec3 a = Vec3::Zero();
        const Real* cf = s.pair_coefficient.data() + i * cap_f;
        int k = 0;
        s.fluid_fluid.for_each(i, [&](Index j) { a -= ((pi + f.p[j]) * cf[k++]) * (xi - f.x[j]); });
        if (pi != 0) {
            const Real* cw = s.wall_coefficient.data() + i * cap_w;
            const Real* hw = s.wall_hydrostatic.data() + i * cap_w;
            k = 0;
            s.fluid_wall.for_each(i, [&](Index w) {
                a -= boundary_pressure_term(pi, cw[k], hw[k], xi - model.walls.x[w]);
                ++k;
            });
            // Porous particles are boundary particles like walls (§4.3); their reaction is
            // the same term, summed on the fragment side (coupling/fluid_reactions.cpp).
            const Real* cp = s.porous_coefficient.data() + i * cap_p;
            const Real* hp = s.porous_hydrostatic.data() + i * cap_p;
            k = 0;
            s.fluid_porous.for_each(i, [&](Index w) {
                a -= boundary_pressure_term(pi, cp[k], hp[k], xi - porous_x[w]);
                ++k;
            });
        }
        a *= f.sph_mass[i] / f.mass[i];  // a force per unit rho0 V acting on the true mass
        s.a_pressure[i] = a;
        s.x_pred[i] = xi + dt * (f.v[i] + dt * (s.a_other[i] + a));
    });
}

/// The parts of the pressure acceleration that stay fixed through the iterations, per pair:
/// m_j / rho0^2 dW/dr / r (fluid), Psi_k / rho0^2 dW/dr / r and -rho0 g.x_ik (walls). Computing
/// them once per step saves a square root, a division and the kernel in every iteration.
void pair_coefficients(const Model& model, State& state) {
    const FluidParticles& f = state.fluid;
    FluidScratch& s = state.scratch;
    const CubicKernel& W = model.kernel;
    const Real inv_rho0_2 = 1 / (model.rho0 * model.rho0);
    const Vec3 rho0_g = model.rho0 * model.scene.gravity;
    const PorousParticles& porous = state.porous.particles;
    const std::vector<Real>& psi = state.porous_scratch.psi;
    const int cap_f = s.fluid_fluid.capacity, cap_w = s.fluid_wall.capacity, cap_p = s.fluid_porous.capacity;
    s.pair_coefficient.resize(size_t(f.size()) * cap_f);
    s.wall_coefficient.resize(size_t(f.size()) * cap_w);
    s.wall_hydrostatic.resize(size_t(f.size()) * cap_w);
    s.porous_coefficient.resize(size_t(f.size()) * cap_p);
    s.porous_hydrostatic.resize(size_t(f.size()) * cap_p);
    parallel_for(f.size(), [&](Index i) {
        int k = 0;
        s.fluid_fluid.for_each(i, [&](Index j) {
            s.pair_coefficient[i * cap_f + k++] = f.sph_mass[j] * inv_rho0_2 * W.dw_over_r((f.x[i] - f.x[j]).norm());
        });
        k = 0;
        s.fluid_wall.for_each(i, [&](Index w) {
            const Vec3 xik = f.x[i] - model.walls.x[w];
            s.wall_coefficient[i * cap_w + k] = boundary_pressure_coefficient(model.walls.psi[w], inv_rho0_2, W, xik);
            s.wall_hydrostatic[i * cap_w + k++] = -rho0_g.dot(xik);
        });
        k = 0;
        s.fluid_porous.for_each(i, [&](Index w) {
            const Vec3 xik = f.x[i] - porous.x[w];
            s.porous_coefficient[i * cap_p + k] = boundary_pressure_coefficient(psi[w], inv_rho0_2, W, xik);
            s.porous_hydrostatic[i * cap_p + k++] = -rho0_g.dot(xik);
        });
    });
}

/// Per-particle scaling factor delta_i (Pa per kg/m^3), M8 evaluated on the particle's own
/// neighbourhood and capped at the prototype value:
///   delta_i = rho0^2 / (2 dt^2 (|sum_j m_j grad W_ij + sum_k Psi_k grad W_ik|^2 + sum_j m_j^2 |grad W_ij|^2)).
/// Why [D]: M8's prototype (full fluid neighbourhood) omits the stiffness that Akinci wall
/// neighbours add; at wall corners |sum_k Psi_k grad W_ik|^2 is several times the prototype's
/// sum, the prototype delta over-relaxes there, and with the maximum-error stopping rule the loop
/// diverges. Capping keeps the prototype everywhere it is stable (the interior, free surface).
void compute_delta(const Model& model, const State& state, Real dt, std::vector<Real>& delta) {
    const PorousParticles& porous = state.porous.particles;
    const std::vector<Real>& psi = state.porous_scratch.psi;
    const FluidParticles& f = state.fluid;
    const FluidScratch& s = state.scratch;
    const CubicKernel& W = model.kernel;
    const Real prototype = model.pcisph_delta(dt);
    const Real scale = model.rho0 * model.rho0 / (2 * dt * dt);
    delta.resize(f.size());
    parallel_for(f.size(), [&](Index i) {
        Vec3 sum_grad = Vec3::Zero();
        Real sum_sq = 0;
        s.fluid_fluid.for_each(i, [&](Index j) {
            const Vec3 g = f.sph_mass[j] * W.gradient(f.x[i] - f.x[j]);
            sum_grad += g;
            sum_sq += g.squaredNorm();
        });
        s.fluid_wall.for_each(i, [&](Index k) { sum_grad += model.walls.psi[k] * W.gradient(f.x[i] - model.walls.x[k]); });
        s.fluid_porous.for_each(i, [&](Index k) { sum_grad += psi[k] * W.gradient(f.x[i] - porous.x[k]); });
        const Real denominator = sum_grad.squaredNorm() + sum_sq;
        delta[i] = denominator > 0 ? std::min(prototype, scale / denominator) : prototype;
    });
}

}  // namespace

PcisphReport solve_pressure_pcisph(const Model& model, State& state, Real dt) {
    FluidParticles& f = state.fluid;
    FluidScratch& s = state.scratch;
    const Index n = f.size();
    const FluidSettings& fs = model.scene.fluid;
    const Real rho0 = model.rho0;
    const CubicKernel& W = model.kernel;
    const PorousParticles& porous = state.porous.particles;
    const std::vector<Real>& psi = state.porous_scratch.psi;

    // p starts at 0 every step (method.md §4.3). A warm start from the last step's pressure
    // (signed update, p >= 0) was tried: it smooths the pressure but left a resting column
    // moving at 0.1-0.2 m/s RMS, so it is not used.
    f.p.assign(n, 0);
    s.x_pred.resize(n);
    s.rho_err.resize(n);
    compute_delta(model, state, dt, s.delta);
    pair_coefficients(model, state);
    s.a_pressure.assign(n, Vec3::Zero());
    parallel_for(n, [&](Index i) { s.x_pred[i] = f.x[i] + dt * (f.v[i] + dt * s.a_other[i]); });

    PcisphReport report;
    while (report.iterations < fs.max_iterations) {
        // Predicted density at x* (walls stay put), clamped error, pressure update.
        parallel_for(n, [&](Index i) {
            const Vec3 xi = s.x_pred[i];
            Real rho = f.sph_mass[i] * W.w0();
            s.fluid_fluid.for_each(i, [&](Index j) { rho += f.sph_mass[j] * W.w((xi - s.x_pred[j]).norm()); });
            s.fluid_wall.for_each(i, [&](Index k) { rho += model.walls.psi[k] * W.w((xi - model.walls.x[k]).norm()); });
            s.fluid_porous.for_each(i, [&](Index k) { rho += psi[k] * W.w((xi - porous.x[k]).norm()); });
            const Real err = std::max(rho - rho0, Real(0));
            s.rho_err[i] = err;
            f.p[i] += s.delta[i] * err;
        });
        report.max_density_error = parallel_max(n, 0.0, [&](Index i) { return s.rho_err[i]; }) / rho0;
        pressure_acceleration_and_prediction(model, state, dt);
        ++report.iterations;
        // Stopping rule (method.md §4.3; the paper's l.13 never ends).
        if (report.iterations >= fs.min_iterations && report.max_density_error <= fs.max_density_error) break;
    }
    return report;
}

}  // namespace karst
