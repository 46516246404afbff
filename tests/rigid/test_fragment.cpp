// Rigid fragments (docs/method.md §4.5): mass properties of a particle box, and a free fragment in
// vacuum that keeps its momentum, angular momentum and a unit quaternion.
#include "karst/rigid/fragment.hpp"

#include <gtest/gtest.h>

namespace karst {
namespace {

TEST(Fragment, MassPropertiesOfALatticeBoxMatchTheClosedForm) {
    // n_x x n_y x n_z particles of mass m at spacing d: I_xx = m N d^2 ((n_y^2 - 1) + (n_z^2 - 1))
    // / 12.
    const int nx = 6, ny = 4, nz = 3;
    const Real d = 0.1, m = 2.0;
    std::vector<Vec3> x;
    for (int k = 0; k < nz; ++k)
        for (int j = 0; j < ny; ++j)
            for (int i = 0; i < nx; ++i) x.push_back(Vec3(1 + i * d, -2 + j * d, 0.5 + k * d));
    const std::vector<Real> mass(x.size(), m);
    std::vector<Vec3> body;
    const Fragment f = fragment_at_rest(x, mass, body);
    const Real N = Real(x.size());
    EXPECT_NEAR(f.mass, m * N, 1e-12);
    EXPECT_LT((f.centre - Vec3(1 + 2.5 * d, -2 + 1.5 * d, 0.5 + d)).norm(), 1e-12);
    auto s = [&](int n) { return (n * n - 1) * d * d / 12; };
    EXPECT_NEAR(f.body_inertia(0, 0), m * N * (s(ny) + s(nz)), 1e-12);
    EXPECT_NEAR(f.body_inertia(1, 1), m * N * (s(nx) + s(nz)), 1e-12);
    EXPECT_NEAR(f.body_inertia(2, 2), m * N * (s(nx) + s(ny)), 1e-12);
    EXPECT_NEAR(f.body_inertia(0, 1), 0, 1e-12);
    Vec3 sum = Vec3::Zero();
    for (const Vec3& X : body) sum += X;
    EXPECT_LT(sum.norm(), 1e-12) << "body positions are measured from the centre of mass";
}

TEST(Fragment, FreeFragmentInVacuumKeepsMomentaAndAUnitQuaternion) {
    Fragment f;
    f.mass = 3.0;
    f.body_inertia << 2.0, 0.3, -0.1, 0.3, 1.0, 0.2, -0.1, 0.2, 0.5;  // asymmetric top
    f.velocity = Vec3(0.3, -0.2, 1.0);
    f.angular_momentum = Vec3(0.7, -1.1, 2.3);  // not along a principal axis: it tumbles
    const Vec3 p0 = f.mass * f.velocity, L0 = f.angular_momentum, c0 = f.centre;
    const Eigen::Quaterniond q0 = f.rotation;
    const Real dt = 1e-3;
    for (int step = 0; step < 20000; ++step) integrate_fragment(f, Vec3::Zero(), Vec3::Zero(), dt);
    EXPECT_LT((f.mass * f.velocity - p0).norm(), 1e-14 * p0.norm());
    EXPECT_LT((f.angular_momentum - L0).norm(), 1e-14 * L0.norm());
    EXPECT_NEAR(f.rotation.norm(), 1, 1e-14);
    EXPECT_LT((f.centre - (c0 + 20 * p0 / f.mass)).norm(), 1e-10);
    EXPECT_GT(f.rotation.angularDistance(q0), 0.1) << "it did rotate";
    // Kinetic energy of rotation 1/2 L.omega stays within 1 % over 20 s of tumbling.
    Fragment start;
    start.body_inertia = f.body_inertia, start.angular_momentum = L0;
    const Real e0 = 0.5 * L0.dot(start.angular_velocity()),
               e1 = 0.5 * f.angular_momentum.dot(f.angular_velocity());
    EXPECT_NEAR(e1 / e0, 1, 0.01);
}

TEST(Fragment, AnchoredFragmentDoesNotMove) {
    Fragment f;
    f.mass = 1, f.anchored = true;
    integrate_fragment(f, Vec3(0, 0, -9.81), Vec3(1, 2, 3), 0.1);
    EXPECT_EQ(f.centre, Vec3::Zero());
    EXPECT_EQ(f.velocity, Vec3::Zero());
    EXPECT_EQ(f.angular_momentum, Vec3::Zero());
}

}  // namespace
}  // namespace karst
