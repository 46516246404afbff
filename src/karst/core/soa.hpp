#pragma once
// Helpers for structure-of-arrays particle sets.
#include <cstddef>
#include <vector>

namespace karst {

/// Keeps the elements whose flag is set, in order.
template <class T>
void keep_flagged(std::vector<T>& a, const std::vector<char>& keep) {
    std::size_t k = 0;
    for (std::size_t i = 0; i < a.size(); ++i)
        if (keep[i]) a[k++] = a[i];
    a.resize(k);
}

}  // namespace karst
