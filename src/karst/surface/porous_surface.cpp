#include "karst/surface/porous_surface.hpp"

#include "karst/pfem/biot_setup.hpp"
#include "karst/pfem/mesh_split.hpp"
#include "karst/surface/mesh_repair.hpp"

#include <algorithm>
#include <set>

namespace karst {

PorousSurfaces::Piece PorousSurfaces::make_piece(const Model& model, std::vector<Index> ids,
                                                 std::vector<Vec3> rest) const {
    Piece piece;
    piece.ids = std::move(ids);
    piece.rest = std::move(rest);
    const std::vector<Vec3>& x = piece.rest;
    PfemTimings timings;
    const TetMesh mesh = mesh_points(model, x, timings);
    // The boundary of the assembled tets with volume (the alpha shape less its slivers). Where
    // four points of a lattice square have a tet on each side and none in between (a flat tet is
    // dropped or was never kept), the two triangulations of the square face each other on the
    // boundary: both sides are solid there, so those four faces are dropped.
    const Real min_volume = 1e-9 * model.dx * model.dx * model.dx;
    std::vector<Tet> solid;
    for (const Tet& t : mesh.tets)
        if (signed_volume(x[t[0]], x[t[1]], x[t[2]], x[t[3]]) > min_volume) solid.push_back(t);
    const std::vector<Triangle> faces = boundary_faces(solid);
    std::map<std::pair<Index, Index>, std::vector<Index>> faces_on_edge;
    for (size_t f = 0; f < faces.size(); ++f)
        for (int k = 0; k < 3; ++k)
            faces_on_edge[std::minmax(faces[f][k], faces[f][(k + 1) % 3])].push_back(Index(f));
    std::map<std::array<Index, 4>, std::set<Index>> squares;  // coplanar face pairs by corners
    for (const auto& [edge, on] : faces_on_edge)
        for (size_t a = 0; a < on.size(); ++a)
            for (size_t b = a + 1; b < on.size(); ++b) {
                std::set<Index> corners(faces[on[a]].begin(), faces[on[a]].end());
                corners.insert(faces[on[b]].begin(), faces[on[b]].end());
                if (corners.size() != 4) continue;
                std::array<Index, 4> c;
                std::copy(corners.begin(), corners.end(), c.begin());
                if (std::abs(signed_volume(x[c[0]], x[c[1]], x[c[2]], x[c[3]])) > min_volume)
                    continue;
                squares[c].insert({on[a], on[b]});
            }
    std::vector<char> dropped(faces.size(), 0);
    for (const auto& [corners, on] : squares)
        if (on.size() == 4)
            for (Index f : on) dropped[f] = 1;
    // Its nodes only, renumbered in order of first use.
    std::vector<Index> local(x.size(), -1), member;
    std::vector<Vec3> position;
    std::vector<std::array<Index, 3>> triangles;
    for (size_t face = 0; face < faces.size(); ++face) {
        if (dropped[face]) continue;
        const Triangle& t = faces[face];
        std::array<Index, 3> f;
        for (int k = 0; k < 3; ++k) {
            if (local[t[k]] < 0) {
                local[t[k]] = Index(member.size());
                member.push_back(t[k]);
                position.push_back(x[t[k]]);
            }
            f[k] = local[t[k]];
        }
        triangles.push_back(f);
    }
    std::vector<Index> source;
    split_non_manifold(position, triangles, source);
    piece.vertex_member.resize(source.size());
    for (size_t v = 0; v < source.size(); ++v) piece.vertex_member[v] = member[source[v]];
    piece.triangles = std::move(triangles);
    return piece;
}

SurfaceMesh PorousSurfaces::build(const Model& model, const PorousParticles& p,
                                  const std::vector<Real>& saturation) {
    std::map<Index, std::vector<Index>> members;  // fragment -> particles, in particle order
    for (Index i = 0; i < p.size(); ++i) members[p.fragment[i]].push_back(i);
    std::map<Index, Piece> pieces;
    SurfaceMesh mesh;
    std::vector<Real> sat, porosity, fragment;
    for (const auto& [f, list] : members) {
        if (list.size() < 4) continue;
        std::vector<Index> ids(list.size());
        std::vector<Vec3> x(list.size()), rest(list.size());
        for (size_t k = 0; k < list.size(); ++k)
            ids[k] = p.id[list[k]], x[k] = p.x[list[k]], rest[k] = p.rest[list[k]];
        // Meshed on the body-frame positions, which no motion changes: the same triangles
        // whenever the same members are meshed (a resumed run's surfaces are the straight run's).
        const auto cached = m_pieces.find(f);
        Piece piece =
            cached != m_pieces.end() && cached->second.ids == ids && cached->second.rest == rest
                ? std::move(cached->second)
                : make_piece(model, std::move(ids), std::move(rest));

        // Copies of one particle are moved apart into their own pieces (see the header).
        const Index first = mesh.vertex_count();
        std::vector<int> copies(list.size(), 0);
        for (Index m : piece.vertex_member) ++copies[m];
        std::vector<Vec3> inward(piece.vertex_member.size(), Vec3::Zero());
        for (const auto& t : piece.triangles) {
            const Vec3 centre = (x[piece.vertex_member[t[0]]] + x[piece.vertex_member[t[1]]] +
                                 x[piece.vertex_member[t[2]]]) /
                                3;
            for (Index v : t) inward[v] += centre - x[piece.vertex_member[v]];
        }
        for (size_t v = 0; v < piece.vertex_member.size(); ++v) {
            const Index m = piece.vertex_member[v], i = list[m];
            Vec3 at = x[m];
            if (copies[m] > 1 && inward[v].norm() > 0)
                at += 0.01 * model.dx * inward[v].normalized();
            mesh.vertices.x.push_back(at);
            sat.push_back(saturation[i]), porosity.push_back(p.porosity[i]),
                fragment.push_back(Real(f));
        }
        for (const auto& t : piece.triangles)
            mesh.triangles.push_back({first + t[0], first + t[1], first + t[2]});
        pieces.emplace(f, std::move(piece));
    }
    m_pieces = std::move(pieces);
    mesh.vertices.add_vector("normal", vertex_normals(mesh.vertices.x, mesh.triangles));
    mesh.vertices.add_scalar("saturation", sat);
    mesh.vertices.add_scalar("porosity", porosity);
    std::vector<std::int64_t> fragment_index(fragment.begin(), fragment.end());
    mesh.vertices.add_integer("fragment", fragment_index);
    for (Real s : sat) mesh.colour.push_back(m29_colour(s, k_rock_hue, k_rock_saturation));
    return mesh;
}

}  // namespace karst
