#include "karst/porous/dissolution.hpp"

#include "karst/core/parallel.hpp"

#include <cmath>

namespace karst {

namespace {

/// Offsets of the pieces of a split particle: the corners of a cube of edge 0.1 dx, cycled.
Vec3 piece_offset(int piece, Real dx) {
    const Vec3 corner((piece & 1) ? 1 : -1, (piece & 2) ? 1 : -1, (piece & 4) ? 1 : -1);
    return (0.05 * dx) * corner * (1 + piece / 8);
}

}  // namespace

void mark_exposed(const PorousParticles& porous, const FluidParticles& fluid,
                  const NeighbourLists& porous_fluid, Real h, Real spacing,
                  std::vector<char>& exposed) {
    const Real touch = h * h, crowd = 0.36 * spacing * spacing;
    exposed.assign(porous.size(), 0);
    parallel_for(porous.size(), [&](Index k) {
        bool wet = false, crowded = false;
        porous_fluid.for_each(k, [&](Index i) {
            if (fluid.mass[i] == 0) return;
            const Real r2 = (fluid.x[i] - porous.x[k]).squaredNorm();
            wet = wet || r2 < touch, crowded = crowded || r2 < crowd;
        });
        exposed[k] = wet && !crowded;
    });
}

DissolutionReport dissolve(PorousParticles& porous, FluidParticles& fluid,
                           std::span<const PoreWaterLaw> laws, const DissolutionSettings& settings,
                           std::int64_t& next_id, const std::vector<char>& exposed) {
    DissolutionReport report;
    std::vector<char> keep(porous.size(), 1);
    for (Index i = 0; i < porous.size(); ++i) {
        if (!exposed.empty() && !exposed[i]) continue;
        const Real phi = porous.porosity[i];
        const PoreWaterLaw& law = laws[porous.material_of(i)];
        const DissolutionThreshold& threshold = settings.thresholds[porous.material_of(i)];
        if (phi < threshold.porosity) continue;
        if (law.saturation(porous.absorbed_mass[i], phi, porous.volume[i]) < threshold.saturation)
            continue;
        keep[i] = 0, ++report.dissolved;
        const Real m = porous.solid_mass[i] + porous.absorbed_mass[i],
                   solute = porous.solid_mass[i];
        const Real sph_mass = porous.absorbed_mass[i] +
                              solute * law.rest_density / threshold.grain_density;  // rho0 V
        const int pieces = m > 2 * settings.fluid_particle_mass
                               ? int(std::ceil(m / settings.fluid_particle_mass))
                               : 1;
        // Equal pieces, the last taking the rounding remainder, so the sums are exact.
        Real mass_left = m, solute_left = solute;
        for (int k = 0; k < pieces; ++k) {
            const bool last = k == pieces - 1;
            const Real mk = last ? mass_left : m / pieces,
                       sk = last ? solute_left : solute / pieces;
            mass_left -= mk, solute_left -= sk;
            const Index j = fluid.size();
            resize_attributes(fluid, size_t(j) + 1);  // every attribute, zero unless set here
            fluid.x[j] =
                porous.x[i] + (pieces > 1 ? piece_offset(k, settings.spacing) : Vec3::Zero());
            fluid.v[j] = porous.v[i];
            fluid.mass[j] = mk;
            fluid.sph_mass[j] = sph_mass * (mk / m);
            fluid.solute[j] = sk;
            fluid.rho[j] = law.rest_density;
            fluid.id[j] = next_id++;
            ++report.fluid_created;
        }
    }
    if (report.dissolved == 0) return report;
    keep_attributes(porous, keep);
    return report;
}

}  // namespace karst
