#pragma once
// The fluid surface of a frame: the colour-field surface of the fluid particles with the vertex
// values a renderer and a compositor use (docs/method.md §7).
#include "karst/sim/model.hpp"
#include "karst/sim/state.hpp"
#include "karst/surface/surface_mesh.hpp"

#include <string>

namespace karst {

/// The fluid's surface at the scene's /output settings, with the vertex arrays normal, velocity
/// (for motion blur) and concentration (Shepard-interpolated, §7), and the M29 colour of the
/// concentration. With `level_set`, it also gets the level set's .vdb bytes.
SurfaceMesh fluid_frame_surface(const Model& model, const FluidParticles& fluid,
                                std::string* level_set = nullptr);

}  // namespace karst
