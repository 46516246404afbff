#include "karst/porous/pore_flow.hpp"

#include "karst/core/parallel.hpp"
#include "karst/porous/anisotropic_kernel.hpp"
#include "karst/porous/permeability.hpp"

#include <cmath>

namespace karst {

PoreFlow::PoreFlow(const PoreWaterLaw& law, Real h, Real spacing)
    : m_law(law), m_h(h), m_spacing(spacing), m_calibration(pair_weight_calibration()) {}

void PoreFlow::refresh(const PorousParticles& p) {
    const Index n = p.size();
    m_G.resize(n), m_det_g.resize(n), m_kbar.resize(n), m_saturation.resize(n), m_potential.resize(n);
    m_outflow_scale.assign(n, 1);
    parallel_for(n, [&](Index i) {
        const KernelMetric metric = kernel_metric(p.permeability[i], m_h);
        m_G[i] = metric.G, m_det_g[i] = metric.det_g, m_kbar[i] = metric.k_ref;
        m_saturation[i] = p.porosity[i] >= k_min_porosity ? m_law.saturation(p.absorbed_mass[i], p.porosity[i], p.volume[i]) : 0;
        m_potential[i] = m_law.flow_potential(m_saturation[i], p.x[i]);
    });
}

Real PoreFlow::pair_conductance(const PorousParticles& p, Index lo, Index hi) const {
    if (p.porosity[lo] < k_min_porosity || p.porosity[hi] < k_min_porosity) return 0;  // impermeable (M3)
    const Vec3 x = p.x[lo] - p.x[hi];
    // Different fragments exchange water only in contact, so an open crack does not conduct.
    if (p.fragment[lo] != p.fragment[hi] && x.norm() >= 1.1 * m_spacing) return 0;
    // M16: the pair weight in the metric of both kernels, calibrated by c_eps.
    const Real F = 0.5 * (pair_weight(x, m_G[lo], m_det_g[lo]) + pair_weight(x, m_G[hi], m_det_g[hi])) * m_calibration;
    // M15: harmonic-mean permeability.
    const Real kpair = 2 * m_kbar[lo] * m_kbar[hi] / (m_kbar[lo] + m_kbar[hi]);
    return m_law.rest_density * p.volume[lo] * p.volume[hi] * kpair / (m_law.darcy_viscosity * m_h * m_h) * F;
}

Real PoreFlow::pair_flux(const PorousParticles& p, Index i, Index j) const {
    const Index lo = std::min(i, j), hi = std::max(i, j);
    const Real dphi = m_potential[hi] - m_potential[lo];
    if (dphi == 0) return 0;
    const Real conductance = pair_conductance(p, lo, hi);
    if (conductance == 0) return 0;
    // Relative permeability of the donor (larger Phi), upwinded.
    const Index donor = dphi > 0 ? hi : lo;
    const Real kr = std::pow(std::min(m_saturation[donor], Real(1)), m_law.saturation_exponent);
    const Real into_lo = conductance * kr * dphi * m_outflow_scale[donor];
    return i == lo ? into_lo : -into_lo;
}

void PoreFlow::rates(const PorousParticles& p, const NeighbourLists& neighbours, std::vector<Real>& rate) {
    refresh(p);
    rate.assign(p.size(), 0);
    parallel_for(p.size(), [&](Index i) {
        Real sum = 0;
        neighbours.for_each(i, [&](Index j) { sum += pair_flux(p, i, j); });
        rate[i] = sum;
    });
}

PoreFlowReport PoreFlow::advance(PorousParticles& p, const NeighbourLists& neighbours, Real dt) {
    PoreFlowReport report;
    const Index n = p.size();
    std::vector<Real> rate(n), outflow(n);
    Real remaining = dt;
    while (remaining > 0) {
        refresh(p);
        // Sub-step limit (§4.7.5): explicit diffusion is stable for dt sum_j c_ij dPhi_i/dm_i <= 1;
        // half of that, with k_r = 1 as its upper bound.
        const Real stiffness = parallel_max(n, Real(0), [&](Index i) {
            if (p.porosity[i] < k_min_porosity) return Real(0);
            Real sum = 0;
            neighbours.for_each(i, [&](Index j) { sum += pair_conductance(p, std::min(i, j), std::max(i, j)); });
            const Real dphi_dm = m_law.potential_slope(m_saturation[i]) / (m_law.rest_density * p.porosity[i] * p.volume[i]);
            return sum * dphi_dm;
        });
        const Real limit = stiffness > 0 ? 0.5 / stiffness : remaining;
        const Real steps = std::ceil(remaining / limit - 1e-12);
        const Real h_sub = remaining / std::max(Real(1), steps);

        // Donor limiter (Zalesak-style): a donor may not give more than it has this sub-step;
        // all its outgoing pair fluxes are scaled alike, and each stays antisymmetric.
        parallel_for(n, [&](Index i) {
            Real out = 0;
            neighbours.for_each(i, [&](Index j) { out += std::max(-pair_flux(p, i, j), Real(0)); });
            outflow[i] = out;
        });
        for (Index i = 0; i < n; ++i)
            if (outflow[i] * h_sub > p.absorbed_mass[i]) {
                m_outflow_scale[i] = p.absorbed_mass[i] / (outflow[i] * h_sub);
                ++report.limited_donors;
            }
        parallel_for(n, [&](Index i) {
            Real sum = 0;
            neighbours.for_each(i, [&](Index j) { sum += pair_flux(p, i, j); });
            rate[i] = sum;
        });
        for (Index i = 0; i < n; ++i) p.absorbed_mass[i] = std::max(p.absorbed_mass[i] + h_sub * rate[i], Real(0));
        remaining -= h_sub;
        if (remaining < 1e-12 * dt) remaining = 0;
        ++report.substeps;
    }
    return report;
}

}  // namespace karst
