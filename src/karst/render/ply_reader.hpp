#pragma once
// Reads the binary PLY triangle meshes karst writes (io/ply_writer.hpp): positions, normals,
// colours and faces; other vertex properties are skipped.
#include "karst/surface/surface_mesh.hpp"

#include <filesystem>

namespace karst {

/// The mesh in `file`: vertices.x, a "normal" array when the file has nx ny nz, colour when it
/// has red green blue. Throws std::runtime_error naming the file on anything else than a
/// binary little-endian PLY of float/int/uchar vertex properties and triangle faces.
SurfaceMesh read_ply_mesh(const std::filesystem::path& file);

}  // namespace karst
