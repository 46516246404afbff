#pragma once
// Reads back the EnSight Gold (C Binary) files karst writes for its meshes, following the
// format's rules (80-character records, one part, Float32 component-major values), so tests can
// check a frame holds exactly what was written.
#include <array>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

namespace karst::test {

class EnsightCursor {
public:
    explicit EnsightCursor(const std::string& bytes) : m_bytes(bytes) {}
    std::string line() {
        const std::string raw = take(80);
        return raw.substr(0, raw.find('\0'));
    }
    template <class T>
    T value() {
        T v;
        std::memcpy(&v, take(sizeof v).data(), sizeof v);
        return v;
    }
    bool done() const { return m_at == m_bytes.size(); }

private:
    std::string take(size_t n) {
        if (m_at + n > m_bytes.size()) throw std::runtime_error("EnSight file ends early");
        m_at += n;
        return m_bytes.substr(m_at - n, n);
    }
    const std::string& m_bytes;
    size_t m_at = 0;
};

struct EnsightGeometry {
    std::vector<std::array<double, 3>> x;
    std::vector<std::array<std::int32_t, 4>> tets;  ///< 1-based, as in the file
};

inline void expect_record(EnsightCursor& in, const std::string& expected) {
    const std::string got = in.line();
    if (got != expected)
        throw std::runtime_error("expected '" + expected + "', found '" + got + "'");
}

inline EnsightGeometry read_ensight_geometry(const std::string& bytes) {
    EnsightCursor in(bytes);
    expect_record(in, "C Binary");
    in.line(), in.line();
    expect_record(in, "node id off");
    expect_record(in, "element id off");
    expect_record(in, "part");
    if (in.value<std::int32_t>() != 1) throw std::runtime_error("part is not 1");
    in.line();
    expect_record(in, "coordinates");
    EnsightGeometry g;
    g.x.resize(size_t(in.value<std::int32_t>()));
    for (int c = 0; c < 3; ++c)
        for (auto& x : g.x) x[c] = in.value<float>();
    expect_record(in, "tetra4");
    g.tets.resize(size_t(in.value<std::int32_t>()));
    for (auto& t : g.tets)
        for (auto& node : t) node = in.value<std::int32_t>();
    if (!in.done()) throw std::runtime_error("bytes after the geometry");
    return g;
}

/// The values of a per-node variable file of `n` nodes and `components` components, in the
/// file's component-major order.
inline std::vector<double> read_ensight_variable(const std::string& bytes, size_t n, int components,
                                                 std::string* name = nullptr) {
    EnsightCursor in(bytes);
    const std::string description = in.line();
    if (name) *name = description;
    expect_record(in, "part");
    if (in.value<std::int32_t>() != 1) throw std::runtime_error("part is not 1");
    expect_record(in, "coordinates");
    std::vector<double> values(n * size_t(components));
    for (double& v : values) v = in.value<float>();
    if (!in.done()) throw std::runtime_error("bytes after the values");
    return values;
}

}  // namespace karst::test
