#pragma once
// SPH kernels with support radius h (W = 0 for r >= h), docs/method.md §1.1.
#include "karst/core/types.hpp"

#include <cmath>
#include <numbers>

namespace karst {

/// Cubic spline (Monaghan; SPlisHSPlasH CubicKernel) with support h, used for the fluid density,
/// pressure and viscosity operators. W = k(6q^3 - 6q^2 + 1) for q <= 1/2, 2k(1 - q)^3 for
/// q <= 1, k = 8/(pi h^3), q = r/h. Units 1/m^3.
class CubicKernel {
public:
    explicit CubicKernel(Real h)
        : m_h(h),
          m_inv_h(1 / h),
          m_k(8 / (std::numbers::pi * h * h * h)),
          m_l(48 / (std::numbers::pi * h * h * h)) {}

    Real h() const { return m_h; }
    Real w0() const { return m_k; }

    Real w(Real r) const {
        const Real q = r * m_inv_h;
        if (q <= 0.5) return m_k * (6 * q * q * q - 6 * q * q + 1);
        if (q <= 1) return 2 * m_k * (1 - q) * (1 - q) * (1 - q);
        return 0;
    }

    /// dW/dr divided by r (1/m^5): grad W(x) = x * dw_over_r(|x|). Zero at r = 0.
    Real dw_over_r(Real r) const {
        const Real q = r * m_inv_h;
        if (r <= 1e-9 * m_h || q >= 1) return 0;
        const Real dq = m_inv_h / r;  // (dq/dr) / r
        if (q <= 0.5) return m_l * q * (3 * q - 2) * dq;
        return -m_l * (1 - q) * (1 - q) * dq;
    }

    Vec3 gradient(const Vec3& x) const { return x * dw_over_r(x.norm()); }

    struct ValueAndSlope {
        Real w, dw_over_r;
    };
    /// w(r) and dw_over_r(r) from one q: a pass that needs both per pair computes r once.
    ValueAndSlope w_and_dw_over_r(Real r) const {
        const Real q = r * m_inv_h;
        if (q >= 1) return {0, 0};
        const Real dq = r <= 1e-9 * m_h ? 0 : m_inv_h / r;
        if (q <= 0.5) return {m_k * (6 * q * q * q - 6 * q * q + 1), m_l * q * (3 * q - 2) * dq};
        const Real t = 1 - q;
        return {2 * m_k * t * t * t, -m_l * t * t * dq};
    }

private:
    Real m_h, m_inv_h, m_k, m_l;
};

/// M1: spiky kernel W = 15/(pi h^6) (h - r)^3, grad W = -45/(pi h^6) (h - r)^2 r_hat.
class SpikyKernel {
public:
    explicit SpikyKernel(Real h) : m_h(h), m_c(15 / (std::numbers::pi * std::pow(h, 6))) {}
    Real w(Real r) const { return r < m_h ? m_c * (m_h - r) * (m_h - r) * (m_h - r) : 0; }
    Vec3 gradient(const Vec3& x) const {
        const Real r = x.norm();
        if (r >= m_h || r <= 0) return Vec3::Zero();
        return (-3 * m_c * (m_h - r) * (m_h - r) / r) * x;
    }

private:
    Real m_h, m_c;
};

/// M9: Akinci 2013 cohesion kernel, with 32/(pi h^9) on both branches so C is continuous at h/2.
inline Real cohesion_kernel(Real r, Real h) {
    if (r <= 0 || r > h) return 0;
    const Real c = 32 / (std::numbers::pi * std::pow(h, 9));
    const Real t = (h - r) * (h - r) * (h - r) * r * r * r;
    if (r > 0.5 * h) return c * t;
    return c * (2 * t - std::pow(h, 6) / 64);
}

/// M10: Akinci 2013 adhesion kernel, A = 0.007/h^3.25 (-4r^2/h + 6r - 2h)^(1/4) on (h/2, h].
inline Real adhesion_kernel(Real r, Real h) {
    if (r <= 0.5 * h || r > h) return 0;
    // The polynomial is zero at r = h; rounding can make it -1e-18 there, and pow would give NaN.
    return 0.007 / std::pow(h, 3.25) *
           std::pow(std::max(-4 * r * r / h + 6 * r - 2 * h, Real(0)), 0.25);
}

}  // namespace karst
