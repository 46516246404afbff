#pragma once
// Nodes of a box on a lattice of spacing close to dx, faces included, optionally jittered by a
// fraction of the spacing. Nodes on a face keep their coordinate normal to it, so the box's
// faces stay flat for boundary conditions.
//
// [D, deviation from docs/method.md §5.1.1] The sheet jitters lattices by 1e-3 dx because they are
// fully degenerate for Delaunay. CGAL's exact predicates with symbolic perturbation handle the
// degeneracy (1.4-1.7x slower, perf-facts.md) and give a conforming mesh of 6 tets per cell with
// no sliver; the jittered lattice gives ~1 flat sliver per cell between cells whose shared
// square was split along different diagonals (see mesh_builder.cpp). So meshes for the solver
// are built unjittered; jitter is kept for tests of the mesher itself.
#include "karst/core/types.hpp"

#include <cmath>
#include <random>
#include <vector>

namespace karst {

inline std::vector<Vec3> box_lattice_nodes(const Vec3& lo, const Vec3& hi, Real dx,
                                           Real jitter_fraction = 0, unsigned seed = 1) {
    int cells[3];
    Real step[3];
    for (int c = 0; c < 3; ++c) {
        cells[c] = std::max(1, int(std::lround((hi[c] - lo[c]) / dx)));
        step[c] = (hi[c] - lo[c]) / cells[c];
    }
    std::mt19937_64 random(seed);
    std::uniform_real_distribution<Real> jitter(-jitter_fraction, jitter_fraction);
    std::vector<Vec3> nodes;
    nodes.reserve(size_t(cells[0] + 1) * (cells[1] + 1) * (cells[2] + 1));
    for (int k = 0; k <= cells[2]; ++k)
        for (int j = 0; j <= cells[1]; ++j)
            for (int i = 0; i <= cells[0]; ++i) {
                const int index[3] = {i, j, k};
                Vec3 x;
                for (int c = 0; c < 3; ++c) {
                    const bool on_face = index[c] == 0 || index[c] == cells[c];
                    const Real shake = jitter(random);
                    x[c] = lo[c] + index[c] * step[c] + (on_face ? 0 : shake * step[c]);
                }
                nodes.push_back(x);
            }
    return nodes;
}

}  // namespace karst
