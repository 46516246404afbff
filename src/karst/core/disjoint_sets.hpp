#pragma once
// Union-find over [0, n) with path halving. The root of a set is its smallest member, so the
// numbering of sets never depends on the order of the joins.
#include "karst/core/types.hpp"

#include <algorithm>
#include <numeric>
#include <vector>

namespace karst {

struct DisjointSets {
    std::vector<Index> parent;
    explicit DisjointSets(Index n) : parent(n) {
        std::iota(parent.begin(), parent.end(), Index(0));
    }
    Index find(Index x) {
        while (parent[x] != x) x = parent[x] = parent[parent[x]];
        return x;
    }
    void join(Index a, Index b) {
        a = find(a), b = find(b);
        if (a != b) parent[std::max(a, b)] = std::min(a, b);
    }
};

}  // namespace karst
