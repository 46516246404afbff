#include "karst/pfem/polyhedral_elements.hpp"

#include "karst/core/parallel.hpp"
#include "karst/pfem/laplace_shape.hpp"

#include <algorithm>

namespace karst {

std::vector<PolyhedralElement> polyhedral_elements(const TetMesh& mesh, Real gradient_step) {
    Index count = 0;
    for (Index id : mesh.tet_polyhedron) count = std::max(count, id + 1);
    std::vector<std::vector<Index>> tets_of(count);
    for (Index e = 0; e < mesh.tet_count(); ++e) tets_of[mesh.tet_polyhedron[e]].push_back(e);

    std::vector<PolyhedralElement> elements(count);
    parallel_for(count, [&](Index id) {
        PolyhedralElement& element = elements[id];
        for (Index e : tets_of[id])
            for (Index a : mesh.tets[e]) element.nodes.push_back(a);
        std::sort(element.nodes.begin(), element.nodes.end());
        element.nodes.erase(std::unique(element.nodes.begin(), element.nodes.end()),
                            element.nodes.end());
        std::vector<Vec3> x(element.nodes.size());
        for (size_t k = 0; k < x.size(); ++k) x[k] = mesh.nodes[element.nodes[k]];
        for (Index e : tets_of[id]) {
            PolyhedralElement::Point point;
            point.tet = e;
            point.weight = mesh.tet_volume(e);
            point.N.resize(x.size()), point.grad.resize(x.size());
            const Tet& t = mesh.tets[e];
            const Vec3 centroid =
                0.25 * (mesh.nodes[t[0]] + mesh.nodes[t[1]] + mesh.nodes[t[2]] + mesh.nodes[t[3]]);
            laplace_shape_and_gradient(x, centroid, gradient_step, point.N, point.grad);
            element.points.push_back(std::move(point));
        }
    });
    return elements;
}

}  // namespace karst
