#pragma once
#include "karst/io/point_arrays.hpp"

#include <filesystem>
#include <string>
#include <vector>

namespace karst {

/// VTK XML PolyData (.vtp), appended binary (zlib-compressed blocks when `zlib`, else raw),
/// with a Verts cell per point so ParaView draws the points. Positions and float arrays are
/// Float32, integer arrays Int64.
std::string vtp_bytes(const PointSet& points, bool zlib = true);

/// VTK XML PolyData (.vtp) of polygons over the points (each a list of point indices), with
/// the point arrays.
std::string vtp_polygons_bytes(const PointSet& points,
                               const std::vector<std::vector<Index>>& polygons, bool zlib = true);

/// One data set of a ParaView collection (.pvd).
struct PvdEntry {
    double time;
    int part;
    std::string file;
};
std::string pvd_bytes(const std::vector<PvdEntry>& entries);

}  // namespace karst
