#include "karst/surface/mesh_repair.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Surface_mesh.h>

#include <Eigen/Geometry>

#include <map>

namespace karst {

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
namespace PMP = CGAL::Polygon_mesh_processing;

std::vector<Point> cgal_points(const std::vector<Vec3>& x) {
    std::vector<Point> p;
    p.reserve(x.size());
    for (const Vec3& v : x) p.emplace_back(v[0], v[1], v[2]);
    return p;
}

std::vector<std::vector<std::size_t>> cgal_polygons(
    const std::vector<std::array<Index, 3>>& triangles) {
    std::vector<std::vector<std::size_t>> polygons;
    polygons.reserve(triangles.size());
    for (const auto& t : triangles)
        polygons.push_back({std::size_t(t[0]), std::size_t(t[1]), std::size_t(t[2])});
    return polygons;
}

}  // namespace

void split_non_manifold(std::vector<Vec3>& x, std::vector<std::array<Index, 3>>& triangles,
                        std::vector<Index>& source) {
    std::vector<Point> points = cgal_points(x);
    std::vector<std::vector<std::size_t>> polygons = cgal_polygons(triangles);
    const std::size_t n = points.size();
    PMP::orient_polygon_soup(points, polygons);
    // Copies are appended; the face that uses a copy in place of its original tells which.
    source.resize(points.size());
    for (std::size_t v = 0; v < points.size(); ++v) source[v] = Index(v);
    for (std::size_t f = 0; f < polygons.size(); ++f)
        for (int k = 0; k < 3; ++k)
            if (polygons[f][k] >= n) {
                // orient_polygon_soup may rotate a face's vertex list: match by position.
                for (int m = 0; m < 3; ++m)
                    if (triangles[f][m] < Index(n) &&
                        points[polygons[f][k]] == points[triangles[f][m]])
                        source[polygons[f][k]] = triangles[f][m];
            }
    x.resize(points.size());
    for (std::size_t v = n; v < points.size(); ++v) x[v] = x[source[v]];
    for (std::size_t f = 0; f < polygons.size(); ++f)
        triangles[f] = {Index(polygons[f][0]), Index(polygons[f][1]), Index(polygons[f][2])};
}

SurfaceCheck check_surface(const SurfaceMesh& mesh, bool self_intersections) {
    SurfaceCheck check;
    const std::vector<Vec3>& x = mesh.vertices.x;
    std::map<std::pair<Index, Index>, int> directed;
    for (const auto& t : mesh.triangles) {
        for (int k = 0; k < 3; ++k) ++directed[{t[k], t[(k + 1) % 3]}];
        if ((x[t[1]] - x[t[0]]).cross(x[t[2]] - x[t[0]]).squaredNorm() == 0) ++check.degenerate;
    }
    bool edges_ok = true;
    for (const auto& [edge, count] : directed) {
        const auto opposite = directed.find({edge.second, edge.first});
        edges_ok &= count == 1 && opposite != directed.end() && opposite->second == 1;
    }
    const std::vector<std::vector<std::size_t>> polygons = cgal_polygons(mesh.triangles);
    check.closed_manifold = edges_ok && PMP::is_polygon_soup_a_polygon_mesh(polygons);
    if (self_intersections && check.closed_manifold) {
        CGAL::Surface_mesh<Point> surface;
        PMP::polygon_soup_to_polygon_mesh(cgal_points(x), polygons, surface);
        std::vector<
            std::pair<CGAL::Surface_mesh<Point>::Face_index, CGAL::Surface_mesh<Point>::Face_index>>
            pairs;
        PMP::self_intersections(surface, std::back_inserter(pairs));
        check.self_intersections = Index(pairs.size());
    }
    return check;
}

}  // namespace karst
