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
    /// dt g when the solve includes the step's other forces (DFSPH's density solve), plus dt
    /// times the reaction of `earlier` (the divergence pressure, read mirrored) when given.
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

}  // namespace karst
