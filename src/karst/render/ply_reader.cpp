#include "karst/render/ply_reader.hpp"

#include <fmt/format.h>

#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace karst {

namespace {

struct Property {
    std::string name;
    int size = 4;  ///< bytes: float and int 4, uchar 1
    bool is_float = true;
};

}  // namespace

SurfaceMesh read_ply_mesh(const std::filesystem::path& file) {
    std::ifstream in(file, std::ios::binary);
    auto fail = [&](const std::string& why) {
        return std::runtime_error(fmt::format("cannot read '{}': {}", file.string(), why));
    };
    if (!in) throw fail("no such file");
    std::string line;
    std::getline(in, line);
    if (line != "ply") throw fail("not a PLY file");
    size_t vertices = 0, faces = 0;
    std::vector<Property> props;
    std::string element;
    while (std::getline(in, line) && line != "end_header") {
        std::istringstream words(line);
        std::string word, type, name;
        words >> word;
        if (word == "format" && line != "format binary_little_endian 1.0")
            throw fail("not binary little-endian");
        if (word == "element") {
            size_t count = 0;
            words >> element >> count;
            (element == "vertex" ? vertices : faces) = count;
        } else if (word == "property" && element == "vertex") {
            words >> type >> name;
            if (type != "float" && type != "int" && type != "uchar")
                throw fail("a vertex property of type " + type);
            props.push_back({name, type == "uchar" ? 1 : 4, type == "float"});
        } else if (word == "property" && element == "face" &&
                   line != "property list uchar int vertex_indices") {
            throw fail("faces other than uchar-counted int lists");
        }
    }
    if (line != "end_header") throw fail("no end_header");

    SurfaceMesh mesh;
    size_t row = 0;
    for (const Property& p : props) row += p.size;
    std::vector<char> bytes(vertices * row);
    in.read(bytes.data(), std::streamsize(bytes.size()));
    if (!in) throw fail("fewer vertices than its header says");
    auto column = [&](const std::string& name) {
        size_t offset = 0;
        for (const Property& p : props) {
            if (p.name == name) return std::pair<long, const Property*>(long(offset), &p);
            offset += p.size;
        }
        return std::pair<long, const Property*>(-1, nullptr);
    };
    auto value = [&](size_t v, const std::pair<long, const Property*>& c) -> Real {
        const char* at = bytes.data() + v * row + c.first;
        if (c.second->size == 1) return Real(std::uint8_t(*at));
        if (c.second->is_float) {
            float f;
            std::memcpy(&f, at, 4);
            return f;
        }
        std::int32_t i;
        std::memcpy(&i, at, 4);
        return i;
    };
    const auto x = column("x"), y = column("y"), z = column("z");
    if (!x.second || !y.second || !z.second) throw fail("no x y z");
    const auto nx = column("nx"), ny = column("ny"), nz = column("nz");
    const auto red = column("red"), green = column("green"), blue = column("blue");
    std::vector<Vec3> normal;
    for (size_t v = 0; v < vertices; ++v) {
        mesh.vertices.x.emplace_back(value(v, x), value(v, y), value(v, z));
        if (nx.second && ny.second && nz.second)
            normal.emplace_back(value(v, nx), value(v, ny), value(v, nz));
        if (red.second && green.second && blue.second)
            mesh.colour.push_back({std::uint8_t(value(v, red)), std::uint8_t(value(v, green)),
                                   std::uint8_t(value(v, blue))});
    }
    if (!normal.empty()) mesh.vertices.add_vector("normal", normal);
    for (size_t f = 0; f < faces; ++f) {
        std::uint8_t count = 0;
        std::int32_t index[3];
        in.read(reinterpret_cast<char*>(&count), 1);
        if (count != 3) throw fail("a face that is not a triangle");
        in.read(reinterpret_cast<char*>(index), sizeof index);
        if (!in) throw fail("fewer faces than its header says");
        for (std::int32_t i : index)
            if (i < 0 || size_t(i) >= vertices) throw fail("a face index out of range");
        mesh.triangles.push_back({index[0], index[1], index[2]});
    }
    return mesh;
}

}  // namespace karst
