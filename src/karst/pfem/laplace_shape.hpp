#pragma once
// Laplace (non-Sibsonian) shape functions on an EDT polyhedron (docs/method.md §5.2, M21):
//   N_i(x) = (s_i / h_i) / sum_j (s_j / h_j),
// s_i the area of the Voronoi facet shared by x and node i in the Voronoi diagram of
// {x} and the nodes, h_i = |x - n_i|. On a single tet they are the barycentric coordinates.
//
// The facet is found without a triangulation: it is the bisector plane of x and n_i, clipped by
// the half-spaces nearer x than every other node (a convex polygon), which is exact and cheap
// for the few nodes of a polyhedron. x must lie strictly inside the nodes' convex hull.
#include "karst/core/types.hpp"

#include <span>
#include <vector>

namespace karst {

/// N_i(x) for every node, written to `N` (same size as `nodes`).
void laplace_shape(std::span<const Vec3> nodes, const Vec3& x, std::span<Real> N);

/// N_i(x) and grad N_i(x); the gradients by central differences with step `step` (M21 allows
/// 1e-4 dx).
void laplace_shape_and_gradient(std::span<const Vec3> nodes, const Vec3& x, Real step,
                                std::span<Real> N, std::span<Vec3> gradient);

}  // namespace karst
