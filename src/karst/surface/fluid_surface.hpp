#pragma once
// The fluid surface (docs/method.md §7): the level set c = iso of the SPH colour field
// c(x) = sum_j V_j W_j(x - x_j), sampled on a sparse OpenVDB grid and meshed by its
// VolumeToMesh. Isotropic kernels are the cubic spline of support h; the anisotropic option
// (Yu & Turk 2013, M28) stretches each kernel along its neighbourhood's weighted PCA and moves
// its centre to x_i + lambda (x_i^w - x_i), lambda = 0.9, so thin sheets stay sheets.
#include "karst/surface/surface_mesh.hpp"

#include <string>
#include <vector>

namespace karst {

struct FluidSurfaceOptions {
    Real voxel = 0;            ///< grid spacing, m
    bool anisotropic = false;  ///< Yu-Turk kernels instead of spheres of radius h
    Real iso = 0.5;            ///< the colour value on the surface (1 inside the fluid)
};

/// The closed, outward surface of the particles x with volumes V (m^3) and kernel support h, with
/// vertex normals; the same bits on any thread count. With `level_set`, it gets the grid
/// phi = iso - c (negative inside) as a .vdb file's bytes.
SurfaceMesh colour_field_surface(const std::vector<Vec3>& x, const std::vector<Real>& volume,
                                 Real h, const FluidSurfaceOptions& options,
                                 std::string* level_set = nullptr);

/// Shepard interpolation A(p) = sum_j V_j A_j W(p - x_j) / sum_j V_j W(p - x_j) (§7) of each
/// column (a value per particle) at the points `at`, with the cubic spline of support `support`;
/// 0 where no particle is within reach. Returns one vector per column.
std::vector<std::vector<Real>> shepard_interpolate(const std::vector<Vec3>& at,
                                                   const std::vector<Vec3>& x,
                                                   const std::vector<Real>& volume, Real support,
                                                   const std::vector<std::vector<Real>>& columns);

}  // namespace karst
