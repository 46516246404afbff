#pragma once
// Links between the elements of a mesh (docs/method.md §5.5, M27): two tets are linked when they
// share a face. Fracture breaks links; the unbroken ones say which elements hold together.
#include "karst/pfem/structure_state.hpp"

#include <algorithm>
#include <array>

namespace karst {

/// The nodes two linked tets have in common (a face's three), in the order of tet a's.
struct SharedNodes {
    std::array<Index, 3> node{};
    int count = 0;
    const Index* begin() const { return node.data(); }
    const Index* end() const { return node.data() + count; }
};

inline SharedNodes shared_nodes(const TetMesh& mesh, const ElementLink& l) {
    SharedNodes shared;
    const Tet& b = mesh.tets[l.b];
    for (Index a : mesh.tets[l.a])
        if (shared.count < 3 && std::find(b.begin(), b.end(), a) != b.end())
            shared.node[shared.count++] = a;
    return shared;
}

/// Every pair of tets sharing a face, each once with a < b, sorted by (a, b).
std::vector<ElementLink> face_links(const TetMesh& mesh);

}  // namespace karst
