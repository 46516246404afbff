#pragma once
// A triangle surface with per-vertex values and colours: what the fluid and porous surface
// builders make and the PLY and VTK writers write (docs/method.md §7).
#include "karst/io/point_arrays.hpp"

#include <array>
#include <cstdint>
#include <vector>

namespace karst {

using Rgb = std::array<std::uint8_t, 3>;

struct SurfaceMesh {
    PointSet vertices;                            ///< positions and named per-vertex arrays
    std::vector<std::array<Index, 3>> triangles;  ///< outward (right-hand) orientation
    std::vector<Rgb> colour;                      ///< per vertex (M29), empty if none

    Index vertex_count() const { return Index(vertices.x.size()); }
    Index triangle_count() const { return Index(triangles.size()); }
};

/// Area-weighted vertex normals of the triangles, unit length (zero for a vertex of no
/// triangle); summed over the triangles in order, so the same on any thread count.
std::vector<Vec3> vertex_normals(const std::vector<Vec3>& x,
                                 const std::vector<std::array<Index, 3>>& triangles);

/// Area and enclosed volume (divergence theorem; exact for a closed, outward mesh).
struct SurfaceMeasures {
    Real area = 0, volume = 0;
};
SurfaceMeasures surface_measures(const SurfaceMesh& mesh);

/// M29: the colour of lightness L = 0.8 - 0.6 s (s clamped to [0, 1]) at a fixed hue (degrees)
/// and HSL saturation.
Rgb m29_colour(Real s, Real hue_deg, Real hsl_saturation);

/// The fixed hue and saturation of each surface: water blue, rock sandstone.
inline constexpr Real k_water_hue = 200, k_water_saturation = 0.55;
inline constexpr Real k_rock_hue = 32, k_rock_saturation = 0.45;

}  // namespace karst
