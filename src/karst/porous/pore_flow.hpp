#pragma once
// Conservative pore-water transport between porous particles (method.md §4.7, M14-M16): one
// antisymmetric Darcy flux per pair in the metric of the anisotropic kernel, with the donor
// limiter and sub-steps of §4.7.5. Total pore water is conserved to round-off.
#include "karst/porous/pore_water.hpp"
#include "karst/sph/neighbour_grid.hpp"

namespace karst {

struct PoreFlowReport {
    int substeps = 0;
    Index limited_donors = 0;  ///< donors whose outflow the limiter scaled (summed over sub-steps)
};

/// Transport over dt. `neighbours` lists, for every particle, the particles within the largest
/// kernel reach (kernel_reach of M13); `h` is the isotropic support radius.
class PoreFlow {
public:
    /// `h` is the isotropic support radius, `spacing` the particle spacing dx.
    PoreFlow(const PoreWaterLaw& law, Real h, Real spacing);
    PoreFlowReport advance(PorousParticles& particles, const NeighbourLists& neighbours, Real dt);

    /// Net pore-water rate into each particle (kg/s) at the current state, for tests.
    void rates(const PorousParticles& particles, const NeighbourLists& neighbours, std::vector<Real>& rate);

private:
    /// Per particle: G (M13), det G, the reference permeability, S and Phi.
    void refresh(const PorousParticles& particles);
    /// rho0 V_lo V_hi kbar_pair F c_eps / (eta h^2) of M15/M16 (lo < hi), kg/(s Pa) without k_r;
    /// 0 for impermeable particles and for fragments not in contact.
    Real pair_conductance(const PorousParticles& particles, Index lo, Index hi) const;
    /// q_{j->i} of M15 with the pair's terms evaluated in (min, max) index order, so that the
    /// flux computed from either side is bitwise the same and mass is conserved exactly.
    Real pair_flux(const PorousParticles& particles, Index i, Index j) const;

    PoreWaterLaw m_law;
    Real m_h, m_spacing, m_calibration;
    std::vector<Mat3> m_G;
    std::vector<Real> m_det_g, m_kbar /* k_ref of KernelMetric */, m_saturation, m_potential, m_outflow_scale;
};

}  // namespace karst
