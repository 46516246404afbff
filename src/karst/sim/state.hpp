#pragma once
// The mutable state (style.md P3/P4): fluid particles as one array per attribute, the time, and
// per-step derived data (neighbour lists, accelerations) kept apart from the physical state.
#include "karst/core/types.hpp"
#include "karst/pfem/structure_state.hpp"
#include "karst/porous/pore_flow.hpp"
#include "karst/porous/pore_water.hpp"
#include "karst/rigid/contact.hpp"
#include "karst/rigid/fragment.hpp"
#include "karst/sph/fluid_particles.hpp"
#include "karst/sph/neighbour_grid.hpp"

#include <limits>
#include <optional>
#include <vector>

namespace karst {

struct Model;

/// Per fluid particle i, its boundary pairs (walls and porous, coefficients c_ik and hydrostatic
/// terms h_ik of update_density_and_pair_coefficients) summed once per step: the pressure solves'
/// boundary terms are linear in p_i and v_i wherever no hydrostatic clamp acts, and then need no
/// pair loop.
struct BoundarySums {
    std::vector<Vec3> gradient;     ///< sum_k c_ik x_ik
    std::vector<Vec3> hydrostatic;  ///< sum_k c_ik h_ik x_ik
    std::vector<Real> lowest;       ///< min(min_k h_ik, 0), Pa: p_i + lowest >= 0 means no clamp
};

/// Data rebuilt every step from the physical state.
struct FluidScratch {
    CellRanges cells;                      ///< fluid particles sorted by cell
    NeighbourLists fluid_fluid;            ///< fluid neighbours (self excluded)
    NeighbourLists fluid_wall;             ///< wall neighbours
    std::vector<Vec3> a_other;             ///< (n) non-pressure acceleration incl. gravity, m/s^2
    std::vector<Vec3> a_pressure;          ///< (n) pressure acceleration, m/s^2
    std::vector<Vec3> normal;              ///< (n) Akinci 2013 surface normal, dimensionless
    std::vector<Vec3> x_pred;              ///< (n) PCISPH predicted position, m
    std::vector<Real> rho_err;             ///< (n) predicted density error, kg/m^3
    std::vector<Real> rho_boundary;        ///< (n) PCISPH: boundary density at x, kg/m^3
    std::vector<Vec3> v_pred;              ///< (n) DFSPH predicted velocity, m/s
    std::vector<Vec3> a_divergence;        ///< (n) DFSPH divergence-solve acceleration, m/s^2
    std::vector<Real> diagonal;            ///< (n) DFSPH -d rho*_i / d p_i, kg/m^3 per Pa
    std::vector<Real> delta;               ///< (n) PCISPH scaling factor delta_i, Pa m^3/kg
    std::vector<Real> pair_coefficient;    ///< per fluid pair (list layout): m_j / rho0^2 dW/dr / r
    std::vector<Real> wall_coefficient;    ///< per wall pair: Psi_k / rho0^2 dW/dr / r
    std::vector<Real> wall_hydrostatic;    ///< per wall pair: -rho0 g.x_ik, Pa
    NeighbourLists fluid_porous;           ///< porous neighbours within h (Akinci boundary, §4.1)
    std::vector<Real> porous_coefficient;  ///< per porous pair: Psi_k / rho0^2 dW/dr / r
    std::vector<Real> porous_hydrostatic;  ///< per porous pair: -rho0 g.x_ik, Pa
    BoundarySums boundary_sums;            ///< (n) the boundary pairs summed (walls and porous)
    std::vector<Vec3> porous_v_pred;       ///< per porous particle: its velocity in the solve, m/s
};

/// Porous particles and their fragments (docs/method.md §2, §4.5): the physical state.
struct PorousState {
    PorousParticles particles;
    std::vector<Fragment>
        fragments;            ///< indexed by PorousParticles::fragment; empty ones have mass 0
    Real absorbed = 0;        ///< net water taken from fluid particles so far, kg
    Index dissolved = 0;      ///< porous particles turned into muddy fluid (§4.8)
    Index fluid_deleted = 0;  ///< drained fluid particles deleted (§4.7.3)
    Index removed = 0;        ///< porous particles that left the domain
    Index pore_substeps = 0;  ///< pore-flow sub-steps taken (§4.7.5), summed over steps
    std::vector<CrackContact> crack_contacts;  ///< springs a crack left short (M27), sorted
    Index size() const { return particles.size(); }
};

/// Porous data rebuilt every step.
struct PorousScratch {
    CellRanges cells;              ///< porous particles in the SPH grid (cell h)
    NeighbourLists porous_porous;  ///< within h, self excluded
    NeighbourLists porous_fluid;   ///< fluid within h
    NeighbourLists porous_wall;    ///< wall particles within h
    std::vector<Real> psi;         ///< Psi_k = rho0 V_k of this step (§4.1), kg
    std::vector<Vec3> force;       ///< fluid reactions and contact forces of this step, N
    std::vector<char>
        exposed;         ///< per porous particle: a fluid particle lies within h (may dissolve)
    Index contacts = 0;  ///< touching pairs of this step
    /// Pore-flow pairs within each fragment (M15/M16). Rigid motion changes neither a pair's
    /// distance nor its weight in the rotating kernel metric, so they are built once and again
    /// only when the porous particles change (`pairs_stale`).
    PorePairs fragment_pairs;
    bool pairs_stale = true;
    std::optional<PoreFlow> flow;  ///< kept between steps for its buffers
};

struct State {
    FluidParticles fluid;
    FluidScratch scratch;
    PorousState porous;
    PorousScratch porous_scratch;
    StructureState structures;  ///< Algorithm 2's meshes and fields (docs/method.md §5)
    BiotCache biot_cache;       ///< their solvers, rebuilt on demand
    Real time = 0;              ///< s
    Index steps = 0;
    Real dt = 0;     ///< last step, s
    Real a_max = 0;  ///< largest acceleration of the last step, m/s^2
    /// Upper bound on the next step set by the pressure solve's convergence, s (infinite until a
    /// solve fails to converge; sph/integrate.hpp).
    Real dt_solver_limit = std::numeric_limits<Real>::infinity();
    Index removed = 0;  ///< particles that left the domain
    Index pushed_back =
        0;  ///< fluid particles put back inside a wall they crossed (sph/integrate.hpp)
    std::int64_t next_id = 0;  ///< the id of the next particle made, fluid or porous
};

/// Fluid at t = 0 from the model's sampled blocks; porous particles and their fragments at rest
/// (or with a free solid's initial velocity); the meshes and Biot problems of the anchored
/// fragments of permeable solids.
State make_initial_state(const Model& model);

}  // namespace karst
