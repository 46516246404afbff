#pragma once
// EnSight Gold (C Binary) output of a tetrahedral mesh whose topology changes rarely: a geometry
// file (coordinates and tetra4 connectivity) written only when it changed, one file per point
// array and frame, and a .case file that lists them by time (ParaView, VisIt and VTK read it).
#include "karst/io/point_arrays.hpp"

#include <array>
#include <string>
#include <vector>

namespace karst {

/// The geometry file: one part of `points.x` (Float32) and the tetrahedra (1-based Int32).
std::string ensight_geometry_bytes(const PointSet& points,
                                   const std::vector<std::array<Index, 4>>& tets);

/// The per-node variable file of one array of `points` (components as EnSight orders them:
/// vectors x y z, symmetric tensors 11 22 33 12 13 23).
std::string ensight_variable_bytes(const PointSet& points, const PointArray& array);

/// The name of a frame's file: `<stem>_<what>_NNNN.<ext>` (`what` empty for the geometry).
std::string ensight_file(const std::string& stem, const std::string& what, int frame);

/// One time step of the .case file: the frames whose files it reads, the geometry's and then
/// each variable's (a file unchanged since an earlier frame is read again, not rewritten).
struct EnsightStep {
    double time;
    std::vector<int> files;
};

/// The .case file of `steps`, with the variables of `layout` (names and components); each file
/// has its own time set, so its filename numbers can repeat.
std::string ensight_case_bytes(const std::string& stem, const PointSet& layout,
                               const std::vector<EnsightStep>& steps);

}  // namespace karst
