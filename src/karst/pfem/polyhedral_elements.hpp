#pragma once
// EDT polyhedra as finite elements with Laplace shape functions (docs/method.md §5.2, M21, the
// "faithful option"): each polyhedron's nodes and its quadrature points, the centroids of its
// sub-tets weighted by their volumes, with N and grad N there.
#include "karst/pfem/tet_mesh.hpp"

namespace karst {

struct PolyhedralElement {
    struct Point {
        Index tet = 0;           ///< the sub-tet (for its mobility)
        Real weight = 0;         ///< its volume, m^3
        std::vector<Real> N;     ///< (nodes)
        std::vector<Vec3> grad;  ///< (nodes), 1/m
    };
    std::vector<Index> nodes;
    std::vector<Point> points;
};

/// One element per polyhedron of `mesh` (tet_polyhedron), in parallel; gradients by central
/// differences with step `gradient_step` (M21: 1e-4 dx).
std::vector<PolyhedralElement> polyhedral_elements(const TetMesh& mesh, Real gradient_step);

}  // namespace karst
