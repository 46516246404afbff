#pragma once
// A point set with named per-point arrays, the common input of the VTK and PLY writers.
#include "karst/core/types.hpp"

#include <string>
#include <vector>

namespace karst {

struct PointArray {
    std::string name;
    int components =
        1;  ///< 1 (scalar), 3 (vector) or 6 (symmetric tensor, VTK order xx yy zz xy yz xz)
    bool integer = false;        ///< stored as Int64 (VTK) / int (PLY) instead of Float32
    std::vector<double> values;  ///< (n * components)
};

struct PointSet {
    std::vector<Vec3> x;  ///< (n) m
    std::vector<PointArray> arrays;
    void add_scalar(std::string name, const std::vector<Real>& v);
    void add_vector(std::string name, const std::vector<Vec3>& v);
    void add_integer(std::string name, const std::vector<std::int64_t>& v);
    void add_symmetric_tensor(std::string name, const std::vector<Mat3>& v);
};

}  // namespace karst
