// Shape measures of single tets (docs/method.md §5.1 quality figures, §4.10 distortion trigger).
#include "karst/pfem/tet_mesh.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace karst {

Real signed_volume(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
    return (b - a).cross(c - a).dot(d - a) / 6;
}

Real min_dihedral_deg(const std::array<Vec3, 4>& x) {
    // The dihedral angle at edge (i,j) is the angle between the faces (i,j,k) and (i,j,l),
    // computed from the face normals: pi minus the angle between the outward normals.
    static constexpr int edges[6][4] = {{0, 1, 2, 3}, {0, 2, 1, 3}, {0, 3, 1, 2},
                                        {1, 2, 0, 3}, {1, 3, 0, 2}, {2, 3, 0, 1}};
    // acos falls monotonically, so the smallest angle is that of the largest cosine.
    Real largest_cosine = -1;
    for (const auto& e : edges) {
        const Vec3 axis = (x[e[1]] - x[e[0]]).normalized();
        Vec3 a = x[e[2]] - x[e[0]], b = x[e[3]] - x[e[0]];
        a -= a.dot(axis) * axis, b -= b.dot(axis) * axis;
        largest_cosine = std::max(largest_cosine,
                                  std::clamp(a.dot(b) / (a.norm() * b.norm()), Real(-1), Real(1)));
    }
    return std::acos(largest_cosine) * 180 / std::numbers::pi;
}

Real TetMesh::tet_volume(Index e) const {
    const Tet& t = tets[e];
    return signed_volume(nodes[t[0]], nodes[t[1]], nodes[t[2]], nodes[t[3]]);
}

Vec3 TetMesh::area_vector(const Triangle& t) const {
    return 0.5 * (nodes[t[1]] - nodes[t[0]]).cross(nodes[t[2]] - nodes[t[0]]);
}

}  // namespace karst
