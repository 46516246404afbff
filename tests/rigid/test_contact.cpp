// Contact springs between fragments (docs/method.md §4.2): exact momentum exchange, the chosen
// restitution, and no force inside a fragment.
#include "karst/rigid/contact.hpp"

#include <gtest/gtest.h>

namespace karst {
namespace {

/// Two particles of mass m in fragments 0 and 1 approaching head-on at +-v0 along x.
struct Collision {
    PorousParticles p;
    NeighbourLists pairs;
    Real m = 0.008;
    Collision(Real gap, Real v0, Index second_fragment) {
        p.x = {Vec3(0, 0, 0), Vec3(gap, 0, 0)};
        p.v = {Vec3(v0, 0, 0), Vec3(-v0, 0, 0)};
        p.fragment = {0, second_fragment}, p.origin = {0, 1};
        p.volume = p.porosity = p.absorbed_mass = p.solid_mass = {0, 0};
        p.permeability = {Mat3::Zero(), Mat3::Zero()};
        pairs.capacity = 1, pairs.index = {1, 0}, pairs.count = {1, 1};
    }
};

TEST(Contact, HeadOnCollisionConservesMomentumAndRebounds) {
    const Real dx = 0.02;
    Collision c(dx, 0.5, 1);
    const ContactLaw law = ContactLaw::for_fragments(dx, 1.0, 9.81, c.m, 0.2);
    const Real dt = 1e-6;
    Real closest = dx;
    for (int step = 0; step < 200000; ++step) {
        std::vector<Vec3> force(2, Vec3::Zero());
        add_contact_forces(c.p, c.pairs, law, force);
        ASSERT_EQ(force[0], Vec3(-force[1])) << "forces are equal and opposite";
        for (int i = 0; i < 2; ++i) c.p.v[i] += dt * force[i] / c.m, c.p.x[i] += dt * c.p.v[i];
        closest = std::min(closest, (c.p.x[1] - c.p.x[0]).norm());
        if ((c.p.x[1] - c.p.x[0]).norm() > dx && c.p.v[1][0] > 0) break;  // separated
    }
    EXPECT_LT(std::abs(c.p.v[0][0] + c.p.v[1][0]), 1e-12) << "total momentum stays 0";
    const Real e = (c.p.v[1][0] - c.p.v[0][0]) / (2 * 0.5);
    EXPECT_NEAR(e, 0.2, 0.03) << "restitution";
    EXPECT_GT(closest, 0.5 * dx) << "the spring keeps fragments apart";
}

TEST(Contact, NoForceWithinOneFragment) {
    Collision c(0.5 * 0.02, 1.0, 0);
    std::vector<Vec3> force(2, Vec3::Zero());
    EXPECT_EQ(
        add_contact_forces(c.p, c.pairs, ContactLaw::for_fragments(0.02, 1, 9.81, c.m), force), 0);
    EXPECT_EQ(force[0], Vec3::Zero());
}

}  // namespace
}  // namespace karst
