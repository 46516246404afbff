#pragma once
#include "karst/io/point_arrays.hpp"
#include "karst/surface/surface_mesh.hpp"

#include <string>

namespace karst {

/// Binary little-endian PLY point cloud: x y z, then each array (vectors as name_x, name_y,
/// name_z; "normal" as nx ny nz) as float, integer arrays as int.
std::string ply_bytes(const PointSet& points);

/// Binary little-endian PLY triangle mesh: the vertices as ply_bytes writes points, then the
/// colour as uchar red green blue when present, and the faces as vertex_indices lists.
std::string ply_bytes(const SurfaceMesh& mesh);

}  // namespace karst
