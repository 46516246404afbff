#pragma once
// Free fragments inside the fluid's pressure solve (interlinked coupling after Gissler et al.
// 2019): each iteration the fragments take the reaction of the current pressures, and the fluid
// sees their members move with it. The fragment's inertia is then part of the solve, and the
// pressure that stops a fragment is bounded by what stopping it needs.
#include "karst/sim/model.hpp"
#include "karst/sim/state.hpp"
#include "karst/sph/pressure_acceleration.hpp"

#include <vector>

namespace karst {

class FragmentResponse {
public:
    /// The free fragments' velocities before this solve's pressure: their present ones, plus
    /// dt g when the solve includes the step's other forces (DFSPH's density solve, PCISPH), plus
    /// dt times the reaction of `earlier` (the divergence pressure, read mirrored) when given.
    FragmentResponse(const Model& model, const State& state, Real dt, bool with_gravity,
                     const std::vector<Real>* earlier);

    /// False when no free fragment touches the fluid: the members keep their velocities.
    bool active() const { return m_active; }

    /// Every porous member's velocity once its fragment has taken the reaction of the fluid
    /// pressures p over dt (anchored members keep theirs).
    void member_velocities(const Model& model, const State& state, const std::vector<Real>& p,
                           BoundaryPressure boundary, std::vector<Vec3>& v) const;

private:
    /// The pressure reaction on each free fragment (force, torque about its centre), summed in
    /// member order so that it does not depend on the thread count.
    void add_reactions(const Model& model, const State& state, const std::vector<Real>& p,
                       BoundaryPressure boundary, std::vector<Vec3>& force,
                       std::vector<Vec3>& torque) const;

    Real m_dt = 0;
    bool m_active = false;
    std::vector<Vec3> m_velocity;              ///< per fragment, before this solve's pressure, m/s
    std::vector<Vec3> m_angular_momentum;      ///< per fragment, likewise, kg m^2/s
    std::vector<Mat3> m_inverse_inertia;       ///< per fragment, world frame
    mutable std::vector<Vec3> m_member_force;  ///< per porous member, N
};

/// How far the free fragments that fluid particle i touches give way to its pressure, per unit
/// m_i: a fragment F adds |B_F|^2 / M_F + T_F.I_F^-1 T_F, with B_F = 2 sum_{k in F} Psi_k grad
/// W_ik and T_F = sum_{k in F} (x_k - c_F) x 2 Psi_k grad W_ik. A pressure solve adds m_i times
/// it to its diagonal: without it a light fragment took the Jacobi update's over-shoot, and the
/// solve diverged. Reads the step's pair factors.
class FragmentMobility {
public:
    explicit FragmentMobility(const State& state);
    Real at(const Model& model, const State& state, Index i) const;

private:
    std::vector<Mat3> m_inverse_inertia;  ///< per fragment, world frame; zero when anchored
};

}  // namespace karst
