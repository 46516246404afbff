#pragma once
// Polygon-soup repair and checks on CGAL's Polygon_mesh_processing (the one CGAL unit of the
// surface code).
#include "karst/surface/surface_mesh.hpp"

#include <vector>

namespace karst {

/// Makes a closed triangle soup a manifold one: where faces meet only along an edge or at a
/// vertex (two alpha-shape pieces touching), the vertex is duplicated so that each piece has its
/// own (CGAL orient_polygon_soup). `source` gets, per vertex of the result, the input vertex it
/// is a copy of. The input's orientation is kept.
void split_non_manifold(std::vector<Vec3>& x, std::vector<std::array<Index, 3>>& triangles,
                        std::vector<Index>& source);

/// What a surface is, as the surface tests check it.
struct SurfaceCheck {
    bool closed_manifold = false;  ///< every edge in exactly two faces, of opposite directions,
                                   ///< and every vertex's faces one fan
    Index self_intersections = 0;  ///< pairs of faces that cross (CGAL does_self_intersect)
    Index degenerate = 0;          ///< faces of zero area
};
SurfaceCheck check_surface(const SurfaceMesh& mesh, bool self_intersections = true);

}  // namespace karst
