#pragma once
// Conservative pore-water transport (docs/method.md §4.7, M14-M16): one antisymmetric Darcy flux
// per pair in the metric of the anisotropic kernel, between porous particles and between porous and
// fluid particles (absorption and back-flow, §4.7.3), with the donor limiter and sub-steps of
// §4.7.5. Total water is conserved to round-off.
#include "karst/porous/pore_water.hpp"
#include "karst/sph/fluid_particles.hpp"
#include "karst/sph/neighbour_grid.hpp"

#include <span>

namespace karst {

/// Explicit pore-flow sub-steps allowed in one step: more means the pore water is so stiff
/// (pore_stiffness x mobility / h^2) that the run would crawl; it stops instead (issue 15).
inline constexpr Real k_max_pore_substeps = 1e4;

struct PoreFlowReport {
    int substeps = 0;
    /// Sub-steps the step would need when over k_max_pore_substeps (then nothing was advanced
    /// past the sub-steps already done); 0 otherwise.
    Real substeps_needed = 0;
    Index limited_donors = 0;  ///< donors whose outflow the limiter scaled (summed over sub-steps)
    Real absorbed = 0;         ///< net water from fluid into porous particles, kg
    /// Per fluid particle: the porous particle that received most of its water in this step (-1
    /// when none), for the deletion of drained particles. Empty without fluid.
    std::vector<Index> main_receiver;
};

/// The fluid particles taking part in the pore flow (§4.7.3): each is a pore-water donor or
/// receiver with S = 1 and Phi = max(p, 0) - rho0 g.x (M6, p the fluid's pressure()), volume m /
/// rho0. A donor's water goes into `drained` (the SPH mass stays until the particle is deleted);
/// water received first refills `drained`, then adds to the mass up to m_f0.
struct FluidExchange {
    FluidParticles& particles;           ///< mass, sph_mass and drained change
    const NeighbourLists& porous_fluid;  ///< per porous particle: its fluid partners
    Real full_mass = 0;                  ///< m_f0: no transfer fills a fluid particle beyond it, kg
};

/// Porous pairs that exchange pore water with their conductances rho0 V_i V_j (k/eta)_ij F_ij
/// c_eps / h^2 (M15/M16 without k_r), kg/(s Pa), in compressed rows: the partners of i are
/// other[start[i] .. start[i + 1]). Every pair is listed from both sides with the same value.
struct PorePairs {
    std::vector<Index> start{0};
    std::vector<Index> other;
    std::vector<Real> conductance;
    std::vector<Real> weight;   ///< F_ij of M16 (calibrated), 1/m^3, for the paper's Eq. 20
    std::vector<Real> row_sum;  ///< sum of each row's conductances, kg/(s Pa)
    Index rows() const { return Index(start.size()) - 1; }
};

/// The pair flux between porous particles: the Darcy flux M15 (default), or the paper's Eq. 20 in
/// the conservative form of docs/method.md §9 item 7, q_{j->i} = (d_ij / h) V_i V_j (m_pj / V_j -
/// m_pi / V_i) F_ij with d_ij = (|v_pi.r| S_i^beta + |v_pj.r| S_j^beta) / 2 and v_p from M17. The
/// latter diffuses m_p / V along the pore velocity: conservative and stable, but blind to
/// gravity and capillarity as drivers. Fluid-porous pairs use M15 in both.
enum class PairFlux { Darcy, PaperEq20 };

/// Which candidate pairs a PorePairs keeps.
enum class PairSelection { All, SameFragment, AcrossFragments };

/// Joins two pair sets over the same particles, row by row.
PorePairs merge_pairs(const PorePairs& a, const PorePairs& b);

/// Transport over dt. `neighbours` lists, for every porous particle, the porous particles
/// within the largest kernel reach (kernel_reach of M13); `h` is the isotropic support radius.
class PoreFlow {
public:
    /// `laws` per material (PorousParticles::material), `h` the isotropic support radius,
    /// `spacing` the particle spacing dx.
    PoreFlow(std::vector<PoreWaterLaw> laws, Real h, Real spacing, PairFlux flux = PairFlux::Darcy);
    PoreFlowReport advance(PorousParticles& particles, const NeighbourLists& neighbours, Real dt,
                           FluidExchange* fluid = nullptr);
    /// The same with the pairs built beforehand (pairs()), which stay valid while positions
    /// within a fragment, volumes, porosities and tensors (up to rotation) do not change.
    PoreFlowReport advance(PorousParticles& particles, const PorePairs& pairs, Real dt,
                           FluidExchange* fluid = nullptr);

    /// The candidate pairs with a non-zero conductance, `selection` of them.
    PorePairs pairs(const PorousParticles& particles, const NeighbourLists& candidates,
                    PairSelection selection = PairSelection::All);

    /// Net pore-water rate into each particle (kg/s) at the current state, for tests.
    void rates(const PorousParticles& particles, const NeighbourLists& neighbours,
               std::vector<Real>& rate);

private:
    const PoreWaterLaw& law(const PorousParticles& p, Index i) const {
        return m_laws[p.material_of(i)];
    }
    /// Per particle (those with partners in `only_with`, if given): G (M13), det G and the
    /// mobility k_ref / eta.
    void refresh_metric(const PorousParticles& particles,
                        const NeighbourLists* only_with = nullptr);
    /// Per particle: S (M3), Phi (M6) and k_r; limiter scales back to 1.
    void refresh_state(const PorousParticles& particles);
    /// rho0 V_lo V_hi (k/eta)_pair F / h^2 of M15 (lo < hi) for the pair weight F, kg/(s Pa)
    /// without k_r.
    Real pair_conductance(const PorousParticles& particles, Index lo, Index hi, Real weight) const;
    /// F_lo,hi of M16 in the metric of both kernels, calibrated (1/m^3); 0 for impermeable
    /// particles and for fragments not in contact.
    Real pair_weight_between(const PorousParticles& particles, Index lo, Index hi) const;
    /// Conductance of porous k with a fluid particle of volume m / rho0 at offset x (M15, fluid
    /// pair).
    Real fluid_conductance(const PorousParticles& particles, Index k, const Vec3& x, Real m) const;
    /// Each fluid pair's conductance in the slots of fluid.porous_fluid, and their sum per
    /// porous particle (for the sub-step limit).
    void cache_fluid_conductances(const PorousParticles& particles, const FluidExchange& fluid);
    /// q_{j->i} of M15 with the pair's terms evaluated in (min, max) index order, so that the
    /// flux computed from either side is bitwise the same and mass is conserved exactly.
    Real pair_flux(Index i, Index j, Real conductance) const;
    /// The paper's Eq. 20 (conservative form) for the pair in slot s of row i.
    Real paper_pair_flux(const PorousParticles& particles, const PorePairs& pairs, Index i,
                         Index s) const;
    /// M17 pore velocities of the listed rows (for the paper's Eq. 20).
    void pore_velocities(const PorousParticles& particles, const PorePairs& pairs,
                         const std::vector<Index>& rows);
    /// Calls f(q_{j->i}) for every partner j of i.
    template <class F>
    void for_each_pair(const PorousParticles& particles, const PorePairs& pairs, Index i,
                       const F& f) const;
    /// Flux into each porous particle from each listed fluid particle (kg/s), in the slots of
    /// fluid.porous_fluid, with the current limiter scales.
    void fluid_pair_fluxes(const PorousParticles& particles, const FluidExchange& fluid);

    std::vector<PoreWaterLaw> m_laws;
    Real m_h, m_spacing, m_calibration;
    PairFlux m_flux;
    std::vector<Vec3> m_pore_velocity;  ///< M17, m/s (paper's Eq. 20 only)
    std::vector<Mat3> m_G;
    std::vector<Real> m_det_g, m_mobility, m_saturation, m_potential, m_outflow_scale;
    std::vector<Real> m_relative_permeability;  ///< k_r = min(S, 1)^beta per particle
    std::vector<char> m_wet;                    ///< S > 1e-6 or touching fluid (empty: all)
    std::vector<Real> m_fluid_potential;        ///< per fluid particle, Pa
    std::vector<Real> m_fluid_donor_scale, m_fluid_receiver_scale;  ///< per fluid particle, limiter
    std::vector<Real> m_fluid_flux,
        m_fluid_transfer;                       ///< per porous-fluid slot: kg/s, kg this step
    std::vector<Real> m_fluid_conductance;      ///< per porous-fluid slot, kg/(s Pa)
    std::vector<Real> m_fluid_conductance_sum;  ///< per porous particle, kg/(s Pa)
};

}  // namespace karst
