#pragma once
// Links between the elements of a mesh (docs/method.md §5.5, M27): two tets are linked when they
// share a face. Fracture breaks links; the unbroken ones say which elements hold together.
#include "karst/pfem/structure_state.hpp"

namespace karst {

/// Every pair of tets sharing a face, each once with a < b, sorted by (a, b).
std::vector<ElementLink> face_links(const TetMesh& mesh);

}  // namespace karst
