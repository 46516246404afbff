#pragma once
// Scalar and small-vector types used everywhere. SI units throughout (m, kg, s, Pa).
#include <Eigen/Core>
#include <cstdint>

namespace karst {

using Real = double;
using Vec3 = Eigen::Matrix<Real, 3, 1>;
using Mat3 = Eigen::Matrix<Real, 3, 3>;
using Index = std::int64_t;

}  // namespace karst
