#include "karst/pfem/face_links.hpp"

#include <algorithm>

namespace karst {

std::vector<ElementLink> face_links(const TetMesh& mesh) {
    struct Face {
        std::array<Index, 3> nodes;
        Index tet;
    };
    std::vector<Face> faces;
    faces.reserve(4 * mesh.tets.size());
    for (Index e = 0; e < mesh.tet_count(); ++e) {
        const Tet& t = mesh.tets[e];
        for (int skip = 0; skip < 4; ++skip) {
            std::array<Index, 3> f;
            for (int k = 0, m = 0; k < 4; ++k)
                if (k != skip) f[m++] = t[k];
            std::sort(f.begin(), f.end());
            faces.push_back({f, e});
        }
    }
    std::sort(faces.begin(), faces.end(), [](const Face& a, const Face& b) {
        return a.nodes != b.nodes ? a.nodes < b.nodes : a.tet < b.tet;
    });
    std::vector<ElementLink> links;
    for (size_t k = 0; k + 1 < faces.size(); ++k)
        if (faces[k].nodes == faces[k + 1].nodes)
            links.push_back({faces[k].tet, faces[k + 1].tet}), ++k;
    std::sort(links.begin(), links.end(), [](const ElementLink& x, const ElementLink& y) {
        return x.a != y.a ? x.a < y.a : x.b < y.b;
    });
    return links;
}

}  // namespace karst
