#pragma once
// Structure-of-arrays particle sets. A set lists its attributes once, in
// `for_each_attribute(f, sets...)`, which calls f(a.attr, b.attr, ...) for every attribute of
// the given sets; resizing, keeping, permuting and appending go through that list, so no
// operation can leave one attribute short (tests/core/test_soa.cpp checks that the list holds
// every member).
#include <cstddef>
#include <cstdint>
#include <type_traits>
#include <vector>

namespace karst {

/// A value with no content: zero for numbers and for Eigen vectors and matrices.
template <class T>
T zero_value() {
    if constexpr (requires { T::Zero(); })
        return T::Zero();
    else
        return T{};
}

/// Keeps the elements whose flag is set, in order.
template <class T>
void keep_flagged(std::vector<T>& a, const std::vector<char>& keep) {
    std::size_t k = 0;
    for (std::size_t i = 0; i < a.size(); ++i)
        if (keep[i]) a[k++] = a[i];
    a.resize(k);
}

/// Reorders a by perm (new k <- old perm[k]).
template <class T>
void apply_permutation(std::vector<T>& a, const std::vector<std::uint32_t>& perm) {
    std::vector<T> tmp(a.size());
    for (std::size_t k = 0; k < perm.size(); ++k) tmp[k] = a[perm[k]];
    a.swap(tmp);
}

/// Every attribute resized to n; new elements are zero.
template <class Set>
void resize_attributes(Set& set, std::size_t n) {
    Set::for_each_attribute(
        [&](auto& a) { a.resize(n, zero_value<typename std::decay_t<decltype(a)>::value_type>()); },
        set);
}

/// Keeps the particles whose flag is set, in order.
template <class Set>
void keep_attributes(Set& set, const std::vector<char>& flag) {
    Set::for_each_attribute([&](auto& a) { keep_flagged(a, flag); }, set);
}

/// Reorders every attribute by perm (new k <- old perm[k]).
template <class Set>
void permute_attributes(Set& set, const std::vector<std::uint32_t>& perm) {
    Set::for_each_attribute([&](auto& a) { apply_permutation(a, perm); }, set);
}

/// Appends the particles of `other`.
template <class Set>
void append_attributes(Set& set, const Set& other) {
    Set::for_each_attribute([](auto& a, const auto& b) { a.insert(a.end(), b.begin(), b.end()); },
                            set, other);
}

/// True when every attribute has `n` elements.
template <class Set>
bool attributes_sized(const Set& set, std::size_t n) {
    bool ok = true;
    Set::for_each_attribute([&](const auto& a) { ok = ok && a.size() == n; }, set);
    return ok;
}

}  // namespace karst
