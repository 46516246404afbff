#pragma once
// Fragments as rigid bodies (docs/method.md §4.5): mass properties from the members (wet mass
// included), and the integration of one step. The state carries the angular momentum L rather
// than omega, so a torque-free fragment keeps L exactly (an explicit update of omega with the
// gyroscopic term does not).
#include "karst/core/types.hpp"

#include <Eigen/Geometry>

#include <span>
#include <vector>

namespace karst {

struct Fragment {
    Vec3 centre = Vec3::Zero();                                    ///< c, m
    Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();  ///< q: body -> world
    Vec3 velocity = Vec3::Zero();                                  ///< v, m/s
    Vec3 angular_momentum = Vec3::Zero();                          ///< L, kg m^2/s (world)
    Real mass = 0;                                                 ///< M, kg
    Mat3 body_inertia = Mat3::Identity();  ///< I0 about c, body frame, kg m^2
    bool anchored = false;

    Mat3 rotation_matrix() const { return rotation.toRotationMatrix(); }
    /// I_w = R I0 R^T.
    Mat3 world_inertia() const {
        const Mat3 R = rotation_matrix();
        return R * body_inertia * R.transpose();
    }
    /// omega = I_w^-1 L.
    Vec3 angular_velocity() const;
    /// v + omega x (x - c): the velocity of a member at world position x.
    Vec3 point_velocity(const Vec3& x) const {
        return velocity + angular_velocity().cross(x - centre);
    }
};

/// Mass, centre and body inertia I0 = sum m (|X|^2 I - X X^T + s^2/6 I) of members with masses
/// `mass` at world positions `x`, with the fragment at rest orientation (R = I); `spacing` s is
/// the edge of the cube each member fills (its own inertia m s^2/6 keeps I0 invertible for one
/// or a line of members). Returns the fragment at rest, and writes each member's body-frame
/// position X = x - c.
Fragment fragment_at_rest(std::span<const Vec3> x, std::span<const Real> mass,
                          std::vector<Vec3>& body_positions, Real spacing = 0);

/// One member's share of I0: m (|X|^2 I - X X^T + s^2/6 I).
inline Mat3 member_inertia(Real m, const Vec3& X, Real spacing) {
    return m * ((X.squaredNorm() + spacing * spacing / 6) * Mat3::Identity() - X * X.transpose());
}

/// One step (§4.5): v += dt F / M, c += dt v; L += dt tau, omega = I_w^-1 L,
/// q <- normalise(q + dt/2 (0, omega) q). Anchored fragments do not move.
void integrate_fragment(Fragment& fragment, const Vec3& force, const Vec3& torque, Real dt);

}  // namespace karst
