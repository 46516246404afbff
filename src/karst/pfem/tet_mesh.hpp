#pragma once
// The PFEM mesh of one fragment as plain arrays (docs/method.md §5.1): no CGAL type leaves
// mesh_builder.cpp, so only that translation unit pays for CGAL's headers.
#include "karst/core/types.hpp"

#include <Eigen/Geometry>

#include <array>
#include <span>
#include <vector>

namespace karst {

using Tet = std::array<Index, 4>;
using Triangle = std::array<Index, 3>;

struct MeshOptions {
    Real alpha = 1.25;          ///< M19: keep a tet iff its circumradius < alpha * h_e
    Real join_delta = 0.1;      ///< M20: join face neighbours iff |c1 - c2| < delta * r_rms
    Real sliver_volume = 1e-3;  ///< §5.1.3: tets with V < sliver_volume * h_e^3 are slivers
    bool weighted = false;      ///< weighted alpha shape (regular triangulation, orthoradius)
};

/// Figures that say how good a mesh is; printed by benchmarks and written to stats.json.
struct MeshQuality {
    Index delaunay_cells = 0;    ///< finite cells of the (regular) Delaunay triangulation
    Index kept = 0;              ///< cells inside the alpha shape (slivers included)
    Index elements = 0;          ///< assembled tets (kept minus slivers)
    Index slivers_dropped = 0;   ///< slivers on the surface, not assembled
    Index interior_slivers = 0;  ///< assembled: dropping them would break conformity
    Index polyhedra = 0;         ///< EDT groups (M20) of assembled tets
    Index joined_polyhedra = 0;  ///< groups of two or more assembled tets
    Real min_dihedral_deg = 0;   ///< over the assembled tets other than interior slivers
    Real volume = 0;             ///< sum of kept cell volumes, m^3
};

struct TetMesh {
    std::vector<Vec3> nodes;            ///< the input points, same indices
    std::vector<Tet> tets;              ///< assembled tets, positively oriented
    std::vector<Index> tet_polyhedron;  ///< EDT group of each assembled tet
    std::vector<Triangle> boundary;  ///< surface of the alpha shape, outward (right-hand) normals
    MeshQuality quality;

    Index node_count() const { return Index(nodes.size()); }
    Index tet_count() const { return Index(tets.size()); }
    Real tet_volume(Index e) const;
    Vec3 tet_centroid(Index e) const {
        const Tet& t = tets[e];
        return 0.25 * (nodes[t[0]] + nodes[t[1]] + nodes[t[2]] + nodes[t[3]]);
    }
    /// Area-weighted outward normal of a boundary triangle (length = area).
    Vec3 area_vector(const Triangle& t) const;
};

/// Delaunay (or regular, when options.weighted) triangulation of `points`, then the alpha shape
/// with per-node characteristic sizes `node_size` (M19), sliver removal and EDT joining (M20).
/// `weights` (squared radii, m^2) are read only for the weighted variant.
TetMesh build_tet_mesh(std::span<const Vec3> points, std::span<const Real> node_size,
                       const MeshOptions& options, std::span<const Real> weights = {});

/// Each node's neighbours, the nodes that share a tet with it, sorted, the node itself included
/// where it has a tet (pfem/tet_adjacency.cpp).
std::vector<std::vector<Index>> node_neighbours(const TetMesh& mesh);

/// Volume of the tet (a, b, c, d): positive when (b - a, c - a, d - a) is right-handed, m^3.
Real signed_volume(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d);

/// Smallest dihedral angle of a tet, in degrees.
Real min_dihedral_deg(const std::array<Vec3, 4>& x);

/// Bare CGAL Delaunay of the same points, for benchmarks: returns the number of finite cells.
Index bare_delaunay_cell_count(std::span<const Vec3> points);

}  // namespace karst
