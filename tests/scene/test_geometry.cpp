#include "karst/scene/geometry.hpp"

#include <gtest/gtest.h>

#include <numbers>

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
