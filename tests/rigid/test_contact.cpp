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

/// Fragments 0 and 1 of mass 1 kg, free or anchored.
std::vector<Fragment> two_fragments(bool first_anchored, bool second_anchored) {
    std::vector<Fragment> f(2);
    f[0].mass = f[1].mass = 1;
    f[0].anchored = first_anchored, f[1].anchored = second_anchored;
    return f;
}

TEST(Contact, APairACrackLeftShortPushesOnlyWhenItClosesFurther) {
    const Real dx = 0.02;
    Collision c(0.9 * dx, 0.0, 1);
    c.p.id = {10, 11};
    const ContactLaw law = ContactLaw::for_fragments(dx, 1.0, 9.81, c.m, 0.2);
    // One body that a crack split into the free fragments 0 and 1, 0.9 dx apart.
    std::vector<CrackContact> cracked;
    const std::vector<char> both{1, 1}, copies{0, 1};
    const std::vector<Vec3> before{Vec3(0, 0, 0), Vec3(dx, 0, 0)};
    rest_after_split(cracked, c.p, two_fragments(false, false), {both, copies, before, c.p.x}, dx);
    ASSERT_EQ(cracked.size(), 1u);
    EXPECT_EQ(cracked[0].lo, 10);
    EXPECT_EQ(cracked[0].hi, 11);
    EXPECT_NEAR(cracked[0].rest, 0.9 * dx, 1e-15);
    const auto force_at = [&](Real gap) {
        c.p.x[1] = Vec3(gap, 0, 0);
        std::vector<Vec3> force(2, Vec3::Zero());
        add_contact_forces(c.p, c.pairs, law, force, {}, cracked);
        return force[1][0];
    };
    EXPECT_EQ(force_at(0.9 * dx), 0) << "the spring starts unloaded where the crack left it";
    EXPECT_EQ(force_at(0.95 * dx), 0) << "and does not pull the pieces together";
    EXPECT_NEAR(force_at(0.85 * dx), law.stiffness * 0.05 * dx, 1e-9 * law.stiffness * dx);
    std::vector<Vec3> force(2, Vec3::Zero());
    c.p.x[1] = Vec3(0.85 * dx, 0, 0);
    add_contact_forces(c.p, c.pairs, law, force);
    EXPECT_NEAR(force[1][0], law.stiffness * 0.15 * dx, 1e-9 * law.stiffness * dx)
        << "without the entry, the law's d0";

    std::vector<CrackContact> kept = cracked;
    c.p.x[1] = Vec3(0.99 * dx, 0, 0);
    forget_parted_pairs(kept, c.p, c.p.x, dx);
    EXPECT_EQ(kept.size(), 1u) << "kept until the pair parts by d0";
    c.p.x[1] = Vec3(dx, 0, 0);
    forget_parted_pairs(kept, c.p, c.p.x, dx);
    EXPECT_TRUE(kept.empty()) << "then the law's d0 holds again";
    kept = cracked;
    c.p.fragment[1] = 0;
    forget_parted_pairs(kept, c.p, c.p.x, dx);
    EXPECT_TRUE(kept.empty()) << "a pair merged into one fragment is forgotten";
}

TEST(Contact, ASplitLoadsNoSpring) {
    const Real dx = 0.02;
    // Particle 0 belongs to the anchored body the crack split (fragment 0); particle 1 is a free
    // fragment resting on it, sunk 0.05 dx. The split's offset moved particle 0 another 0.05 dx
    // closer.
    Collision c(0.9 * dx, 0.0, 1);
    c.p.id = {3, 4};
    const std::vector<char> body{1, 0}, kept_id{0, 0}, new_id{1, 0};
    const std::vector<Vec3> before{Vec3(-0.05 * dx, 0, 0), Vec3(0.9 * dx, 0, 0)};
    const std::vector<Fragment> resting = two_fragments(true, false);
    std::vector<CrackContact> pairs;
    rest_after_split(pairs, c.p, resting, {body, kept_id, before, c.p.x}, dx);
    ASSERT_EQ(pairs.size(), 1u);
    EXPECT_NEAR(pairs[0].rest, 0.95 * dx, 1e-15) << "the same 0.05 dx of load, none added";
    rest_after_split(pairs, c.p, resting, {body, kept_id, c.p.x, c.p.x}, dx);
    EXPECT_NEAR(pairs[0].rest, 0.95 * dx, 1e-15) << "a split that did not move it keeps it";

    std::vector<CrackContact> fresh;
    rest_after_split(fresh, c.p, resting, {body, new_id, before, c.p.x}, dx);
    ASSERT_EQ(fresh.size(), 1u);
    EXPECT_NEAR(fresh[0].rest, 0.9 * dx, 1e-15)
        << "a copy beside its parent starts unloaded, or the split doubles the spring's load";

    std::vector<CrackContact> none;
    rest_after_split(none, c.p, two_fragments(true, true), {body, kept_id, before, c.p.x}, dx);
    EXPECT_TRUE(none.empty()) << "two anchored fragments have no spring";
    rest_after_split(none, c.p, two_fragments(false, true), {body, kept_id, before, c.p.x}, dx);
    ASSERT_EQ(none.size(), 1u);
    EXPECT_NEAR(none[0].rest, 0.9 * dx, 1e-15)
        << "freed beside an anchored fragment, where no spring acted: unloaded";
    none.clear();
    const std::vector<Vec3> apart{Vec3(0.1 * dx, 0, 0), Vec3(0.9 * dx, 0, 0)};
    rest_after_split(none, c.p, resting, {body, kept_id, apart, c.p.x}, dx);
    EXPECT_TRUE(none.empty()) << "a split that moved it away leaves the law's d0";
    c.p.origin = {3, 3};
    const std::vector<char> both{1, 1};
    rest_after_split(none, c.p, two_fragments(false, false), {both, kept_id, c.p.x, c.p.x}, dx);
    EXPECT_TRUE(none.empty()) << "no spring between halves of one split particle";
}

}  // namespace
}  // namespace karst
