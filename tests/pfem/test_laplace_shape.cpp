// Laplace (non-Sibsonian) shape functions, M21: barycentric on a tet, partition of unity and
// linear precision on a polyhedron (the properties the patch test needs).
#include "karst/pfem/laplace_shape.hpp"
#include "karst/pfem/p1_tet.hpp"

#include <gtest/gtest.h>

#include <random>

namespace karst {
namespace {

TEST(LaplaceShape, ReducesToBarycentricCoordinatesOnATet) {
    const std::vector<Vec3> tet{{0, 0, 0}, {1.1, 0.1, 0}, {0.2, 0.9, 0.1}, {0.3, 0.2, 1.2}};
    std::mt19937 random(3);
    std::uniform_real_distribution<Real> u(0.05, 1);
    for (int trial = 0; trial < 20; ++trial) {
        Real w[4], sum = 0;
        for (Real& wi : w) sum += wi = u(random);
        Vec3 x = Vec3::Zero();
        for (int a = 0; a < 4; ++a) x += (w[a] / sum) * tet[a];
        std::vector<Real> N(4);
        laplace_shape(tet, x, N);
        for (int a = 0; a < 4; ++a)
            ASSERT_NEAR(N[a], w[a] / sum, 1e-12) << "trial " << trial << " node " << a;
    }
}

TEST(LaplaceShape, PartitionOfUnityAndLinearPrecisionOnAJitteredCube) {
    std::mt19937 random(5);
    std::uniform_real_distribution<Real> jitter(-0.05, 0.05), inside(0.2, 0.8);
    std::vector<Vec3> cube;
    for (int k = 0; k < 2; ++k)
        for (int j = 0; j < 2; ++j)
            for (int i = 0; i < 2; ++i)
                cube.push_back(Vec3(i, j, k) +
                               Vec3(jitter(random), jitter(random), jitter(random)));
    for (int trial = 0; trial < 20; ++trial) {
        const Vec3 x(inside(random), inside(random), inside(random));
        std::vector<Real> N(8);
        std::vector<Vec3> grad(8);
        laplace_shape_and_gradient(cube, x, 1e-5, N, grad);
        Real sum = 0;
        Vec3 reproduced = Vec3::Zero(), grad_sum = Vec3::Zero();
        Mat3 grad_x = Mat3::Zero();
        for (int a = 0; a < 8; ++a) {
            ASSERT_GE(N[a], 0);
            sum += N[a], reproduced += N[a] * cube[a], grad_sum += grad[a],
                grad_x += cube[a] * grad[a].transpose();
        }
        EXPECT_NEAR(sum, 1, 1e-12);
        EXPECT_LT((reproduced - x).norm(), 1e-12);
        EXPECT_LT(grad_sum.norm(), 1e-8);
        EXPECT_LT((grad_x - Mat3::Identity()).norm(), 1e-7);
    }
}

}  // namespace
}  // namespace karst
