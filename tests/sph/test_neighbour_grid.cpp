#include "karst/core/parallel.hpp"
#include "karst/sph/neighbour_grid.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>

namespace karst {
namespace {

std::vector<Vec3> random_points(size_t n, const Aabb& box, unsigned seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<Real> u(0, 1);
    std::vector<Vec3> x(n);
    for (Vec3& p : x) p = box.min + (box.max - box.min).cwiseProduct(Vec3(u(rng), u(rng), u(rng)));
    return x;
}

TEST(NeighbourGrid, EqualsBruteForceOnRandomSets) {
    for (unsigned seed : {1u, 2u, 3u}) {
        const Aabb box{Vec3(-0.3, 0.1, 0.0), Vec3(0.5, 0.6, 0.35)};
        const Real h = 0.05 + 0.01 * seed;
        const auto queries = random_points(3000, box, seed);
        const auto targets = random_points(2500, box, seed + 100);
        const UniformGrid grid(box, h);
        CellRanges cells;
        sort_into_cells(grid, targets, cells);
        NeighbourLists lists;
        lists.capacity = 4;  // force the grow-and-retry path
        find_neighbours(grid, queries, cells, false, lists);
        for (size_t i = 0; i < queries.size(); ++i) {
            std::set<Index> expected, found;
            for (size_t j = 0; j < targets.size(); ++j)
                if ((queries[i] - targets[j]).norm() < h) expected.insert(Index(j));
            lists.for_each(Index(i), [&](Index j) { found.insert(j); });
            ASSERT_EQ(found, expected) << "query " << i << " seed " << seed;
        }
    }
}

TEST(NeighbourGrid, SelfExclusionAndMortonPermutation) {
    const Aabb box{Vec3::Zero(), Vec3::Ones()};
    const auto x = random_points(2000, box, 7);
    const UniformGrid grid(box, 0.1);
    CellRanges cells;
    sort_into_cells(grid, x, cells);
    NeighbourLists lists;
    find_neighbours(grid, x, cells, true, lists);
    for (Index i = 0; i < Index(x.size()); ++i) {
        size_t brute = 0;
        for (const Vec3& y : x) brute += (x[i] - y).norm() < 0.1;
        lists.for_each(i, [&](Index j) { ASSERT_NE(i, j); });
        ASSERT_EQ(size_t(lists.count[i]) + 1, brute);
    }
    auto perm = morton_order(grid, x);
    std::vector<std::uint32_t> sorted = perm;
    std::sort(sorted.begin(), sorted.end());
    for (size_t k = 0; k < sorted.size(); ++k) ASSERT_EQ(sorted[k], k);
    // Morton order keeps consecutive particles close: mean jump far below the box size.
    Real jump = 0;
    for (size_t k = 1; k < perm.size(); ++k) jump += (x[perm[k]] - x[perm[k - 1]]).norm();
    EXPECT_LT(jump / Real(perm.size()), 0.25);
}

}  // namespace
}  // namespace karst
