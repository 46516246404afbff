#include "karst/io/ensight_writer.hpp"

#include <fmt/format.h>

#include <cstdint>
#include <cstring>
#include <stdexcept>

namespace karst {

namespace {

/// EnSight's 80-character record.
void put_line(std::string& out, std::string_view text) {
    std::string line(80, '\0');
    std::memcpy(line.data(), text.data(), std::min<size_t>(text.size(), 79));
    out += line;
}

template <class T>
void put(std::string& out, T value) {
    char bytes[sizeof(T)];
    std::memcpy(bytes, &value, sizeof(T));
    out.append(bytes, sizeof(T));
}

std::int32_t checked_int32(size_t n, const char* what) {
    if (n > size_t(INT32_MAX))
        throw std::runtime_error(fmt::format("EnSight holds at most 2^31 - 1 {}", what));
    return std::int32_t(n);
}

/// The part header every file of the one part repeats.
void put_part(std::string& out) {
    put_line(out, "part");
    put<std::int32_t>(out, 1);
}

/// Variable type keyword of the .case file.
const char* variable_kind(int components) {
    switch (components) {
        case 1:
            return "scalar per node";
        case 3:
            return "vector per node";
        case 6:
            return "tensor symm per node";
    }
    throw std::logic_error("EnSight: an array of 1, 3 or 6 components");
}

void put_numbers(std::string& out, const std::vector<std::string>& numbers) {
    for (size_t k = 0; k < numbers.size(); ++k)
        out += numbers[k] + ((k + 1) % 6 == 0 || k + 1 == numbers.size() ? "\n" : " ");
}

}  // namespace

std::string ensight_geometry_bytes(const PointSet& points,
                                   const std::vector<std::array<Index, 4>>& tets) {
    const std::int32_t n = checked_int32(points.x.size(), "nodes");
    std::string out;
    put_line(out, "C Binary");
    put_line(out, "karst PFEM meshes");
    put_line(out, "rest positions of the structures' nodes, m");
    put_line(out, "node id off");
    put_line(out, "element id off");
    put_part(out);
    put_line(out, "PFEM mesh");
    put_line(out, "coordinates");
    put<std::int32_t>(out, n);
    for (int c = 0; c < 3; ++c)
        for (const Vec3& x : points.x) put(out, float(x[c]));
    put_line(out, "tetra4");
    put<std::int32_t>(out, checked_int32(tets.size(), "tetrahedra"));
    for (const std::array<Index, 4>& t : tets)
        for (Index node : t) put(out, std::int32_t(node + 1));
    return out;
}

std::string ensight_variable_bytes(const PointSet& points, const PointArray& array) {
    // EnSight's symmetric tensor order 11 22 33 12 13 23, from VTK's xx yy zz xy yz xz.
    static constexpr int k_from_vtk[6] = {0, 1, 2, 3, 5, 4};
    const size_t n = points.x.size();
    const int components = array.components;
    std::string out;
    put_line(out, array.name);
    put_part(out);
    put_line(out, "coordinates");
    for (int c = 0; c < components; ++c) {
        const int from = components == 6 ? k_from_vtk[c] : c;
        for (size_t i = 0; i < n; ++i) put(out, float(array.values[i * components + from]));
    }
    return out;
}

std::string ensight_file(const std::string& stem, const std::string& what, int frame) {
    return what.empty() ? fmt::format("{}_{:04d}.geo", stem, frame)
                        : fmt::format("{}_{}_{:04d}.ens", stem, what, frame);
}

std::string ensight_case_bytes(const std::string& stem, const PointSet& layout,
                               const std::vector<EnsightStep>& steps) {
    std::string out = "FORMAT\ntype: ensight gold\n\nGEOMETRY\n";
    out += fmt::format("model: 1 {}_****.geo\n\nVARIABLE\n", stem);
    for (size_t k = 0; k < layout.arrays.size(); ++k) {
        const PointArray& a = layout.arrays[k];
        out += fmt::format("{}: {} {} {}_{}_****.ens\n", variable_kind(a.components), k + 2, a.name,
                           stem, a.name);
    }
    std::vector<std::string> times;
    for (const EnsightStep& s : steps) times.push_back(fmt::format("{:.9g}", s.time));
    out += "\nTIME\n";
    for (size_t k = 0; k <= layout.arrays.size(); ++k) {
        std::vector<std::string> numbers;
        for (const EnsightStep& s : steps) numbers.push_back(std::to_string(s.files.at(k)));
        out += fmt::format("time set: {}\nnumber of steps: {}\nfilename numbers:\n", k + 1,
                           steps.size());
        put_numbers(out, numbers);
        out += "time values:\n";
        put_numbers(out, times);
    }
    return out;
}

}  // namespace karst
