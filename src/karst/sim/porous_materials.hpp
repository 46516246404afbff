#pragma once
// What a scene's porous material means for the pore water: its PoreWaterLaw (M3-M6) and the
// body-frame permeability tensors K0 of its particles (M12, or M28 for "from_geometry").
#include "karst/porous/pore_water.hpp"
#include "karst/scene/scene.hpp"
#include "karst/sim/model.hpp"

#include <vector>

namespace karst {

/// The pore-water law of a material, with the fluid's rest density and the scene's gravity.
PoreWaterLaw pore_water_law(const PorousMaterial& material, Real rest_density, const Vec3& gravity);

/// K0 per particle at rest positions `rest_x`: layered (bedding normal) or fibrous (fibre axis)
/// with the material's ratio and det K0 = k0^3; for "from_geometry" the bedding normal of each
/// particle is its neighbourhood's direction of least spread (weighted PCA, M28, support `h`),
/// falling back to the scene's normal where the neighbourhood is too sparse to tell.
std::vector<Mat3> body_permeabilities(const PorousMaterial& material,
                                      const std::vector<Vec3>& rest_x, Real h);

/// The particles of `body` at rest in fragment `fragment`: lattice volume dx^3, the material's
/// porosity and solid mass, pore water from its initial saturation and wet regions (none if
/// impermeable, M3), K0 as both body and world tensor, material = the scene solid. `rest`
/// (positions about the fragment centre) is left at zero for the caller.
PorousParticles porous_particles_at_rest(const Model& model, const PorousBody& body,
                                         Index fragment);

}  // namespace karst
