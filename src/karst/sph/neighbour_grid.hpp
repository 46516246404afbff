#pragma once
// Neighbour search on a uniform cell grid (cell size h) built by counting sort, with
// fixed-capacity neighbour lists per particle, and the Morton (Z-curve) order used to reorder
// particle arrays for locality. Results do not depend on the thread count: a particle's
// neighbours are listed in cell order, then in array order within a cell.
#include "karst/core/types.hpp"
#include "karst/scene/geometry.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace karst {

/// A grid this large (4 bytes per cell) would cost gigabytes: the domain is too big for h.
inline constexpr double k_max_grid_cells = 4e8;

/// Cells of edge `cell_size` covering `box`, at least one per axis.
inline double grid_cell_count(const Aabb& box, Real cell_size) {
    double cells = 1;
    for (int d = 0; d < 3; ++d)
        cells *= std::max(1.0, std::ceil((box.max[d] - box.min[d]) / cell_size));
    return cells;
}

struct UniformGrid {
    Vec3 origin = Vec3::Zero();  ///< lower corner of cell (0, 0, 0), m
    Real cell = 1;               ///< cell edge = support radius h, m
    std::array<int, 3> dims{1, 1, 1};

    UniformGrid() = default;
    /// Grid covering `box`; throws SceneError if it would need more than k_max_grid_cells.
    UniformGrid(const Aabb& box, Real cell_size);
    Index cell_count() const { return Index(dims[0]) * dims[1] * dims[2]; }
    std::array<int, 3> coords(const Vec3& x) const;
    Index linear(const std::array<int, 3>& c) const {
        return c[0] + Index(dims[0]) * (c[1] + Index(dims[1]) * c[2]);
    }
    Index cell_of(const Vec3& x) const { return linear(coords(x)); }
};

/// Particles sorted by cell: the particles of cell c are order[start[c] .. start[c + 1]), and
/// sorted_x holds their positions in that order (contiguous reads in the neighbour loop).
struct CellRanges {
    std::vector<std::uint32_t> start;  ///< (cells + 1)
    std::vector<std::uint32_t> order;  ///< (n) particle index per sorted slot
    std::vector<Vec3> sorted_x;        ///< (n) m
};

/// Counting sort of `x` into the cells of `grid` (stable, so deterministic). Every x must lie
/// inside the grid.
void sort_into_cells(const UniformGrid& grid, const std::vector<Vec3>& x, CellRanges& out);

/// Neighbour lists with a fixed capacity per particle: the neighbours of i are
/// index[i * capacity .. i * capacity + count[i]).
struct NeighbourLists {
    int capacity = 48;
    std::vector<std::uint32_t> index;
    std::vector<std::uint16_t> count;
    template <class F>
    void for_each(Index i, const F& f) const {
        const std::uint32_t* list = index.data() + i * capacity;
        for (int k = 0; k < count[i]; ++k) f(Index(list[k]));
    }
};

/// For each query point, lists the particles of `targets` closer than grid.cell (strictly).
/// With `exclude_self`, the query i skips target i (queries and targets are the same set).
/// The capacity grows (and the search repeats) when a particle has more neighbours.
void find_neighbours(const UniformGrid& grid, const std::vector<Vec3>& queries,
                     const CellRanges& targets, bool exclude_self, NeighbourLists& out);

/// Calls f(j, x_j) for every particle j of `targets` closer to `at` than `radius` (strictly),
/// scanning the cells within ceil(radius / grid.cell) of at's cell row by row, without storing a
/// list: for wide searches whose lists would not fit in memory. A cell of half the radius scans
/// 125 cells of 1/8 the volume, 42 % less space than 27 cells of the radius.
template <class F>
void for_each_within(const UniformGrid& grid, const CellRanges& targets, const Vec3& at,
                     Real radius, const F& f) {
    const Real r2 = radius * radius;
    const int reach = int(std::ceil(radius / grid.cell - 1e-9));
    const auto c = grid.coords(at);
    const int x0 = std::max(c[0] - reach, 0), x1 = std::min(c[0] + reach, grid.dims[0] - 1);
    for (int z = std::max(c[2] - reach, 0); z <= std::min(c[2] + reach, grid.dims[2] - 1); ++z)
        for (int y = std::max(c[1] - reach, 0); y <= std::min(c[1] + reach, grid.dims[1] - 1); ++y)
            for (std::uint32_t s = targets.start[grid.linear({x0, y, z})],
                               e = targets.start[grid.linear({x1, y, z}) + 1];
                 s < e; ++s)
                if ((targets.sorted_x[s] - at).squaredNorm() < r2)
                    f(Index(targets.order[s]), targets.sorted_x[s]);
}

/// for_each_within with the radius grid.cell: in the order find_neighbours lists them.
template <class F>
void for_each_within(const UniformGrid& grid, const CellRanges& targets, const Vec3& at,
                     const F& f) {
    for_each_within(grid, targets, at, grid.cell, f);
}

/// Permutation sorting `x` along the Morton curve of their grid cells (ties by index).
std::vector<std::uint32_t> morton_order(const UniformGrid& grid, const std::vector<Vec3>& x);

}  // namespace karst
