// Particle attributes are declared once (issue 12): each set's for_each_attribute lists every
// member, so resize, keep, permute and append cannot leave one behind.
#include "karst/core/soa.hpp"
#include "karst/sim/state.hpp"

#include <gtest/gtest.h>

namespace karst {
namespace {

/// Bytes of the members that for_each_attribute visits.
template <class Set>
size_t listed_bytes() {
    Set set;
    size_t bytes = 0;
    Set::for_each_attribute([&](auto& a) { bytes += sizeof a; }, set);
    return bytes;
}

TEST(ParticleAttributes, EveryMemberOfEachParticleSetIsListedOnce) {
    // Every member is a std::vector, so the struct is exactly the listed vectors (listing one
    // twice or forgetting one changes the sum).
    EXPECT_EQ(listed_bytes<FluidParticles>(), sizeof(FluidParticles));
    EXPECT_EQ(listed_bytes<PorousParticles>(), sizeof(PorousParticles));
}

TEST(ParticleAttributes, ResizeKeepPermuteAndAppendMoveEveryAttributeTogether) {
    FluidParticles f;
    resize_attributes(f, 4);
    ASSERT_TRUE(attributes_sized(f, 4));
    EXPECT_EQ(f.x[3], Vec3::Zero());
    EXPECT_EQ(f.p_divergence[3], 0);
    for (Index i = 0; i < 4; ++i)
        f.id[i] = 10 + i, f.mass[i] = Real(i), f.x[i] = Vec3(Real(i), 0, 0);
    keep_attributes(f, {1, 0, 1, 1});
    ASSERT_TRUE(attributes_sized(f, 3));
    EXPECT_EQ(f.id, (std::vector<std::int64_t>{10, 12, 13}));
    permute_attributes(f, {2, 0, 1});
    EXPECT_EQ(f.id, (std::vector<std::int64_t>{13, 10, 12}));
    EXPECT_EQ(f.mass, (std::vector<Real>{3, 0, 2}));
    EXPECT_EQ(f.x[0], Vec3(3, 0, 0));
    FluidParticles g = f;
    append_attributes(f, g);
    ASSERT_TRUE(attributes_sized(f, 6));
    EXPECT_EQ(f.id[5], 12);
}

}  // namespace
}  // namespace karst
