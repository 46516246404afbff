#pragma once
// The anisotropic spiky kernel of the pore flow (docs/method.md §6, M16): W(x, G) = det(G) w(|G x|)
// with w(q) = (15/pi)(1 - q)^3 on the unit ball, and the pair weight of the conservative flux.
#include "karst/core/types.hpp"

#include <numbers>

namespace karst {

/// M16: F(x, G) = -2 x.grad W(x, G) / (|G x|^2 + 0.01) = (90/pi) det G (1 - q)^2 q / (q^2 + 0.01),
/// q = |G x| < 1; `det_g` is det G, passed in since it is fixed per particle (h^-3 by M13).
inline Real pair_weight(const Vec3& x, const Mat3& G, Real det_g) {
    const Real q = (G * x).norm();
    if (q >= 1) return 0;
    return (90 / std::numbers::pi) * det_g * (1 - q) * (1 - q) * q / (q * q + 0.01);
}

/// c_eps of docs/method.md §4.7.2: d / int |y| (-w'(|y|)) |y|^2 / (|y|^2 + 0.01) dy over the unit
/// ball, which removes the regulariser's bias (about 1.046 in 3D); composite Simpson, 4096 panels.
inline Real pair_weight_calibration() {
    // int_0^1 4 pi y^2 * y * (45/pi)(1-y)^2 * y^2/(y^2+0.01) dy.
    const int n = 4096;
    Real sum = 0;
    for (int k = 0; k <= n; ++k) {
        const Real y = Real(k) / n;
        const Real f = 180 * y * y * y * (1 - y) * (1 - y) * y * y / (y * y + 0.01);
        sum += f * (k == 0 || k == n ? 1 : (k % 2 ? 4 : 2));
    }
    return 3 / (sum / (3 * n));
}

}  // namespace karst
