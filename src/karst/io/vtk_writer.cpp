#include "karst/io/vtk_writer.hpp"

#include <fmt/format.h>

#include <zlib.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string_view>

namespace karst {

void PointSet::add_scalar(std::string name, const std::vector<Real>& v) {
    arrays.push_back({std::move(name), 1, false, std::vector<double>(v.begin(), v.end())});
}
void PointSet::add_vector(std::string name, const std::vector<Vec3>& v) {
    PointArray a{std::move(name), 3, false, {}};
    a.values.reserve(3 * v.size());
    for (const Vec3& e : v) a.values.insert(a.values.end(), {e[0], e[1], e[2]});
    arrays.push_back(std::move(a));
}
void PointSet::add_integer(std::string name, const std::vector<std::int64_t>& v) {
    arrays.push_back({std::move(name), 1, true, std::vector<double>(v.begin(), v.end())});
}

void PointSet::add_symmetric_tensor(std::string name, const std::vector<Mat3>& v) {
    PointArray a{std::move(name), 6, false, {}};
    a.values.reserve(6 * v.size());
    for (const Mat3& m : v)
        a.values.insert(a.values.end(), {m(0, 0), m(1, 1), m(2, 2), m(0, 1), m(1, 2), m(0, 2)});
    arrays.push_back(std::move(a));
}

namespace {

/// Uncompressed bytes per zlib block (VTK reads any size; larger blocks compress a little better).
constexpr size_t k_zlib_block = 1 << 16;

/// Appended-data block of `values`: raw, a UInt64 byte count then the bytes; with zlib, VTK's
/// vtkZLibDataCompressor layout: UInt64 block count, block size, size of the last partial block
/// (0 when full), each block's compressed size, then the compressed blocks.
template <class T>
void append_block(std::string& blob, const std::vector<T>& values, bool zlib) {
    const char* bytes = reinterpret_cast<const char*>(values.data());
    const std::uint64_t size = values.size() * sizeof(T);
    auto put = [&](std::uint64_t v) { blob.append(reinterpret_cast<const char*>(&v), sizeof v); };
    if (!zlib) {
        put(size);
        blob.append(bytes, size);
        return;
    }
    const std::uint64_t blocks = (size + k_zlib_block - 1) / k_zlib_block;
    put(blocks), put(k_zlib_block), put(size % k_zlib_block);
    const size_t sizes_at = blob.size();
    blob.append(blocks * sizeof(std::uint64_t), '\0');
    for (std::uint64_t b = 0; b < blocks; ++b) {
        const size_t begin = b * k_zlib_block,
                     length = std::min<size_t>(k_zlib_block, size - begin);
        uLongf packed = compressBound(uLong(length));
        const size_t at = blob.size();
        blob.resize(at + packed);
        if (compress2(reinterpret_cast<Bytef*>(blob.data() + at), &packed,
                      reinterpret_cast<const Bytef*>(bytes + begin), uLong(length),
                      Z_DEFAULT_COMPRESSION) != Z_OK)
            throw std::runtime_error("zlib could not compress a VTK block");
        blob.resize(at + packed);
        const std::uint64_t packed64 = packed;
        std::memcpy(blob.data() + sizes_at + b * sizeof packed64, &packed64, sizeof packed64);
    }
}

/// The VTKFile element's opening tag.
std::string vtk_file_tag(const char* type, bool zlib) {
    return fmt::format(
        "<VTKFile type=\"{}\" version=\"1.0\" byte_order=\"LittleEndian\" "
        "header_type=\"UInt64\"{}>\n",
        type, zlib ? " compressor=\"vtkZLibDataCompressor\"" : "");
}

std::vector<float> to_float(const std::vector<double>& v) {
    return {v.begin(), v.end()};
}

/// Appends the point arrays and the positions to `blob`; returns the <PointData> entries and
/// the offset of the positions block.
std::pair<std::string, size_t> append_points(std::string& blob, const PointSet& points, bool zlib) {
    std::string point_data;
    for (const PointArray& a : points.arrays) {
        point_data += fmt::format(
            "        <DataArray type=\"{}\" Name=\"{}\" NumberOfComponents=\"{}\" "
            "format=\"appended\" offset=\"{}\"/>\n",
            a.integer ? "Int64" : "Float32", a.name, a.components, blob.size());
        if (a.integer)
            append_block(blob, std::vector<std::int64_t>(a.values.begin(), a.values.end()), zlib);
        else
            append_block(blob, to_float(a.values), zlib);
    }
    const size_t points_offset = blob.size();
    std::vector<float> xyz;
    xyz.reserve(3 * points.x.size());
    for (const Vec3& x : points.x) xyz.insert(xyz.end(), {float(x[0]), float(x[1]), float(x[2])});
    append_block(blob, xyz, zlib);
    return {point_data, points_offset};
}

std::string finish(std::string head, const std::string& blob) {
    head += blob;
    head += "\n  </AppendedData>\n</VTKFile>\n";
    return head;
}

}  // namespace

namespace {

/// PolyData of the points with one cell block (`kind`: "Verts" or "Polys"): the cells' point
/// indices one after another, and where each cell ends.
std::string polydata_bytes(const PointSet& points, const char* kind,
                           const std::vector<std::int64_t>& conn,
                           const std::vector<std::int64_t>& offsets, bool zlib) {
    std::string blob;
    const auto [point_data, points_offset] = append_points(blob, points, zlib);
    // Int32 cell arrays (half the bytes) whenever the indices fit, as VTK's own writer does.
    const std::int64_t largest =
        std::max<std::int64_t>(offsets.empty() ? 0 : offsets.back(), points.x.size());
    const bool narrow = largest <= std::numeric_limits<std::int32_t>::max();
    auto append_cells = [&](const std::vector<std::int64_t>& v) {
        if (narrow)
            append_block(blob, std::vector<std::int32_t>(v.begin(), v.end()), zlib);
        else
            append_block(blob, v, zlib);
    };
    const size_t conn_offset = blob.size();
    append_cells(conn);
    const size_t offsets_offset = blob.size();
    append_cells(offsets);
    const char* cell_type = narrow ? "Int32" : "Int64";
    const bool verts = std::string_view(kind) == "Verts";
    return finish(
        fmt::format("<?xml version=\"1.0\"?>\n"
                    "{8}"
                    "  <PolyData>\n"
                    "    <Piece NumberOfPoints=\"{0}\" NumberOfVerts=\"{1}\" "
                    "NumberOfLines=\"0\" NumberOfStrips=\"0\" NumberOfPolys=\"{2}\">\n"
                    "      <PointData>\n{3}      </PointData>\n"
                    "      <Points>\n"
                    "        <DataArray type=\"Float32\" NumberOfComponents=\"3\" "
                    "format=\"appended\" offset=\"{4}\"/>\n"
                    "      </Points>\n"
                    "      <{5}>\n"
                    "        <DataArray type=\"{9}\" Name=\"connectivity\" "
                    "format=\"appended\" offset=\"{6}\"/>\n"
                    "        <DataArray type=\"{9}\" Name=\"offsets\" "
                    "format=\"appended\" offset=\"{7}\"/>\n"
                    "      </{5}>\n"
                    "    </Piece>\n"
                    "  </PolyData>\n"
                    "  <AppendedData encoding=\"raw\">\n   _",
                    points.x.size(), verts ? offsets.size() : 0, verts ? 0 : offsets.size(),
                    point_data, points_offset, kind, conn_offset, offsets_offset,
                    vtk_file_tag("PolyData", zlib), cell_type),
        blob);
}

}  // namespace

std::string vtp_bytes(const PointSet& points, bool zlib) {
    std::vector<std::int64_t> conn(points.x.size()), offsets(points.x.size());
    for (size_t i = 0; i < conn.size(); ++i)
        conn[i] = std::int64_t(i), offsets[i] = std::int64_t(i + 1);
    return polydata_bytes(points, "Verts", conn, offsets, zlib);
}

std::string vtp_polygons_bytes(const PointSet& points,
                               const std::vector<std::vector<Index>>& polygons, bool zlib) {
    std::vector<std::int64_t> conn, offsets;
    for (const auto& polygon : polygons) {
        conn.insert(conn.end(), polygon.begin(), polygon.end());
        offsets.push_back(std::int64_t(conn.size()));
    }
    return polydata_bytes(points, "Polys", conn, offsets, zlib);
}

std::string pvd_bytes(const std::vector<PvdEntry>& entries) {
    std::string out =
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" "
        "byte_order=\"LittleEndian\">\n"
        "  <Collection>\n";
    for (const PvdEntry& e : entries)
        out += fmt::format("    <DataSet timestep=\"{:.17g}\" part=\"{}\" file=\"{}\"/>\n", e.time,
                           e.part, e.file);
    out += "  </Collection>\n</VTKFile>\n";
    return out;
}

}  // namespace karst
