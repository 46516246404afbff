#include "karst/scene/wall_crossing.hpp"

#include <algorithm>

namespace karst {

namespace {

/// The outward normal of a wall's open side at x: the gradient of the signed distance of the
/// region a particle may not enter (central differences; unit length or zero).
Vec3 outward_normal(const Wall& wall, const Vec3& x, Real step) {
    const Real sign = wall.kind == Wall::Kind::Container ? 1 : -1;
    Vec3 g;
    for (int d = 0; d < 3; ++d) {
        Vec3 e = Vec3::Zero();
        e[d] = step;
        g[d] = sign * (wall.shape.signed_distance(x + e) - wall.shape.signed_distance(x - e));
    }
    const Real norm = g.norm();
    return norm > 0 ? Vec3(g / norm) : Vec3::Zero();
}

}  // namespace

bool push_back_through_walls(const std::vector<Wall>& walls, Real dx, Vec3& x, Vec3& v) {
    bool pushed = false;
    for (const Wall& wall : walls) {
        const Real d = wall.shape.signed_distance(x);
        const Real outside =
            wall.kind == Wall::Kind::Container ? d : -d;  // > 0: on the wall's side
        if (!(outside > 0)) continue;
        const Vec3 n = outward_normal(wall, x, 0.1 * dx);
        x -= (outside + k_push_back_depth * dx) * n;
        v -= std::max(v.dot(n), Real(0)) * n;
        pushed = true;
    }
    return pushed;
}

}  // namespace karst
