#pragma once
// A flat binary archive for checkpoints (sim/checkpoint.hpp). One list of fields per type,
// `fields(archive, value)` found by argument-dependent lookup, serves both directions: the
// writer appends the bytes of each field, the reader fills the same fields in the same order.
// The reader trusts nothing: every length is checked against the bytes left before anything is
// allocated, so a truncated or damaged file ends in ArchiveError, never in a crash.
#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

namespace karst {

struct ArchiveError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

template <class T>
concept ArchiveScalar = std::is_arithmetic_v<T> || std::is_enum_v<T>;

template <class T>
concept FixedEigen = requires {
    T::RowsAtCompileTime;
    T::ColsAtCompileTime;
}
&&T::RowsAtCompileTime > 0 && T::ColsAtCompileTime > 0;

/// The dispatch both directions share: scalars and fixed-size Eigen values are raw bytes, tuples
/// and arrays their elements, strings and vectors a count then their elements, any other type its
/// `fields`. Derived supplies raw(pointer, bytes) and sequence(container).
template <class Derived>
class ArchiveBase {
protected:
    template <class T>
    void field(T& v) {
        Derived& self = static_cast<Derived&>(*this);
        if constexpr (ArchiveScalar<T>)
            self.raw(&v, sizeof v);
        else if constexpr (FixedEigen<T>)
            self.raw(v.data(), sizeof(typename T::Scalar) * v.size());
        else if constexpr (std::is_same_v<T, Eigen::Quaterniond>)
            self.raw(v.coeffs().data(), 4 * sizeof(double));
        else if constexpr (requires { std::tuple_size<T>::value; })
            std::apply([&](auto&... e) { (field(e), ...); }, v);
        else if constexpr (requires { typename T::value_type; })
            self.sequence(v);
        else
            fields(self, v);
    }
};

class ArchiveWriter : public ArchiveBase<ArchiveWriter> {
public:
    /// The writer only reads the values it is given.
    template <class... T>
    void operator()(const T&... values) {
        (field(const_cast<T&>(values)), ...);
    }
    const std::string& bytes() const { return m_bytes; }

private:
    friend class ArchiveBase<ArchiveWriter>;
    void raw(const void* data, size_t n) {
        if (n > 0) m_bytes.append(static_cast<const char*>(data), n);  // empty: data may be null
    }
    template <class C>
    void sequence(C& c) {
        std::uint64_t n = c.size();
        raw(&n, sizeof n);
        if constexpr (ArchiveScalar<typename C::value_type>)
            raw(c.data(), sizeof(typename C::value_type) * c.size());
        else
            for (auto& e : c) field(e);
    }
    void sequence(std::vector<bool>&) = delete;

    std::string m_bytes;
};

class ArchiveReader : public ArchiveBase<ArchiveReader> {
public:
    explicit ArchiveReader(std::string_view bytes) : m_bytes(bytes) {}
    template <class... T>
    void operator()(T&... values) {
        (field(values), ...);
    }
    size_t left() const { return m_bytes.size() - m_at; }

private:
    friend class ArchiveBase<ArchiveReader>;
    void raw(void* data, size_t n) {
        if (n > left())
            throw ArchiveError("the file ends " + std::to_string(n - left()) +
                               " bytes early (truncated or damaged)");
        if (n == 0) return;  // an empty vector's data() may be null, which memcpy may not take
        std::memcpy(data, m_bytes.data() + m_at, n);
        m_at += n;
    }
    /// A count, then that many elements: the count must fit in the bytes left (each element
    /// takes at least one byte) before anything is allocated.
    template <class C>
    void sequence(C& c) {
        std::uint64_t n = 0;
        raw(&n, sizeof n);
        using T = typename C::value_type;
        const size_t least = ArchiveScalar<T> ? sizeof(T) : 1;
        if (n > left() / least)
            throw ArchiveError("a list of " + std::to_string(n) + " entries does not fit in the " +
                               std::to_string(left()) + " bytes left (damaged file)");
        c.clear();
        c.resize(size_t(n));
        if constexpr (ArchiveScalar<T>)
            raw(c.data(), sizeof(T) * c.size());
        else
            for (auto& e : c) field(e);
    }

    std::string_view m_bytes;
    size_t m_at = 0;
};

}  // namespace karst
