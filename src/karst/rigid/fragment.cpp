#include "karst/rigid/fragment.hpp"

#include "karst/core/check.hpp"

#include <Eigen/LU>

namespace karst {

Vec3 Fragment::angular_velocity() const {
    return world_inertia().inverse() * angular_momentum;
}

Fragment fragment_at_rest(std::span<const Vec3> x, std::span<const Real> mass,
                          std::vector<Vec3>& body_positions, Real spacing) {
    KARST_CHECK(x.size() == mass.size() && !x.empty());
    Fragment f;
    Vec3 moment = Vec3::Zero();
    for (size_t k = 0; k < x.size(); ++k) f.mass += mass[k], moment += mass[k] * x[k];
    KARST_CHECK(f.mass > 0);
    f.centre = moment / f.mass;
    body_positions.resize(x.size());
    f.body_inertia.setZero();
    for (size_t k = 0; k < x.size(); ++k) {
        const Vec3 X = x[k] - f.centre;
        body_positions[k] = X;
        f.body_inertia += member_inertia(mass[k], X, spacing);
    }
    return f;
}

void integrate_fragment(Fragment& f, const Vec3& force, const Vec3& torque, Real dt) {
    if (f.anchored) return;
    f.velocity += dt * force / f.mass;
    f.centre += dt * f.velocity;
    f.angular_momentum += dt * torque;
    const Vec3 omega = f.angular_velocity();
    const Eigen::Quaterniond spin(0, omega[0], omega[1], omega[2]);
    Eigen::Quaterniond q = f.rotation;
    q.coeffs() += (0.5 * dt) * (spin * f.rotation).coeffs();
    f.rotation = q.normalized();
}

}  // namespace karst
