#include "karst/surface/fluid_frame.hpp"

#include "karst/surface/fluid_surface.hpp"

namespace karst {

SurfaceMesh fluid_frame_surface(const Model& model, const FluidParticles& fluid,
                                std::string* level_set) {
    const OutputSettings& out = model.scene.output;
    std::vector<Real> volume(fluid.size());
    for (Index i = 0; i < fluid.size(); ++i) volume[i] = fluid.sph_mass[i] / model.rho0;
    FluidSurfaceOptions options;
    options.voxel = out.surface_voxel * model.dx;
    options.anisotropic = out.anisotropic_surface;
    SurfaceMesh mesh = colour_field_surface(fluid.x, volume, model.h, options, level_set);

    // Per-particle values, then Shepard sums over twice the support: an anisotropic surface may
    // lie beyond h of every particle.
    std::vector<std::vector<Real>> columns(4, std::vector<Real>(fluid.size()));
    for (Index i = 0; i < fluid.size(); ++i) {
        for (int d = 0; d < 3; ++d) columns[d][i] = fluid.v[i][d];
        columns[3][i] = fluid.solute[i] / fluid.mass[i];
    }
    const Real support = options.anisotropic ? 2 * model.h : model.h;
    const std::vector<std::vector<Real>> at =
        shepard_interpolate(mesh.vertices.x, fluid.x, volume, support, columns);
    std::vector<Vec3> velocity(mesh.vertex_count());
    for (Index v = 0; v < mesh.vertex_count(); ++v)
        velocity[v] = Vec3(at[0][v], at[1][v], at[2][v]);
    mesh.vertices.add_vector("velocity", velocity);
    mesh.vertices.add_scalar("concentration", at[3]);
    for (Real c : at[3]) mesh.colour.push_back(m29_colour(c, k_water_hue, k_water_saturation));
    return mesh;
}

}  // namespace karst
