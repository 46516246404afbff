#pragma once
// The surface checks of issue 14: closed, manifold, no self-intersection, no zero-area face.
#include "karst/surface/mesh_repair.hpp"

#include <gtest/gtest.h>

namespace karst::test {

inline void expect_clean(const SurfaceMesh& mesh) {
    const SurfaceCheck check = check_surface(mesh);
    EXPECT_TRUE(check.closed_manifold);
    EXPECT_EQ(check.self_intersections, 0);
    EXPECT_EQ(check.degenerate, 0);
}

}  // namespace karst::test
