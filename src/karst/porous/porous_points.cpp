#include "karst/porous/porous_points.hpp"

#include "karst/core/parallel.hpp"
#include "karst/sph/kernels.hpp"

#include <cmath>

namespace karst {

PointSet porous_points(const PorousParticles& p, std::span<const PoreWaterLaw> laws,
                       const NeighbourLists& pairs, Real h) {
    const Index n = p.size();
    std::vector<Real> S(n), pore_pressure(n), potential(n);
    parallel_for(n, [&](Index i) {
        const PoreWaterLaw& law = laws[p.material_of(i)];
        S[i] = p.porosity[i] >= k_min_porosity
                   ? law.saturation(p.absorbed_mass[i], p.porosity[i], p.volume[i])
                   : 0;
        pore_pressure[i] = law.pore_pressure(S[i]);
        potential[i] = law.flow_potential(S[i], p.x[i]);
    });
    // M17: v_p = -(k_r K / (phi eta)) grad Phi, grad Phi = sum_j V_j (Phi_j - Phi_i) grad W_ij.
    const CubicKernel W(h);
    std::vector<Vec3> velocity(n, Vec3::Zero());
    parallel_for(n, [&](Index i) {
        if (p.porosity[i] < k_min_porosity) return;
        const PoreWaterLaw& law = laws[p.material_of(i)];
        Vec3 grad = Vec3::Zero();
        pairs.for_each(i, [&](Index j) {
            if (p.fragment[j] == p.fragment[i] && p.porosity[j] >= k_min_porosity)
                grad += p.volume[j] * (potential[j] - potential[i]) * W.gradient(p.x[i] - p.x[j]);
        });
        const Real kr = std::pow(std::min(S[i], Real(1)), law.saturation_exponent);
        velocity[i] = law.pore_velocity(kr, p.porosity[i], p.permeability[i], grad);
    });
    std::vector<std::int64_t> fragment(p.fragment.begin(), p.fragment.end());
    PointSet points;
    points.x = p.x;
    points.add_scalar("saturation", S);
    points.add_scalar("porosity", p.porosity);
    points.add_scalar("absorbed_mass", p.absorbed_mass);
    points.add_scalar("pore_pressure", pore_pressure);
    points.add_vector("pore_velocity", velocity);
    points.add_integer("fragment", fragment);
    points.add_vector("velocity", p.v);
    points.add_integer("id", std::vector<std::int64_t>(p.id.begin(), p.id.end()));
    points.add_symmetric_tensor("permeability", p.permeability);
    return points;
}

}  // namespace karst
