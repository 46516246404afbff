// The one translation unit that includes CGAL (docs/method.md §5.1). Everything else sees
// tet_mesh.hpp.
//
// Slivers (docs/method.md §5.1.3) are dropped only where they touch the surface, as Kratos does
// [D, deviation]: an interior sliver is typically the flat tet between two lattice cells whose
// Delaunay split their shared square along different diagonals. Dropping it leaves the two
// sides non-conforming, and the patch test then fails at the nodes beside it. Kept, the mesh is
// consistent but the sliver is stiff
// (~ area / thickness) and locks bending: a cantilever came out twice too stiff. So lattices
// are meshed unjittered (box_nodes.hpp), where CGAL's symbolic perturbation splits the
// cospherical cells consistently and no sliver arises; a sliver-free mesh of moved particles
// needs the polyhedral shape functions (M21), which are not built yet.
//
// The alpha shape is one loop over the cells with the per-tet test of M19 rather than CGAL's
// Alpha_shape_3 classes: those use one global alpha (M19's threshold depends on the tet's own
// nodes) and cost 2-3x the Delaunay itself, while the loop gives the same facets 20x cheaper
// (perf-facts.md, 70k points: 1.0 s against 0.048 s).
#include "karst/pfem/tet_mesh.hpp"

#include "karst/core/check.hpp"
#include "karst/core/disjoint_sets.hpp"
#include "karst/core/parallel.hpp"

#include <CGAL/Delaunay_triangulation_3.h>
#include <CGAL/Delaunay_triangulation_cell_base_3.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Regular_triangulation_3.h>
#include <CGAL/Regular_triangulation_cell_base_3.h>
#include <CGAL/Regular_triangulation_vertex_base_3.h>
#include <CGAL/Triangulation_cell_base_with_info_3.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>

#include <functional>
#include <numbers>

namespace karst {

namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;

using DelaunayVb = CGAL::Triangulation_vertex_base_with_info_3<Index, K>;
using DelaunayCb =
    CGAL::Triangulation_cell_base_with_info_3<Index, K,
                                              CGAL::Delaunay_triangulation_cell_base_3<K>>;
using Delaunay =
    CGAL::Delaunay_triangulation_3<K, CGAL::Triangulation_data_structure_3<DelaunayVb, DelaunayCb>>;

using RegularVb =
    CGAL::Triangulation_vertex_base_with_info_3<Index, K,
                                                CGAL::Regular_triangulation_vertex_base_3<K>>;
using RegularCb =
    CGAL::Triangulation_cell_base_with_info_3<Index, K, CGAL::Regular_triangulation_cell_base_3<K>>;
using Regular =
    CGAL::Regular_triangulation_3<K, CGAL::Triangulation_data_structure_3<RegularVb, RegularCb>>;

Vec3 to_vec(const K::Point_3& p) {
    return {p.x(), p.y(), p.z()};
}

/// Per finite cell: node ids, circumcentre (orthocentre when weighted), squared (ortho)radius.
struct Cells {
    std::vector<Tet> nodes;
    std::vector<Vec3> centre;
    std::vector<Real> radius2;
    std::vector<std::array<Index, 4>>
        neighbour;  ///< cell across the face opposite node k; -1 outside
};

template <class Triangulation, class Centre>
Cells collect_cells(Triangulation& tri, const Centre& centre_and_radius2) {
    Cells cells;
    Index next = 0;
    for (auto c = tri.all_cells_begin(); c != tri.all_cells_end(); ++c)
        c->info() = tri.is_infinite(c) ? -1 : next++;
    cells.nodes.resize(next), cells.centre.resize(next), cells.radius2.resize(next),
        cells.neighbour.resize(next);
    for (auto c = tri.finite_cells_begin(); c != tri.finite_cells_end(); ++c) {
        const Index id = c->info();
        for (int k = 0; k < 4; ++k) {
            cells.nodes[id][k] = c->vertex(k)->info();
            cells.neighbour[id][k] = c->neighbor(k)->info();
        }
        std::tie(cells.centre[id], cells.radius2[id]) = centre_and_radius2(c);
    }
    return cells;
}

/// M19, slivers (§5.1.3), M20 and the boundary, on the collected cells.
TetMesh mesh_from_cells(std::span<const Vec3> points, std::span<const Real> node_size,
                        const MeshOptions& options, const Cells& cells) {
    const Index n_cells = Index(cells.nodes.size());
    TetMesh mesh;
    mesh.nodes.assign(points.begin(), points.end());
    mesh.quality.delaunay_cells = n_cells;

    // M19 keep test and the sliver test, in parallel over cells.
    std::vector<char> kept(n_cells), sliver(n_cells);
    std::vector<Real> volume(n_cells);
    parallel_for(n_cells, [&](Index c) {
        const Tet& t = cells.nodes[c];
        const Real h =
            0.25 * (node_size[t[0]] + node_size[t[1]] + node_size[t[2]] + node_size[t[3]]);
        volume[c] = std::abs(signed_volume(points[t[0]], points[t[1]], points[t[2]], points[t[3]]));
        kept[c] = cells.radius2[c] < options.alpha * options.alpha * h * h;
        sliver[c] = volume[c] < options.sliver_volume * h * h * h;
    });

    // M20: union-find over face-adjacent kept cells with nearly coincident centres.
    DisjointSets groups(n_cells);
    for (Index c = 0; c < n_cells; ++c) {
        if (!kept[c]) continue;
        for (int k = 0; k < 4; ++k) {
            const Index d = cells.neighbour[c][k];
            if (d < c || !kept[d]) continue;  // each pair once; -1 (outside) is < c
            const Real r_rms = std::sqrt(0.5 * (cells.radius2[c] + cells.radius2[d]));
            if ((cells.centre[c] - cells.centre[d]).norm() < options.join_delta * r_rms)
                groups.join(c, d);
        }
    }

    // Assembled tets (positively oriented), their polyhedron ids, boundary facets.
    std::vector<Index> polyhedron_id(n_cells, -1), group_size(n_cells, 0);
    Index polyhedra = 0;
    MeshQuality& q = mesh.quality;
    q.min_dihedral_deg = 180;
    for (Index c = 0; c < n_cells; ++c) {
        if (!kept[c]) continue;
        ++q.kept;
        q.volume += volume[c];
        Tet t = cells.nodes[c];
        bool on_surface = false;
        for (int k = 0; k < 4; ++k) {
            const Index d = cells.neighbour[c][k];
            if (d >= 0 && kept[d]) continue;
            on_surface = true;
            Triangle f{t[(k + 1) % 4], t[(k + 2) % 4], t[(k + 3) % 4]};
            const Vec3 &a = points[f[0]], &b = points[f[1]], &cc = points[f[2]],
                       &opposite = points[t[k]];
            if ((b - a).cross(cc - a).dot(opposite - a) > 0)
                std::swap(f[1], f[2]);  // normal away from the cell
            mesh.boundary.push_back(f);
        }
        if (sliver[c] && on_surface) {
            ++q.slivers_dropped;
            continue;
        }
        q.interior_slivers += sliver[c];
        const Index root = groups.find(c);
        if (polyhedron_id[root] < 0) polyhedron_id[root] = polyhedra++;
        q.joined_polyhedra += ++group_size[root] == 2;
        if (signed_volume(points[t[0]], points[t[1]], points[t[2]], points[t[3]]) < 0)
            std::swap(t[2], t[3]);
        mesh.tets.push_back(t);
        mesh.tet_polyhedron.push_back(polyhedron_id[root]);
        if (!sliver[c])
            q.min_dihedral_deg = std::min(
                q.min_dihedral_deg,
                min_dihedral_deg({points[t[0]], points[t[1]], points[t[2]], points[t[3]]}));
    }
    q.elements = Index(mesh.tets.size());
    q.polyhedra = polyhedra;
    if (q.elements == 0) q.min_dihedral_deg = 0;
    return mesh;
}

template <class Point>
std::vector<std::pair<Point, Index>> indexed(std::span<const Vec3> points,
                                             const std::function<Point(Index)>& make) {
    std::vector<std::pair<Point, Index>> out(points.size());
    for (Index i = 0; i < Index(points.size()); ++i) out[i] = {make(i), i};
    return out;
}

}  // namespace

TetMesh build_tet_mesh(std::span<const Vec3> points, std::span<const Real> node_size,
                       const MeshOptions& options, std::span<const Real> weights) {
    KARST_CHECK(node_size.size() == points.size());
    if (!options.weighted) {
        const auto input = indexed<K::Point_3>(
            points, [&](Index i) { return K::Point_3(points[i][0], points[i][1], points[i][2]); });
        Delaunay tri(input.begin(), input.end());
        const Cells cells = collect_cells(tri, [&](Delaunay::Cell_handle c) {
            const Vec3 centre = to_vec(tri.dual(c));
            return std::pair{centre, (centre - to_vec(c->vertex(0)->point())).squaredNorm()};
        });
        return mesh_from_cells(points, node_size, options, cells);
    }
    KARST_CHECK(weights.size() == points.size());
    using WP = Regular::Weighted_point;
    const auto input = indexed<WP>(points, [&](Index i) {
        return WP(K::Point_3(points[i][0], points[i][1], points[i][2]), weights[i]);
    });
    Regular tri(input.begin(), input.end());
    const auto orthocentre = tri.geom_traits().construct_weighted_circumcenter_3_object();
    const Cells cells = collect_cells(tri, [&](Regular::Cell_handle c) {
        const WP &p = c->vertex(0)->point(), &q = c->vertex(1)->point(), &r = c->vertex(2)->point(),
                 &s = c->vertex(3)->point();
        const Vec3 centre = to_vec(orthocentre(p, q, r, s));
        // Orthoradius: |c - p|^2 - w_p is the same for all four weighted points.
        return std::pair{centre, (centre - to_vec(p.point())).squaredNorm() - p.weight()};
    });
    return mesh_from_cells(points, node_size, options, cells);
}

Index bare_delaunay_cell_count(std::span<const Vec3> points) {
    std::vector<K::Point_3> input;
    input.reserve(points.size());
    for (const Vec3& p : points) input.emplace_back(p[0], p[1], p[2]);
    CGAL::Delaunay_triangulation_3<K> tri(input.begin(), input.end());
    return Index(tri.number_of_finite_cells());
}

}  // namespace karst
