// The surfaces of the shipped scenes as a run writes them (issue 14): every fluid and porous
// surface closed, manifold and free of self-intersections, while the water soaks, splashes and
// dissolves.
#include "support/files.hpp"
#include "support/simulate.hpp"
#include "support/surfaces.hpp"

#include "karst/surface/fluid_frame.hpp"
#include "karst/surface/porous_surface.hpp"

#include <gtest/gtest.h>

namespace karst {
namespace {

void check_scene(const std::string& file, std::vector<Real> times, bool anisotropic) {
    SCOPED_TRACE(file);
    test::Simulation sim(test::read_text(std::string(KARST_SOURCE_DIR) + "/scenes/" + file));
    sim.model.scene.output.anisotropic_surface = anisotropic;
    PorousSurfaces porous;
    for (Real t : times) {
        sim.run_until(t);
        const SurfaceMesh fluid = fluid_frame_surface(sim.model, sim.state.fluid);
        ASSERT_GT(fluid.triangle_count(), 100);
        {
            SCOPED_TRACE("fluid");
            test::expect_clean(fluid);
        }
        // The colour follows the concentration: clear water is the lightest (M29).
        for (Index v = 0; v < fluid.vertex_count(); ++v)
            ASSERT_EQ(fluid.colour[v], m29_colour(fluid.vertices.arrays[2].values[v], k_water_hue,
                                                  k_water_saturation));
        if (sim.state.porous.size() == 0) continue;
        const PorousParticles& p = sim.state.porous.particles;
        std::vector<Real> saturation(p.size());
        for (Index i = 0; i < p.size(); ++i)
            saturation[i] = p.absorbed_mass[i] / (sim.model.rho0 * p.porosity[i] * p.volume[i]);
        const SurfaceMesh rock = porous.build(sim.model, p, saturation);
        ASSERT_GT(rock.triangle_count(), 100);
        {
            SCOPED_TRACE("porous");
            test::expect_clean(rock);
        }
    }
}

TEST(SceneSurfaces, TheCaveWhileItSoaks) {
    check_scene("cave_soak.json", {0, 0.05}, false);
}

TEST(SceneSurfaces, TheDissolvingMoundWithAnisotropicKernels) {
    check_scene("dissolving_mound.json", {0, 0.05, 0.15, 0.3}, true);
}

TEST(SceneSurfaces, TheDamBreakAsItHitsTheObstacle) {
    check_scene("dam_break_obstacle.json", {0, 0.3}, false);
}

}  // namespace
}  // namespace karst
