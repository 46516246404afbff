#pragma once
// The force between a fluid particle i and a boundary particle k (a static wall or a porous
// particle of a fragment), per unit mass of i. The fluid side and the reaction on the boundary
// side call the same functions with the same operands, so each pair's two forces are bitwise
// opposite and momentum passes to the fragments exactly (docs/method.md §4.2, §4.3).
#include "karst/core/types.hpp"
#include "karst/sph/kernels.hpp"

#include <algorithm>
#include <cmath>

namespace karst {

/// c_ik = Psi_k / rho0^2 dW/dr / r of the pressure term, m/kg.
inline Real boundary_pressure_coefficient(Real psi, Real inv_rho0_2, const CubicKernel& W,
                                          const Vec3& x_ik) {
    return psi * inv_rho0_2 * W.dw_over_r(x_ik.norm());
}

/// Pressure term of pair (i, k) in a_i^p = -sum_k (p_i + p_ik) c_ik x_ik, with c_ik =
/// Psi_k / rho0^2 dW/dr / r and the boundary pressure extrapolated hydrostatically,
/// p_ik = max(p_i - rho0 g.x_ik, 0) (sph/pcisph.cpp says why); `hydrostatic` is -rho0 g.x_ik.
inline Vec3 boundary_pressure_term(Real p_i, Real coefficient, Real hydrostatic, const Vec3& x_ik) {
    const Real p_ik = std::max(p_i + hydrostatic, Real(0));
    return ((p_i + p_ik) * coefficient) * x_ik;
}

/// What the friction and adhesion with a boundary need, fixed for a step.
struct BoundaryShear {
    Real friction = 0;     ///< sigma_f
    Real adhesion = 0;     ///< beta_adh
    Real sound_speed = 0;  ///< c_s, m/s
    Real h = 0;            ///< support radius, m
    bool any() const { return friction > 0 || adhesion > 0; }
};

/// Friction (Akinci 2012, Pi_ik = -nu_b min(v_ik.x_ik, 0) / (r^2 + 0.01 h^2), nu_b = sigma_f h c_s
/// / (2 rho_i)) and adhesion (Akinci 2013, M10) acceleration of fluid particle i from boundary
/// particle k of weight `psi`; v_ik is the velocity of i relative to k.
inline Vec3 boundary_shear_acceleration(const BoundaryShear& b, const CubicKernel& W,
                                        const Vec3& x_ik, const Vec3& v_ik, Real rho_i, Real psi) {
    const Real r2 = x_ik.squaredNorm(), r = std::sqrt(r2);
    Vec3 a = Vec3::Zero();
    if (b.friction > 0) {
        const Real nu_b = b.friction * b.h * b.sound_speed / (2 * rho_i);
        const Real pi_ik = -nu_b * std::min(v_ik.dot(x_ik), Real(0)) / (r2 + 0.01 * b.h * b.h);
        a -= (psi * pi_ik * W.dw_over_r(r)) * x_ik;
    }
    if (b.adhesion > 0 && r > 1e-9 * b.h)
        a -= (b.adhesion * psi * adhesion_kernel(r, b.h) / r) * x_ik;
    return a;
}

}  // namespace karst
