// The pressure acceleration a_i^p (sph/pressure_acceleration.hpp) against its pair-by-pair
// definition, walls and porous particles as boundary: the per-particle boundary sums it reads
// where no hydrostatic clamp acts must give the same force as the clamped pair terms, and the
// densities computed in the same pass must be M7's (compute_density).
#include "support/simulate.hpp"

#include "karst/coupling/porous_boundary_volumes.hpp"
#include "karst/coupling/porous_neighbours.hpp"
#include "karst/sph/density.hpp"
#include "karst/sph/fluid_neighbours.hpp"
#include "karst/sph/pressure_acceleration.hpp"

#include <gtest/gtest.h>

#include <random>

namespace karst {
namespace {

/// -sum_j m_j (p_i + p_j) / rho0^2 grad W_ij - sum_k Psi_k (p_i + p_ik) / rho0^2 grad W_ik, with
/// p_ik = max(p_i - rho0 g.x_ik, 0) (hydrostatic) or p_i (mirrored), every pair evaluated.
Vec3 by_pairs(const Model& model, const State& state, const std::vector<Real>& p, Index i,
              bool hydrostatic) {
    const FluidParticles& f = state.fluid;
    const FluidScratch& s = state.scratch;
    const CubicKernel& W = model.kernel;
    const Real rho0_2 = model.rho0 * model.rho0;
    const Vec3 rho0_g = model.rho0 * model.scene.gravity;
    Vec3 a = Vec3::Zero();
    s.fluid_fluid.for_each(i, [&](Index j) {
        a -= f.sph_mass[j] * (p[i] + p[j]) / rho0_2 * W.gradient(f.x[i] - f.x[j]);
    });
    const auto boundary = [&](Real psi, const Vec3& xk) {
        const Vec3 xik = f.x[i] - xk;
        const Real p_ik = std::max(p[i] - (hydrostatic ? rho0_g.dot(xik) : 0), Real(0));
        a -= psi * (p[i] + p_ik) / rho0_2 * W.gradient(xik);
    };
    if (p[i] != 0) {
        s.fluid_wall.for_each(i, [&](Index w) { boundary(model.walls.psi[w], model.walls.x[w]); });
        const PorousParticles& porous = state.porous.particles;
        s.fluid_porous.for_each(
            i, [&](Index k) { boundary(state.porous_scratch.psi[k], porous.x[k]); });
    }
    return a * (f.sph_mass[i] / f.mass[i]);
}

TEST(PressureAcceleration, ItsPassGivesM7DensitiesAndTheBoundarySumsThePairByPairForce) {
    test::Simulation sim(R"({
      "name": "wet_corner", "particle_spacing": 0.02,
      "fluid_blocks": [ { "shape": { "type": "box", "min": [0, 0, 0], "max": [0.2, 0.2, 0.2] } } ],
      "walls": [ { "kind": "container",
                   "shape": { "type": "box", "min": [0, 0, 0], "max": [0.3, 0.3, 0.3] } } ],
      "porous_solids": [ { "shape": { "type": "box", "min": [0.2, 0, 0], "max": [0.28, 0.2, 0.2] },
                           "material": { "porosity": 0.3, "permeability": 1e-9 } } ]
    })");
    for (int k = 0; k < 3; ++k) sim.advance();  // moved off the lattice a little
    Model& model = sim.model;
    State& state = sim.state;
    update_fluid_neighbours(model, state);
    update_porous_neighbours(model, state);
    update_porous_boundary_volumes(model, state);
    update_density_and_pair_coefficients(model, state);
    const FluidParticles& f = state.fluid;
    std::vector<Real> rho;
    compute_density(model, state, f.x, rho);
    Real rho_worst = 0;
    for (Index i = 0; i < f.size(); ++i)
        rho_worst = std::max(rho_worst, std::abs(f.rho[i] - rho[i]));
    EXPECT_LT(rho_worst, 1e-12 * model.rho0) << "kg/m^3";
    // Pressures from 0 to twice the hydrostatic span of a support radius (rho0 g h = 392 Pa):
    // the low ones clamp p_ik of the boundary particles above i, the high ones none.
    std::mt19937 random(7);
    std::uniform_real_distribution<Real> pressure(0, 800);
    std::vector<Real> p(f.size());
    for (Real& pi : p) pi = random() % 5 == 0 ? 0 : pressure(random);
    Index boundary_pairs = 0, clamped = 0;
    Real worst = 0, scale = 0;
    for (Index i = 0; i < f.size(); ++i) {
        const Index n = state.scratch.fluid_wall.count[i] + state.scratch.fluid_porous.count[i];
        boundary_pairs += n;
        if (n > 0 && p[i] + state.scratch.boundary_sums.lowest[i] < 0) ++clamped;
        for (const bool hydrostatic : {true, false}) {
            const Vec3 exact = by_pairs(model, state, p, i, hydrostatic);
            const Vec3 a = pressure_acceleration(
                model, state, p, i,
                hydrostatic ? BoundaryPressure::Hydrostatic : BoundaryPressure::Mirrored);
            worst = std::max(worst, (a - exact).norm());
            scale = std::max(scale, exact.norm());
        }
    }
    ASSERT_GT(boundary_pairs, 1000) << "the scene has boundary pairs to sum";
    ASSERT_GT(clamped, 20) << "some particles take the clamped pair terms";
    ASSERT_GT(scale, 1.0) << "m/s^2";
    EXPECT_LT(worst, 1e-12 * scale);
}

}  // namespace
}  // namespace karst
