#include "karst/sph/kernels.hpp"

#include <gtest/gtest.h>

namespace karst {
namespace {

/// Sum of f over a fine lattice (spacing h/40) covering the support: a quadrature of the integral.
template <class F>
auto lattice_integral(Real h, const F& f) {
    const Real d = h / 40;
    const int n = 41;
    decltype(f(Vec3::Zero())) sum = f(Vec3::Zero()) * 0;
    for (int k = -n; k <= n; ++k)
        for (int j = -n; j <= n; ++j)
            for (int i = -n; i <= n; ++i)
                sum += f(Vec3(i + 0.5, j + 0.5, k + 0.5) * d) * (d * d * d);
    return sum;
}

TEST(CubicKernel, IntegratesToOne) {
    const CubicKernel W(0.04);
    EXPECT_NEAR(lattice_integral(0.04, [&](const Vec3& x) { return W.w(x.norm()); }), 1.0, 1e-4);
}

TEST(CubicKernel, GradientIntegratesToZeroAndMatchesFiniteDifference) {
    const Real h = 0.04;
    const CubicKernel W(h);
    const Vec3 sum = lattice_integral(h, [&](const Vec3& x) { return W.gradient(x); });
    EXPECT_LT(sum.norm(), 1e-9);
    for (Real r : {0.1 * h, 0.3 * h, 0.5 * h, 0.7 * h, 0.95 * h}) {
        const Real e = 1e-7 * h;
        const Real fd = (W.w(r + e) - W.w(r - e)) / (2 * e);
        ASSERT_NE(fd, 0.0);
        EXPECT_NEAR(W.dw_over_r(r) * r, fd, 1e-6 * std::abs(fd)) << "r/h = " << r / h;
    }
    // Gradient points from the neighbour to the particle's outside: -r_hat direction.
    EXPECT_LT(W.gradient(Vec3(0.3 * h, 0, 0))[0], 0);
}

TEST(CubicKernel, ValueAndSlopeFromOneDistanceAreWAndDwOverR) {
    const Real h = 0.04;
    const CubicKernel W(h);
    for (Real r : {0.0, 1e-12, 0.2 * h, 0.5 * h, 0.5000001 * h, 0.8 * h, h, 1.2 * h}) {
        const CubicKernel::ValueAndSlope both = W.w_and_dw_over_r(r);
        EXPECT_EQ(both.w, W.w(r)) << "r/h = " << r / h;
        EXPECT_EQ(both.dw_over_r, W.dw_over_r(r)) << "r/h = " << r / h;
    }
}

TEST(SpikyKernel, M1IntegratesToOneWithNegativeGradient) {
    const Real h = 0.04;
    const SpikyKernel W(h);
    EXPECT_NEAR(lattice_integral(h, [&](const Vec3& x) { return W.w(x.norm()); }), 1.0, 1e-3);
    const Vec3 x(0.2 * h, 0.1 * h, -0.3 * h);
    const Real e = 1e-7 * h;
    for (int d = 0; d < 3; ++d) {
        Vec3 dx = Vec3::Zero();
        dx[d] = e;
        EXPECT_NEAR(W.gradient(x)[d], (W.w((x + dx).norm()) - W.w((x - dx).norm())) / (2 * e),
                    1e-5 * W.gradient(x).norm());
    }
}

TEST(AkinciKernels, CohesionIsContinuousAtHalfSupportAndAdhesionVanishesInside) {
    const Real h = 0.04;
    // M9: the constant multiplies both branches, so there is no jump at h/2.
    EXPECT_NEAR(cohesion_kernel(0.5 * h - 1e-12, h), cohesion_kernel(0.5 * h + 1e-12, h),
                1e-6 * cohesion_kernel(0.5 * h + 1e-12, h));
    EXPECT_LT(cohesion_kernel(0.05 * h, h), 0);  // repulsive at short range
    EXPECT_GT(cohesion_kernel(0.75 * h, h), 0);
    EXPECT_EQ(cohesion_kernel(1.01 * h, h), 0);
    EXPECT_EQ(adhesion_kernel(0.4 * h, h), 0);
    EXPECT_GT(adhesion_kernel(0.75 * h, h), 0);
    EXPECT_NEAR(adhesion_kernel(h, h), 0, 1e-12);
}

}  // namespace
}  // namespace karst
