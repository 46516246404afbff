#pragma once
// The porous surface (docs/method.md §7): per fragment, the boundary triangles of the alpha shape
// (§5.1, the PFEM mesh builder's) of its particles' body-frame positions, placed on their current
// positions, so the surface follows the fragment's motion and the Biot displacement. A fragment's
// triangles are kept while its members and their body-frame positions stay the same, and rebuilt
// when some dissolve, split off or join.
#include "karst/sim/model.hpp"
#include "karst/sim/state.hpp"
#include "karst/surface/surface_mesh.hpp"

#include <map>

namespace karst {

class PorousSurfaces {
public:
    /// The surfaces of every fragment of at least four particles, with the vertex arrays
    /// saturation and porosity (from `saturation`, per particle), fragment, and the M29 colour of
    /// the saturation. Closed and manifold; where pieces of one alpha shape touch at an edge or
    /// a vertex, each piece gets its own copy of the vertex, moved 1 % of a spacing into it.
    SurfaceMesh build(const Model& model, const PorousParticles& particles,
                      const std::vector<Real>& saturation);

private:
    struct Piece {
        std::vector<Index> ids;            ///< the members' particle ids, in particle order
        std::vector<Vec3> rest;            ///< their body-frame positions when meshed
        std::vector<Index> vertex_member;  ///< per vertex: its member (index into ids)
        std::vector<std::array<Index, 3>> triangles;
    };
    Piece make_piece(const Model& model, std::vector<Index> ids, std::vector<Vec3> rest) const;
    std::map<Index, Piece> m_pieces;  ///< by fragment
};

}  // namespace karst
