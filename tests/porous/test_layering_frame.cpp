// Weighted PCA frames (docs/method.md §6.2, M28): the layering normal of a tilted slab, and M28's
// kernel tensor (inverse spread, unit determinant, the few-neighbour case).
#include "karst/porous/layering_frame.hpp"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <numbers>

namespace karst {
namespace {

TEST(LayeringFrame, WeightedPcaFindsTheNormalOfATiltedSlab) {
    const Real dx = 0.01, h = 2 * dx;
    const Mat3 tilt = (Eigen::AngleAxisd(0.4, Vec3(1, 2, 0).normalized()) *
                       Eigen::AngleAxisd(std::numbers::pi / 5, Vec3::UnitZ()))
                          .toRotationMatrix();
    std::vector<Vec3> x;
    for (int k = 0; k < 3; ++k)  // a sheet three particles thick
        for (int j = 0; j < 30; ++j)
            for (int i = 0; i < 30; ++i) x.push_back(tilt * (dx * Vec3(i, j, k)));
    const Vec3 normal = tilt * Vec3::UnitZ();
    const auto frames = pca_frames(x, h);
    int checked = 0;
    for (size_t p = 0; p < x.size(); ++p) {
        const Vec3 local = (tilt.transpose() * x[p] / dx).array().round();  // lattice coordinates
        if (local[0] < 5 || local[0] > 24 || local[1] < 5 || local[1] > 24)
            continue;  // away from the rim
        ASSERT_TRUE(frames[p].reliable());
        ASSERT_GT(std::abs(frames[p].normal().dot(normal)), std::cos(2 * std::numbers::pi / 180))
            << "particle " << p;
        ++checked;
    }
    EXPECT_EQ(checked, 3 * 20 * 20);
}

TEST(LayeringFrame, M28KernelStretchesAlongTheSpreadWithUnitVolume) {
    const Real h = 0.02;
    PcaFrame frame;
    frame.neighbours = 40;
    frame.axes = Eigen::AngleAxisd(0.7, Vec3(1, 1, 1).normalized()).toRotationMatrix();
    frame.spread = Vec3(4e-4, 2e-4, 1e-5);  // sigma_3 is clamped up to sigma_1 / 4
    const Mat3 G = pca_kernel_tensor(frame, h);
    EXPECT_NEAR(G.determinant() * h * h * h, 1, 1e-12);
    // The inverse: the kernel reaches farther (|G e| smaller) along the largest spread.
    const Real along = (G * frame.axes.col(0)).norm(), across = (G * frame.axes.col(2)).norm();
    EXPECT_NEAR(across / along, 4, 1e-9);
    frame.neighbours = 10;  // too few: G = I / (k_n h)
    EXPECT_LT((pca_kernel_tensor(frame, h) - Mat3::Identity() / (0.5 * h)).norm(), 1e-9);
}

}  // namespace
}  // namespace karst
