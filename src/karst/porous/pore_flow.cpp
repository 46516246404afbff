#include "karst/porous/pore_flow.hpp"

#include "karst/core/check.hpp"
#include "karst/core/parallel.hpp"
#include "karst/porous/anisotropic_kernel.hpp"
#include "karst/porous/permeability.hpp"
#include "karst/sph/kernels.hpp"

#include <cmath>

namespace karst {

PoreFlow::PoreFlow(std::vector<PoreWaterLaw> laws, Real h, Real spacing, PairFlux flux)
    : m_laws(std::move(laws)),
      m_h(h),
      m_spacing(spacing),
      m_calibration(pair_weight_calibration()),
      m_flux(flux) {
    KARST_CHECK(!m_laws.empty());
}

void PoreFlow::refresh_metric(const PorousParticles& p, const NeighbourLists* only_with) {
    const Index n = p.size();
    m_G.resize(n), m_det_g.resize(n), m_mobility.resize(n);
    parallel_for(n, [&](Index i) {
        if (only_with && only_with->count[i] == 0) return;
        const KernelMetric metric = kernel_metric(p.permeability[i], m_h);
        m_G[i] = metric.G, m_det_g[i] = metric.det_g,
        m_mobility[i] = metric.k_ref / law(p, i).darcy_viscosity;
    });
}

void PoreFlow::refresh_state(const PorousParticles& p) {
    const Index n = p.size();
    m_saturation.resize(n), m_potential.resize(n), m_relative_permeability.resize(n);
    m_outflow_scale.assign(n, 1);
    parallel_for(n, [&](Index i) {
        const PoreWaterLaw& l = law(p, i);
        m_saturation[i] = p.porosity[i] >= k_min_porosity
                              ? l.saturation(p.absorbed_mass[i], p.porosity[i], p.volume[i])
                              : 0;
        m_potential[i] = l.flow_potential(m_saturation[i], p.x[i]);
        m_relative_permeability[i] =
            std::pow(std::min(m_saturation[i], Real(1)), l.saturation_exponent);
    });
}

Real PoreFlow::pair_weight_between(const PorousParticles& p, Index lo, Index hi) const {
    if (p.porosity[lo] < k_min_porosity || p.porosity[hi] < k_min_porosity)
        return 0;  // impermeable (M3)
    const Vec3 x = p.x[lo] - p.x[hi];
    // Different fragments exchange water only in contact, so an open crack does not conduct.
    if (p.fragment[lo] != p.fragment[hi] && x.norm() >= 1.1 * m_spacing) return 0;
    // M16: the pair weight in the metric of both kernels, calibrated by c_eps.
    return 0.5 * (pair_weight(x, m_G[lo], m_det_g[lo]) + pair_weight(x, m_G[hi], m_det_g[hi])) *
           m_calibration;
}

Real PoreFlow::pair_conductance(const PorousParticles& p, Index lo, Index hi, Real weight) const {
    // M15: harmonic mean of the mobilities k / eta (of the permeabilities for one material).
    const Real mobility = 2 * m_mobility[lo] * m_mobility[hi] / (m_mobility[lo] + m_mobility[hi]);
    return law(p, lo).rest_density * p.volume[lo] * p.volume[hi] * mobility / (m_h * m_h) * weight;
}

Real PoreFlow::fluid_conductance(const PorousParticles& p, Index k, const Vec3& x, Real m) const {
    if (p.porosity[k] < k_min_porosity) return 0;
    // M15/M16 for a fluid-porous pair: rho0 V_k (m / rho0) chi k_porous F(x, G_porous) / (eta h^2).
    const Real F = pair_weight(x, m_G[k], m_det_g[k]) * m_calibration;
    return p.volume[k] * m * law(p, k).absorption_factor * m_mobility[k] / (m_h * m_h) * F;
}

PorePairs PoreFlow::pairs(const PorousParticles& p, const NeighbourLists& candidates,
                          PairSelection selection) {
    refresh_metric(p);
    const Index n = p.size();
    const int cap = candidates.capacity;
    std::vector<Real> weight(size_t(n) * cap, 0);
    std::vector<Index> kept(n, 0);
    parallel_for(n, [&](Index i) {
        int s = 0;
        candidates.for_each(i, [&](Index j) {
            const bool same = p.fragment[i] == p.fragment[j];
            const bool wanted = selection == PairSelection::All ||
                                (selection == PairSelection::SameFragment) == same;
            // (min, max) order: both sides of a pair hold bitwise the same value.
            const Real w = wanted ? pair_weight_between(p, std::min(i, j), std::max(i, j)) : 0;
            weight[i * cap + s++] = w;
            kept[i] += w > 0;
        });
    });
    PorePairs out;
    out.start.assign(n + 1, 0);
    for (Index i = 0; i < n; ++i) out.start[i + 1] = out.start[i] + kept[i];
    out.other.resize(out.start[n]), out.conductance.resize(out.start[n]),
        out.weight.resize(out.start[n]);
    out.row_sum.resize(n);
    parallel_for(n, [&](Index i) {
        Index at = out.start[i];
        int s = 0;
        Real sum = 0;
        candidates.for_each(i, [&](Index j) {
            const Real w = weight[i * cap + s++];
            if (!(w > 0)) return;  // the count pass's test: a NaN weight is skipped by both
            const Real c = pair_conductance(p, std::min(i, j), std::max(i, j), w);
            out.other[at] = j, out.weight[at] = w, out.conductance[at++] = c, sum += c;
        });
        out.row_sum[i] = sum;
    });
    return out;
}

PorePairs merge_pairs(const PorePairs& a, const PorePairs& b) {
    PorePairs out;
    const Index n = a.rows();
    out.start.assign(n + 1, 0);
    for (Index i = 0; i < n; ++i)
        out.start[i + 1] =
            out.start[i] + (a.start[i + 1] - a.start[i]) + (b.start[i + 1] - b.start[i]);
    out.other.reserve(out.start[n]), out.conductance.reserve(out.start[n]),
        out.weight.reserve(out.start[n]);
    out.row_sum.resize(n);
    for (Index i = 0; i < n; ++i) {
        for (const PorePairs* set : {&a, &b})
            for (Index s = set->start[i]; s < set->start[i + 1]; ++s) {
                out.other.push_back(set->other[s]), out.conductance.push_back(set->conductance[s]);
                out.weight.push_back(set->weight[s]);
            }
        out.row_sum[i] = a.row_sum[i] + b.row_sum[i];
    }
    return out;
}

void PoreFlow::cache_fluid_conductances(const PorousParticles& p, const FluidExchange& fluid) {
    const Index n = p.size();
    const int cap = fluid.porous_fluid.capacity;
    m_fluid_conductance.resize(size_t(n) * cap);
    m_fluid_conductance_sum.resize(n);
    parallel_for(n, [&](Index i) {
        Real sum = 0;
        int s = 0;
        fluid.porous_fluid.for_each(i, [&](Index f) {
            const Real c =
                fluid_conductance(p, i, fluid.particles.x[f] - p.x[i], fluid.particles.sph_mass[f]);
            m_fluid_conductance[i * cap + s++] = c;
            sum += c;
        });
        m_fluid_conductance_sum[i] = sum;
    });
}

Real PoreFlow::pair_flux(Index i, Index j, Real conductance) const {
    const Index lo = std::min(i, j), hi = std::max(i, j);
    const Real dphi = m_potential[hi] - m_potential[lo];
    if (dphi == 0 || conductance == 0) return 0;
    // Relative permeability of the donor (larger Phi), upwinded.
    const Index donor = dphi > 0 ? hi : lo;
    const Real into_lo =
        conductance * m_relative_permeability[donor] * dphi * m_outflow_scale[donor];
    return i == lo ? into_lo : -into_lo;
}

void PoreFlow::fluid_pair_fluxes(const PorousParticles& p, const FluidExchange& fluid) {
    const NeighbourLists& lists = fluid.porous_fluid;
    const int cap = lists.capacity;
    m_fluid_flux.resize(size_t(p.size()) * cap);
    parallel_for(p.size(), [&](Index k) {
        const Real* c = m_fluid_conductance.data() + k * cap;
        Real* flux = m_fluid_flux.data() + k * cap;
        int s = 0;
        lists.for_each(k, [&](Index f) {
            const Real dphi = m_fluid_potential[f] - m_potential[k];
            Real q = 0;
            if (c[s] > 0 && dphi != 0) {
                if (dphi > 0)
                    q = c[s] * dphi * m_fluid_donor_scale[f];  // the fluid gives, k_r = 1 (S = 1)
                else  // the porous particle gives back, k_r of its own S, to a fluid receiver
                    q = c[s] * m_relative_permeability[k] * dphi * m_outflow_scale[k] *
                        m_fluid_receiver_scale[f];
            }
            flux[s++] = q;
        });
    });
}

Real PoreFlow::paper_pair_flux(const PorousParticles& p, const PorePairs& pairs, Index i,
                               Index s) const {
    const Index j = pairs.other[s];
    const Index lo = std::min(i, j), hi = std::max(i, j);
    const Vec3 x = p.x[lo] - p.x[hi];
    const Vec3 r = x / x.norm();
    // d_ij = (|v_pi.r| S_i^beta + |v_pj.r| S_j^beta) / 2 >= 0 (docs/method.md §9 item 7), in (lo,
    // hi) order so both sides agree bitwise.
    const Real d = 0.5 * (std::abs(m_pore_velocity[lo].dot(r)) * m_relative_permeability[lo] +
                          std::abs(m_pore_velocity[hi].dot(r)) * m_relative_permeability[hi]);
    const Real into_lo = d / m_h * p.volume[lo] * p.volume[hi] *
                         (p.absorbed_mass[hi] / p.volume[hi] - p.absorbed_mass[lo] / p.volume[lo]) *
                         pairs.weight[s];
    const Index donor = into_lo > 0 ? hi : lo;
    const Real q = into_lo * m_outflow_scale[donor];
    return i == lo ? q : -q;
}

void PoreFlow::pore_velocities(const PorousParticles& p, const PorePairs& pairs,
                               const std::vector<Index>& rows) {
    // M17: v_p = -(k_r K / (phi eta)) grad Phi, grad Phi = sum_j V_j (Phi_j - Phi_i) grad W_ij.
    const CubicKernel W(m_h);
    m_pore_velocity.assign(p.size(), Vec3::Zero());
    parallel_for(Index(rows.size()), [&](Index r) {
        const Index i = rows[r];
        if (p.porosity[i] < k_min_porosity) return;
        Vec3 grad = Vec3::Zero();
        for (Index s = pairs.start[i]; s < pairs.start[i + 1]; ++s) {
            const Index j = pairs.other[s];
            if (p.fragment[j] == p.fragment[i])
                grad +=
                    p.volume[j] * (m_potential[j] - m_potential[i]) * W.gradient(p.x[i] - p.x[j]);
        }
        m_pore_velocity[i] = law(p, i).pore_velocity(m_relative_permeability[i], p.porosity[i],
                                                     p.permeability[i], grad);
    });
}

template <class F>
void PoreFlow::for_each_pair(const PorousParticles& p, const PorePairs& pairs, Index i,
                             const F& f) const {
    for (Index s = pairs.start[i]; s < pairs.start[i + 1]; ++s) {
        const Index j = pairs.other[s];
        if (!(m_wet.empty() || m_wet[i] || m_wet[j])) continue;
        f(m_flux == PairFlux::PaperEq20 ? paper_pair_flux(p, pairs, i, s)
                                        : pair_flux(i, j, pairs.conductance[s]));
    }
}

void PoreFlow::rates(const PorousParticles& p, const NeighbourLists& neighbours,
                     std::vector<Real>& rate) {
    const PorePairs pair_set = pairs(p, neighbours);
    refresh_state(p);
    m_wet.clear();
    rate.assign(p.size(), 0);
    parallel_for(p.size(), [&](Index i) {
        Real sum = 0;
        for_each_pair(p, pair_set, i, [&](Real q) { sum += q; });
        rate[i] = sum;
    });
}

PoreFlowReport PoreFlow::advance(PorousParticles& p, const NeighbourLists& neighbours, Real dt,
                                 FluidExchange* fluid) {
    return advance(p, pairs(p, neighbours), dt, fluid);
}

PoreFlowReport PoreFlow::advance(PorousParticles& p, const PorePairs& neighbours, Real dt,
                                 FluidExchange* fluid) {
    PoreFlowReport report;
    const Index n = p.size();
    const Index nf = fluid ? fluid->particles.size() : 0;
    const int cap = fluid ? fluid->porous_fluid.capacity : 0;
    auto for_each_fluid_pair =
        [&](const auto& f) {  // serial, in (porous, slot) order: deterministic
            if (!fluid) return;
            for (Index k = 0; k < n; ++k)
                for (int s = 0; s < fluid->porous_fluid.count[k]; ++s)
                    f(k, Index(fluid->porous_fluid.index[k * cap + s]), size_t(k * cap + s));
        };
    // Positions, tensors and volumes hold for the whole step: the pair conductances are
    // computed once, and each sub-step only re-reads S and Phi. The kernel metric is needed
    // only where fluid partners are (the porous pairs came with their conductances).
    m_fluid_conductance_sum.assign(n, 0);
    if (fluid) {
        refresh_metric(p, &fluid->porous_fluid);
        cache_fluid_conductances(p, *fluid);
        // Phi_f = max(p, 0) - rho0 g.x (M6); the fluid pressure is this step's and stays fixed.
        m_fluid_potential.resize(nf);
        const PoreWaterLaw& l = m_laws[0];
        parallel_for(nf, [&](Index f) {
            m_fluid_potential[f] = std::max(fluid->particles.pressure(f), Real(0)) -
                                   l.rest_density * l.gravity.dot(fluid->particles.x[f]);
        });
        m_fluid_transfer.assign(size_t(n) * cap, 0);
    }
    std::vector<Real> rate(n), outflow(n), fluid_out(nf), fluid_in(nf);
    Real remaining = dt;
    std::vector<char> active(n);
    std::vector<Index> rows;
    while (remaining > 0) {
        refresh_state(p);
        m_fluid_donor_scale.assign(nf, 1), m_fluid_receiver_scale.assign(nf, 1);
        // Pairs of which neither particle is wet (S > 1e-6) nor touches fluid carry nothing: the
        // explicit scheme spreads traces a kernel reach per sub-step, which would otherwise wake
        // the whole block. Both sides of a pair apply the same test, so water is still conserved
        // exactly; only the rows of wet particles and their partners are visited.
        m_wet.resize(n);
        std::fill(active.begin(), active.end(), 0);
        for (Index i = 0; i < n; ++i)
            m_wet[i] = m_saturation[i] > 1e-6 || (fluid && fluid->porous_fluid.count[i] > 0);
        for (Index i = 0; i < n; ++i) {
            if (!m_wet[i]) continue;
            active[i] = 1;
            for (Index s = neighbours.start[i]; s < neighbours.start[i + 1]; ++s)
                active[neighbours.other[s]] = 1;
        }
        rows.clear();
        for (Index i = 0; i < n; ++i)
            if (active[i]) rows.push_back(i);
        const Index nr = Index(rows.size());
        if (m_flux == PairFlux::PaperEq20) pore_velocities(p, neighbours, rows);
        // Sub-step limit (§4.7.5): explicit diffusion is stable for dt sum_j c_ij dPhi_i/dm_i <= 1;
        // half of that, with k_r = 1 as its upper bound. A fluid particle's Phi does not depend on
        // its mass, so only porous particles limit the step.
        const Real stiffness = parallel_max(nr, Real(0), [&](Index r) {
            const Index i = rows[r];
            if (p.porosity[i] < k_min_porosity) return Real(0);
            const PoreWaterLaw& l = law(p, i);
            const Real dphi_dm =
                l.potential_slope(m_saturation[i]) / (l.rest_density * p.porosity[i] * p.volume[i]);
            if (m_flux == PairFlux::Darcy)
                return (neighbours.row_sum[i] + m_fluid_conductance_sum[i]) * dphi_dm;
            // Eq. 20 diffuses m_p / V: stable for dt sum_j (d_ij / h) V_j F_ij <= 1, with
            // d_ij <= (|v_pi| + |v_pj|) / 2; fluid pairs as for M15.
            Real sum = 0;
            for (Index s = neighbours.start[i]; s < neighbours.start[i + 1]; ++s) {
                const Index j = neighbours.other[s];
                sum += 0.5 * (m_pore_velocity[i].norm() + m_pore_velocity[j].norm()) / m_h *
                       p.volume[j] * neighbours.weight[s];
            }
            return sum + m_fluid_conductance_sum[i] * dphi_dm;
        });
        const Real limit = stiffness > 0 ? 0.5 / stiffness : remaining;
        const Real steps = std::ceil(remaining / limit - 1e-12);
        if (report.substeps + steps > k_max_pore_substeps) {
            report.substeps_needed = report.substeps + steps;
            return report;
        }
        const Real h_sub = remaining / std::max(Real(1), steps);

        // Donor limiter (Zalesak-style): a donor may not give more than it has this sub-step, and
        // a fluid receiver may not fill beyond m_f0; all of a limited particle's outgoing (or
        // incoming) pair fluxes are scaled alike, and each stays antisymmetric.
        // One pass gives each particle's outflow and its unlimited net rate; the rates are
        // summed again only when some donor or receiver was limited.
        if (fluid) fluid_pair_fluxes(p, *fluid);
        auto sum_rates = [&](bool with_outflow) {
            parallel_for(nr, [&](Index r) {
                const Index i = rows[r];
                Real out = 0, sum = 0;
                for_each_pair(p, neighbours, i,
                              [&](Real q) { sum += q, out += std::max(-q, Real(0)); });
                if (fluid)
                    for (int s = 0; s < fluid->porous_fluid.count[i]; ++s) {
                        const Real q = m_fluid_flux[i * cap + s];
                        sum += q, out += std::max(-q, Real(0));
                    }
                rate[i] = sum;
                if (with_outflow) outflow[i] = out;
            });
        };
        std::fill(rate.begin(), rate.end(), 0), std::fill(outflow.begin(), outflow.end(), 0);
        sum_rates(true);
        std::fill(fluid_out.begin(), fluid_out.end(), 0),
            std::fill(fluid_in.begin(), fluid_in.end(), 0);
        for_each_fluid_pair([&](Index, Index f, size_t slot) {
            const Real q = m_fluid_flux[slot];
            (q > 0 ? fluid_out[f] : fluid_in[f]) += std::abs(q);
        });
        bool limited = false, fluid_limited = false;
        for (Index i = 0; i < n; ++i)
            if (outflow[i] * h_sub > p.absorbed_mass[i]) {
                m_outflow_scale[i] = p.absorbed_mass[i] / (outflow[i] * h_sub);
                ++report.limited_donors, limited = true;
            }
        if (fluid) {
            for (Index f = 0; f < nf; ++f) {
                const Real mass = fluid->particles.mass[f], drained = fluid->particles.drained[f];
                const Real water = mass - fluid->particles.solute[f] - drained;
                const Real room = std::max(fluid->full_mass - mass + drained, Real(0));
                if (fluid_out[f] * h_sub > water) {
                    m_fluid_donor_scale[f] = std::max(water, Real(0)) / (fluid_out[f] * h_sub);
                    ++report.limited_donors, fluid_limited = true;
                }
                if (fluid_in[f] * h_sub > room)
                    m_fluid_receiver_scale[f] = room / (fluid_in[f] * h_sub), fluid_limited = true;
            }
            if (limited || fluid_limited) fluid_pair_fluxes(p, *fluid);  // again, with the scales
        }
        if (limited || fluid_limited) sum_rates(false);
        for (Index i = 0; i < n; ++i)
            p.absorbed_mass[i] = std::max(p.absorbed_mass[i] + h_sub * rate[i], Real(0));
        for_each_fluid_pair([&](Index, Index f, size_t slot) {
            const Real dm = h_sub * m_fluid_flux[slot];  // into the porous particle
            Real& drained = fluid->particles.drained[f];
            drained += dm;
            if (drained < 0)
                fluid->particles.mass[f] -= drained, fluid->particles.sph_mass[f] -= drained,
                    drained = 0;  // back-flow beyond what it gave
            m_fluid_transfer[slot] += dm;
            report.absorbed += dm;
        });
        remaining -= h_sub;
        if (remaining < 1e-12 * dt) remaining = 0;
        ++report.substeps;
    }
    if (fluid) {
        // The porous particle that received most of each fluid particle's water (§4.7.3).
        report.main_receiver.assign(nf, -1);
        std::vector<Real> most(nf, 0);
        for_each_fluid_pair([&](Index k, Index f, size_t slot) {
            if (m_fluid_transfer[slot] > most[f])
                most[f] = m_fluid_transfer[slot], report.main_receiver[f] = k;
        });
    }
    return report;
}

}  // namespace karst
