#include "karst/io/ply_writer.hpp"

#include <fmt/format.h>

namespace karst {

namespace {

std::string vertex_header(const PointSet& points, bool colour) {
    std::string header =
        fmt::format("element vertex {}\nproperty float x\nproperty float y\nproperty float z\n",
                    points.x.size());
    for (const PointArray& a : points.arrays) {
        const char* type = a.integer ? "int" : "float";
        if (a.components == 1)
            header += fmt::format("property {} {}\n", type, a.name);
        else if (a.name == "normal")  // what mesh importers read as normals
            header += fmt::format("property {0} nx\nproperty {0} ny\nproperty {0} nz\n", type);
        else
            for (const char* axis : {"x", "y", "z"})
                header += fmt::format("property {} {}_{}\n", type, a.name, axis);
    }
    if (colour) header += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
    return header;
}

template <class T>
void put(std::string& out, T value) {
    out.append(reinterpret_cast<const char*>(&value), sizeof value);
}

void put_vertices(std::string& out, const PointSet& points, const std::vector<Rgb>& colour) {
    for (size_t i = 0; i < points.x.size(); ++i) {
        for (int d = 0; d < 3; ++d) put(out, float(points.x[i][d]));
        for (const PointArray& a : points.arrays)
            for (int c = 0; c < a.components; ++c) {
                const double v = a.values[i * a.components + c];
                if (a.integer)
                    put(out, std::int32_t(v));
                else
                    put(out, float(v));
            }
        if (!colour.empty()) out.append(reinterpret_cast<const char*>(colour[i].data()), 3);
    }
}

std::string preamble() {
    return fmt::format("ply\nformat binary_little_endian 1.0\ncomment karst {}\n", KARST_VERSION);
}

}  // namespace

std::string ply_bytes(const PointSet& points) {
    std::string out = preamble() + vertex_header(points, false) + "end_header\n";
    put_vertices(out, points, {});
    return out;
}

std::string ply_bytes(const SurfaceMesh& mesh) {
    std::string out = preamble() + vertex_header(mesh.vertices, !mesh.colour.empty()) +
                      fmt::format("element face {}\nproperty list uchar int vertex_indices\n",
                                  mesh.triangles.size()) +
                      "end_header\n";
    put_vertices(out, mesh.vertices, mesh.colour);
    for (const auto& t : mesh.triangles) {
        put(out, std::uint8_t(3));
        for (Index v : t) put(out, std::int32_t(v));
    }
    return out;
}

}  // namespace karst
