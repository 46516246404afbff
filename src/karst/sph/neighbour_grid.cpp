#include "karst/sph/neighbour_grid.hpp"

#include "karst/core/check.hpp"
#include "karst/core/parallel.hpp"
#include "karst/scene/scene_error.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <numeric>

namespace karst {

UniformGrid::UniformGrid(const Aabb& box, Real cell_size) : origin(box.min), cell(cell_size) {
    if (!(grid_cell_count(box, cell_size) <= k_max_grid_cells))
        throw SceneError("/domain",
                         fmt::format("a domain of at most {:g} cells of size h = {:g} m",
                                     k_max_grid_cells, cell_size),
                         "a larger domain (shrink it or raise particle_spacing)");
    for (int d = 0; d < 3; ++d)
        dims[d] = int(std::max(1.0, std::ceil((box.max[d] - box.min[d]) / cell_size)));
}

std::array<int, 3> UniformGrid::coords(const Vec3& x) const {
    std::array<int, 3> c;
    for (int d = 0; d < 3; ++d)
        c[d] = std::clamp(int(std::floor((x[d] - origin[d]) / cell)), 0, dims[d] - 1);
    return c;
}

void sort_into_cells(const UniformGrid& grid, const std::vector<Vec3>& x, CellRanges& out) {
    const Index n = Index(x.size());
    std::vector<std::uint32_t> cell(n);
    parallel_for(n, [&](Index i) { cell[i] = std::uint32_t(grid.cell_of(x[i])); });
    // Counting sort: histogram, exclusive prefix sum, stable scatter.
    out.start.assign(grid.cell_count() + 1, 0);
    for (Index i = 0; i < n; ++i) ++out.start[cell[i] + 1];
    for (Index c = 0; c < grid.cell_count(); ++c) out.start[c + 1] += out.start[c];
    out.order.resize(n);
    std::vector<std::uint32_t> fill(out.start.begin(), out.start.end() - 1);
    for (Index i = 0; i < n; ++i) out.order[fill[cell[i]]++] = std::uint32_t(i);
    out.sorted_x.resize(n);
    parallel_for(n, [&](Index s) { out.sorted_x[s] = x[out.order[s]]; });
}

void find_neighbours(const UniformGrid& grid, const std::vector<Vec3>& queries,
                     const CellRanges& targets, bool exclude_self, NeighbourLists& out) {
    const Index n = Index(queries.size());
    const Real h2 = grid.cell * grid.cell;
    for (;;) {
        const int cap = out.capacity;
        out.index.resize(size_t(n) * cap);
        out.count.resize(n);
        std::atomic<int> most{0};
        parallel_for(n, [&](Index i) {
            const Vec3 xi = queries[i];
            const auto c = grid.coords(xi);
            const int x0 = std::max(c[0] - 1, 0), x1 = std::min(c[0] + 1, grid.dims[0] - 1);
            // Every candidate is written and the count advanced by the test: within h or not
            // is a coin toss per candidate, and a branch on it mispredicts often.
            thread_local std::vector<std::uint32_t> found;
            const std::uint32_t self = exclude_self ? std::uint32_t(i) : ~std::uint32_t(0);
            int k = 0;
            for (int dz = -1; dz <= 1; ++dz) {
                const int z = c[2] + dz;
                if (z < 0 || z >= grid.dims[2]) continue;
                for (int dy = -1; dy <= 1; ++dy) {
                    const int y = c[1] + dy;
                    if (y < 0 || y >= grid.dims[1]) continue;
                    // Cells x0..x1 of one row are consecutive, so their particles are one range.
                    const std::uint32_t b = targets.start[grid.linear({x0, y, z})];
                    const std::uint32_t e = targets.start[grid.linear({x1, y, z}) + 1];
                    if (found.size() < size_t(k) + (e - b)) found.resize(2 * (size_t(k) + (e - b)));
                    std::uint32_t* into = found.data();
                    for (std::uint32_t s = b; s < e; ++s) {
                        const std::uint32_t j = targets.order[s];
                        into[k] = j;
                        k += int((targets.sorted_x[s] - xi).squaredNorm() < h2) & int(j != self);
                    }
                }
            }
            std::copy_n(found.data(), std::min(k, cap), out.index.data() + i * cap);
            out.count[i] = std::uint16_t(std::min(k, cap));
            if (k > cap) {
                int m = most.load();
                while (k > m && !most.compare_exchange_weak(m, k)) {
                }
            }
        });
        if (most.load() == 0) return;
        KARST_CHECK(most.load() < 65535, "a particle has {} neighbours: particles collapsed",
                    most.load());
        out.capacity = most.load() + 16;  // grow and search again
    }
}

namespace {
std::uint64_t spread_bits(std::uint64_t v) {  // 21 bits -> every third bit
    v &= 0x1fffff;
    v = (v | v << 32) & 0x1f00000000ffffULL;
    v = (v | v << 16) & 0x1f0000ff0000ffULL;
    v = (v | v << 8) & 0x100f00f00f00f00fULL;
    v = (v | v << 4) & 0x10c30c30c30c30c3ULL;
    v = (v | v << 2) & 0x1249249249249249ULL;
    return v;
}
}  // namespace

std::vector<std::uint32_t> morton_order(const UniformGrid& grid, const std::vector<Vec3>& x) {
    const Index n = Index(x.size());
    std::vector<std::pair<std::uint64_t, std::uint32_t>> keys(n);
    parallel_for(n, [&](Index i) {
        const auto c = grid.coords(x[i]);
        keys[i] = {spread_bits(c[0]) | spread_bits(c[1]) << 1 | spread_bits(c[2]) << 2,
                   std::uint32_t(i)};
    });
    std::sort(keys.begin(), keys.end());
    std::vector<std::uint32_t> perm(n);
    for (Index k = 0; k < n; ++k) perm[k] = keys[k].second;
    return perm;
}

}  // namespace karst
