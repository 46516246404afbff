// Dissolution (docs/method.md §4.8): saturated, high-porosity particles become muddy fluid, with
// water, solute (the grains) and momentum conserved exactly.
#include "karst/core/parallel.hpp"
#include "karst/porous/dissolution.hpp"

#include <gtest/gtest.h>

namespace karst {
namespace {

TEST(Dissolution, ConvertsOnlySaturatedHighPorosityParticlesAndConservesMassSoluteAndMomentum) {
    const Real dx = 0.02, V = dx * dx * dx, rho0 = 1000, mf0 = rho0 * V;
    PoreWaterLaw law;
    PorousParticles porous;
    // Four particles: (phi, S) = (0.7, 1.0) dissolves; (0.7, 0.9) too dry; (0.3, 1.0) too dense
    // a rock; (0.9, 0.99) dissolves and, with heavy grains, splits into pieces.
    const Real phi[4] = {0.7, 0.7, 0.3, 0.9}, S[4] = {1.0, 0.9, 1.0, 0.99},
               rho_s[4] = {2650, 2650, 2650, 30000};
    for (int i = 0; i < 4; ++i) {
        porous.x.push_back(Vec3(i * dx, 0, 0)), porous.v.push_back(Vec3(0.1 * i, -0.2, 0.3));
        porous.volume.push_back(V), porous.porosity.push_back(phi[i]);
        porous.absorbed_mass.push_back(S[i] * rho0 * phi[i] * V),
            porous.solid_mass.push_back(rho_s[i] * (1 - phi[i]) * V);
        porous.permeability.push_back(Mat3::Identity() * 1e-10), porous.fragment.push_back(0);
    }
    FluidParticles fluid;  // one particle already there
    fluid.x = {Vec3(0, 1, 0)}, fluid.v = {Vec3::Zero()}, fluid.mass = {mf0}, fluid.sph_mass = {mf0},
    fluid.solute = {0}, fluid.drained = {0}, fluid.rho = {rho0}, fluid.p = {0},
    fluid.p_divergence = {0}, fluid.id = {0};
    auto totals = [&] {
        Real mass = 0, solute = 0;
        Vec3 momentum = Vec3::Zero();
        for (Index i = 0; i < porous.size(); ++i) {
            mass += porous.absorbed_mass[i] + porous.solid_mass[i], solute += porous.solid_mass[i];
            momentum += (porous.absorbed_mass[i] + porous.solid_mass[i]) * porous.v[i];
        }
        for (Index i = 0; i < fluid.size(); ++i)
            mass += fluid.mass[i], momentum += fluid.mass[i] * fluid.v[i];
        // Solute counts grains still in the rock plus solute in the fluid.
        for (Index i = 0; i < fluid.size(); ++i) solute += fluid.solute[i];
        return std::tuple{mass, solute, momentum};
    };
    const auto [mass0, solute0, momentum0] = totals();
    std::int64_t next_id = 1;
    const DissolutionReport r =
        dissolve(porous, fluid, {&law, 1}, {{{0.98, 0.6, 2650}}, mf0, dx}, next_id);
    EXPECT_EQ(r.dissolved, 2);
    ASSERT_EQ(porous.size(), 2);
    EXPECT_EQ(porous.x[0], Vec3(dx, 0, 0));
    EXPECT_EQ(porous.x[1], Vec3(2 * dx, 0, 0));
    const Real heavy = 30000 * 0.1 * V + 0.99 * rho0 * 0.9 * V;
    EXPECT_EQ(r.fluid_created, 1 + Index(std::ceil(heavy / mf0)));
    EXPECT_EQ(fluid.size(), 1 + r.fluid_created);
    EXPECT_EQ(next_id, 1 + r.fluid_created);
    const auto [mass1, solute1, momentum1] = totals();
    EXPECT_NEAR(mass1, mass0, 1e-15 * mass0);
    EXPECT_NEAR(solute1, solute0, 1e-15 * solute0);
    EXPECT_LT((momentum1 - momentum0).norm(), 1e-15 * momentum0.norm());
    // The first new particle is the light one: C = m_s / (m_s + m_p).
    const Real ms = 2650 * 0.3 * V, mp = 0.7 * rho0 * V;
    EXPECT_NEAR(fluid.solute[1] / fluid.mass[1], ms / (ms + mp), 1e-14);
    for (Index i = 2; i < fluid.size(); ++i)
        EXPECT_LE(fluid.mass[i], 1.0001 * mf0) << "pieces are at most m_f0";
}

}  // namespace
}  // namespace karst
