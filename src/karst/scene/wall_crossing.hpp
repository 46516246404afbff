#pragma once
// A point that crossed a wall's surface (left a container's cavity, entered an obstacle) is put
// back inside: fluid particles after their step (sph/integrate.cpp) and the members of a
// deforming structure after a Biot call (pfem/structure_stages.cpp) alike.
#include "karst/scene/scene.hpp"

namespace karst {

/// How far a point pushed back through a wall lands inside its surface, in spacings: the
/// particle lattices start half a spacing inside, so a quarter keeps it clear of the wall skin.
inline constexpr Real k_push_back_depth = 0.25;

/// Puts x back a quarter spacing inside every wall it crossed and removes the outward normal
/// part of v (an inelastic contact, which cannot add energy). Returns whether it moved x.
bool push_back_through_walls(const std::vector<Wall>& walls, Real dx, Vec3& x, Vec3& v);

}  // namespace karst
