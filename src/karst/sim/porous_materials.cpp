#include "karst/sim/porous_materials.hpp"

#include "karst/porous/layering_frame.hpp"
#include "karst/porous/permeability.hpp"

#include <cmath>

namespace karst {

PoreWaterLaw pore_water_law(const PorousMaterial& mat, Real rest_density, const Vec3& gravity) {
    PoreWaterLaw law;
    law.rest_density = rest_density, law.capillary_scale = mat.capillary_pressure;
    law.capillary_exponent = mat.capillary_exponent, law.pore_stiffness = mat.pore_stiffness;
    law.tait_exponent = mat.pore_exponent;
    law.saturation_exponent = mat.saturation_exponent, law.darcy_viscosity = mat.darcy_viscosity;
    law.gravity = gravity;
    law.absorption_factor = mat.absorption_factor;
    return law;
}

std::vector<Mat3> body_permeabilities(const PorousMaterial& mat, const std::vector<Vec3>& rest_x,
                                      Real h) {
    using L = PorousMaterial::Layering;
    const Real k0 = mat.permeability, ratio = mat.layering_ratio;
    if (mat.layering == L::Fibre) {
        // k_par k_perp^2 = k0^3 with k_par = ratio k_perp.
        const Real k_perp = k0 * std::pow(ratio, -1.0 / 3.0);
        return std::vector<Mat3>(rest_x.size(),
                                 fibre_permeability(ratio * k_perp, k_perp, mat.layering_normal));
    }
    if (mat.layering == L::Bedding || ratio == 1)
        return std::vector<Mat3>(rest_x.size(),
                                 layered_permeability(k0, mat.layering_normal, ratio));
    const std::vector<PcaFrame> frames = pca_frames(rest_x, h);
    std::vector<Mat3> K(rest_x.size());
    for (size_t i = 0; i < rest_x.size(); ++i)
        K[i] = layered_permeability(
            k0, frames[i].reliable() ? frames[i].normal() : mat.layering_normal, ratio);
    return K;
}

PorousParticles porous_particles_at_rest(const Model& model, const PorousBody& body,
                                         Index fragment) {
    const PorousSolid& solid = model.scene.porous_solids[body.solid];
    const PorousMaterial& mat = solid.material;
    const Real V0 = model.dx * model.dx * model.dx;
    PorousParticles p;
    for (size_t i = 0; i < body.rest_x.size(); ++i) {
        const Vec3& x = body.rest_x[i];
        Real S = mat.initial_saturation;
        for (const WetRegion& w : solid.wet_regions)
            if (w.region.signed_distance(x) <= 0) S = w.saturation;
        p.x.push_back(x), p.v.push_back(Vec3::Zero()), p.volume.push_back(V0),
            p.porosity.push_back(mat.porosity);
        p.absorbed_mass.push_back(
            mat.porosity >= k_min_porosity ? S * model.rho0 * mat.porosity * V0 : 0);
        p.solid_mass.push_back(mat.solid_density * (1 - mat.porosity) * V0);
        p.permeability.push_back(body.body_permeability[i]),
            p.body_permeability.push_back(body.body_permeability[i]);
        p.fragment.push_back(fragment), p.material.push_back(body.solid),
            p.rest.push_back(Vec3::Zero());
        p.id.push_back(Index(i)), p.origin.push_back(Index(i));
    }
    return p;
}

}  // namespace karst
