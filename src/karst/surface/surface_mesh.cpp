#include "karst/surface/surface_mesh.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>

namespace karst {

std::vector<Vec3> vertex_normals(const std::vector<Vec3>& x,
                                 const std::vector<std::array<Index, 3>>& triangles) {
    std::vector<Vec3> n(x.size(), Vec3::Zero());
    for (const auto& t : triangles) {
        const Vec3 area2 = (x[t[1]] - x[t[0]]).cross(x[t[2]] - x[t[0]]);
        for (Index v : t) n[v] += area2;
    }
    for (Vec3& v : n) {
        const Real length = v.norm();
        if (length > 0) v /= length;
    }
    return n;
}

SurfaceMeasures surface_measures(const SurfaceMesh& mesh) {
    SurfaceMeasures m;
    const std::vector<Vec3>& x = mesh.vertices.x;
    for (const auto& t : mesh.triangles) {
        const Vec3 &a = x[t[0]], &b = x[t[1]], &c = x[t[2]];
        m.area += 0.5 * (b - a).cross(c - a).norm();
        m.volume += a.dot(b.cross(c)) / 6;
    }
    return m;
}

Rgb m29_colour(Real s, Real hue_deg, Real hsl_saturation) {
    const Real lightness = 0.8 - 0.6 * std::clamp(s, Real(0), Real(1));
    // HSL to RGB (the standard hexcone formulas).
    const Real chroma = (1 - std::abs(2 * lightness - 1)) * hsl_saturation;
    const Real h = std::fmod(hue_deg, 360) / 60;
    const Real second = chroma * (1 - std::abs(std::fmod(h, 2) - 1));
    Vec3 rgb;
    switch (int(h)) {
        case 0:
            rgb = {chroma, second, 0};
            break;
        case 1:
            rgb = {second, chroma, 0};
            break;
        case 2:
            rgb = {0, chroma, second};
            break;
        case 3:
            rgb = {0, second, chroma};
            break;
        case 4:
            rgb = {second, 0, chroma};
            break;
        default:
            rgb = {chroma, 0, second};
            break;
    }
    rgb.array() += lightness - chroma / 2;
    Rgb out;
    for (int c = 0; c < 3; ++c)
        out[c] = std::uint8_t(std::lround(255 * std::clamp(rgb[c], Real(0), Real(1))));
    return out;
}

}  // namespace karst
