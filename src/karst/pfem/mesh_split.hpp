#pragma once
// Node splitting along broken links (docs/method.md §5.6, M27) and the extraction of a mesh's
// components, on the mesh alone: the caller carries the particles (mass, water, momentum) along
// with the `source` and `share` arrays.
#include "karst/pfem/structure_state.hpp"

#include <functional>
#include <span>

namespace karst {

struct MeshSplit {
    TetMesh mesh;                    ///< the input's tets on split nodes, copies appended
    std::vector<Index> source;       ///< per node: the input node it is (a copy of)
    std::vector<Real> share;         ///< per node: its part of the source's volume, 1 if whole
    std::vector<ElementLink> links;  ///< the unbroken links (tet indices unchanged)
    std::vector<Index> component;    ///< per tet: connected component over unbroken links
    Index components = 0;            ///< numbered in order of their lowest tet
    Index split_nodes = 0;           ///< input nodes that were duplicated
};

/// M27: around every node, its tets are grouped by the unbroken links among them; a node with k
/// groups becomes k nodes, one per group, sharing the node by the groups' volumes
/// (sum V_e / 4). Each copy moves `offset` away from the broken faces that cut its group off
/// (along the crack's normal; towards its group's centroid if none), and the moves are shifted
/// so that their share-weighted sum is zero: mass-weighted positions, hence the linear and
/// angular momentum of copies given the source's velocity, are kept.
MeshSplit split_mesh(const TetMesh& mesh, std::span<const ElementLink> links,
                     std::span<const char> broken, Real offset);

/// Per tet, its connected component over `links`, numbered 0, 1, ... in order of their lowest
/// tet; `count` gets the number of components.
std::vector<Index> tet_components(Index tet_count, std::span<const ElementLink> links,
                                  Index& count);

/// Cuts the links by which a tet of volume below `min_volume` (a sliver, with next to no
/// stiffness) would join two pieces that are apart otherwise: the sliver goes with the piece of
/// its first solid neighbour. A piece hanging on a sliver has a singular elasticity. Returns the
/// number of links cut.
Index cut_sliver_bridges(const TetMesh& mesh, std::span<const ElementLink> links,
                         std::vector<char>& cut, Real min_volume);

/// Joins every piece of fewer than `min_tets` tets that the cuts would make to the neighbour it
/// shares the most cut faces with (restoring those cuts), until none is left: a crack does not
/// chip off pieces below the mesh's resolution (they would be rigid fragments of a few
/// particles), and the cuts between the larger pieces stay. A small piece for which
/// `stays_anchored(its tets)` holds becomes no fragment and is left cut, so that a body hanging
/// from a small anchored stub can break off it. Returns the number of links restored.
Index spare_small_pieces(Index tet_count, std::span<const ElementLink> links,
                         std::vector<char>& cut, Index min_tets,
                         const std::function<bool(std::span<const Index>)>& stays_anchored = {});

/// The tets with keep[e] set, on their nodes (renumbered in input order), and with
/// `keep_loose_nodes` the nodes that belong to no tet: `node_of` gets, per node of the result,
/// its index in `mesh`, and `tet_of` per tet.
TetMesh sub_mesh(const TetMesh& mesh, std::span<const char> keep, bool keep_loose_nodes,
                 std::vector<Index>& node_of, std::vector<Index>& tet_of);

/// §4.10, §5.6: the remesh of a cracked body keeps every tet of `old_mesh` whose nodes all
/// remain (`old_node[a]` is node a's index there, or -1 for a node new to the body) and takes
/// from `fresh`, a triangulation of all the nodes, only the tets with a new node. The cracks
/// stay as they were, with both faces meshed: a fresh triangulation of the lattice splits the
/// cells otherwise than the old mesh did, and its tets cross the crack surface, which runs
/// along the old tets' faces. Nodes are kept; the old tets come first.
void keep_old_tets(TetMesh& fresh, const TetMesh& old_mesh, std::span<const Index> old_node);

/// §5.6: a remesh keeps the cracks. Removes from `mesh` (a new triangulation of a cracked
/// body's particles) every tet with two nodes that both lie on broken faces (`on_crack`) and that
/// the mesh it replaces kept apart (no tet of one is, or is linked by `old_links` to, a tet of the
/// other): the two sides of a crack, whose split copies sit a tenth of a spacing apart, and
/// which a Delaunay closes with flat tets. `old_node[a]` is node a's index in `old_mesh`, or -1
/// for a node new to the body (it may join anything). Nodes are kept, the tets keep their order.
/// Returns the tets removed.
Index drop_tets_across_cracks(TetMesh& mesh, const TetMesh& old_mesh,
                              std::span<const ElementLink> old_links,
                              std::span<const Index> old_node, std::span<const char> on_crack);

/// The faces that belong to one tet only, oriented outward.
std::vector<Triangle> boundary_faces(std::span<const Tet> tets);

}  // namespace karst
