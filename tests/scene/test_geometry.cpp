#include "karst/scene/geometry.hpp"

#include <gtest/gtest.h>

#include <numbers>
#include <utility>

namespace karst {
namespace {

TEST(Geometry, SampledVolumesMatchShapes) {
    const Real dx = 0.01;
    Shape sphere{Shape::Kind::Sphere, Vec3(0.3, 0.2, 0.1), Vec3::Zero(), 0.1, {}};
    const double n = double(sample_lattice(sphere, dx, -INFINITY, 0).size());
    EXPECT_NEAR(n * dx * dx * dx, 4.0 / 3 * std::numbers::pi * 1e-3, 0.02 * 4.19e-3);
    Shape cyl{Shape::Kind::Cylinder, Vec3(0, 0, 0), Vec3(0, 0, 0.2), 0.05, {}};
    const double c = double(sample_lattice(cyl, dx, -INFINITY, 0).size());
    EXPECT_NEAR(c * dx * dx * dx, std::numbers::pi * 0.05 * 0.05 * 0.2, 0.03 * 1.57e-3);
    // Box minus sphere: the difference removes the sphere's lattice points.
    Shape box{Shape::Kind::Box, Vec3(0.2, 0.1, 0.0), Vec3(0.4, 0.3, 0.2), 0, {}};
    Shape diff{Shape::Kind::Difference, {}, {}, 0, {box, sphere}};
    const double b = double(sample_lattice(box, dx, -INFINITY, 0).size());
    const double d = double(sample_lattice(diff, dx, -INFINITY, 0).size());
    EXPECT_EQ(b, 20.0 * 20 * 20);
    EXPECT_LT(d, b);
    Shape uni{Shape::Kind::Union, {}, {}, 0, {box, sphere}};
    // Inclusion-exclusion: |box u sphere| = |sphere| + |box - sphere|.
    EXPECT_EQ(double(sample_lattice(uni, dx, -INFINITY, 0).size()), n + d);
}

TEST(Geometry, FarApartPartsGiveTheSamePointsAsTheWholeBox) {
    // Two spheres 3 m apart, less a box through the first, at dx 0.05: the difference is sampled
    // in its union's parts' boxes (not the 3.2 m box), solid and a skin outside alike, and gives
    // the whole box's points in the same order.
    const Real dx = 0.05;
    const Shape first{Shape::Kind::Sphere, Vec3(0, 0, 0), Vec3::Zero(), 0.2, {}};
    const Shape second{Shape::Kind::Sphere, Vec3(3, 3, 3), Vec3::Zero(), 0.2, {}};
    const Shape cut{Shape::Kind::Box, Vec3(-0.05, -0.3, -0.3), Vec3(0.05, 0.3, 0.3), 0, {}};
    const Shape both{Shape::Kind::Union, Vec3::Zero(), Vec3::Zero(), 0, {first, second}};
    const Shape diff{Shape::Kind::Difference, Vec3::Zero(), Vec3::Zero(), 0, {both, cut}};
    for (const auto& [lo, hi] : {std::pair<Real, Real>{-INFINITY, 0}, {0, 2 * dx}}) {
        std::vector<LatticeIndex> whole;  // [-10, 70]^3 holds the box, grown by the skin
        for (std::int64_t k = -10; k <= 70; ++k)
            for (std::int64_t j = -10; j <= 70; ++j)
                for (std::int64_t i = -10; i <= 70; ++i) {
                    const Real d = diff.signed_distance(lattice_point({i, j, k}, dx));
                    if (d > lo && d <= hi) whole.push_back({i, j, k});
                }
        const std::vector<LatticeIndex> parts = sample_lattice(diff, dx, lo, hi);
        EXPECT_GT(parts.size(), 0u);
        EXPECT_EQ(parts, whole);
    }
}

TEST(Geometry, SkinOfAContainerAndEstimate) {
    const Real dx = 0.02;
    Shape box{Shape::Kind::Box, Vec3(0, 0, 0), Vec3(0.4, 0.2, 0.2), 0, {}};
    // One layer just outside a 20x10x10 cavity: the 22x12x12 shell.
    const auto skin = sample_lattice(box, dx, 0, dx);
    EXPECT_EQ(skin.size(), size_t(22 * 12 * 12 - 20 * 10 * 10));
    EXPECT_EQ(estimate_lattice_count(box, dx, 0, dx), double(skin.size()));
}

}  // namespace
}  // namespace karst
