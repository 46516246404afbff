#pragma once
#include "karst/io/point_arrays.hpp"

#include <string>

namespace karst {

/// Binary little-endian PLY point cloud: x y z, then each array (vectors as name_x, name_y,
/// name_z) as float, integer arrays as int.
std::string ply_bytes(const PointSet& points);

}  // namespace karst
