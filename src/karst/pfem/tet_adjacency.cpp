// Which nodes of a tet mesh share a tet.
#include "karst/core/parallel.hpp"
#include "karst/pfem/tet_mesh.hpp"

#include <algorithm>

namespace karst {

std::vector<std::vector<Index>> node_neighbours(const TetMesh& mesh) {
    const Index n = mesh.node_count();
    std::vector<std::vector<Index>> neighbours(n);
    for (const Tet& t : mesh.tets)
        for (Index a : t) neighbours[a].insert(neighbours[a].end(), t.begin(), t.end());
    parallel_for(n, [&](Index a) {
        auto& nb = neighbours[a];
        std::sort(nb.begin(), nb.end());
        nb.erase(std::unique(nb.begin(), nb.end()), nb.end());
    });
    return neighbours;
}

}  // namespace karst
