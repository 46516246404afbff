#include "karst/io/ply_writer.hpp"

#include <fmt/format.h>

namespace karst {

std::string ply_bytes(const PointSet& points) {
    const size_t n = points.x.size();
    std::string header = fmt::format(
        "ply\nformat binary_little_endian 1.0\ncomment karst {}\nelement vertex {}\n"
        "property float x\nproperty float y\nproperty float z\n",
        KARST_VERSION, n);
    for (const PointArray& a : points.arrays) {
        const char* type = a.integer ? "int" : "float";
        if (a.components == 1)
            header += fmt::format("property {} {}\n", type, a.name);
        else
            for (const char* axis : {"x", "y", "z"})
                header += fmt::format("property {} {}_{}\n", type, a.name, axis);
    }
    header += "end_header\n";

    size_t row = 3 * sizeof(float);
    for (const PointArray& a : points.arrays) row += size_t(a.components) * 4;
    std::string out = header;
    out.reserve(header.size() + n * row);
    auto put = [&](auto value) { out.append(reinterpret_cast<const char*>(&value), sizeof value); };
    for (size_t i = 0; i < n; ++i) {
        for (int d = 0; d < 3; ++d) put(float(points.x[i][d]));
        for (const PointArray& a : points.arrays)
            for (int c = 0; c < a.components; ++c) {
                const double v = a.values[i * a.components + c];
                if (a.integer)
                    put(std::int32_t(v));
                else
                    put(float(v));
            }
    }
    return out;
}

}  // namespace karst
