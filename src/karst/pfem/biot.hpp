#pragma once
// The Biot poroelastic problem on a fragment's tet mesh and its staggered solution
// (docs/method.md §5.3, M22): P1 tets, element matrices K, Q, H, lumped storage and volume, and the
// fixed-stress split (L = B^2 / K_dr) or, for comparison, the paper's fixed-strain order (L = 0).
#include "karst/pfem/tet_mesh.hpp"

#include <cstdint>
#include <limits>
#include <memory>

namespace karst {

struct BiotMaterial {
    Real youngs_modulus = 1e9;  ///< drained skeleton, Pa
    Real poisson_ratio = 0.25;
    Real biot_coefficient = 1;  ///< B = 1 - K_dr / K_s
    Real storage = 0;           ///< 1/M = phi/K_f + (B - phi)/K_s, 1/Pa
    Real fluid_density = 1000;  ///< rho0 of the gravity flux, kg/m^3
    Real bulk_density = 2000;   ///< rho_bulk of the body force, kg/m^3

    Real lame_lambda() const {
        return youngs_modulus * poisson_ratio / ((1 + poisson_ratio) * (1 - 2 * poisson_ratio));
    }
    Real shear_modulus() const { return youngs_modulus / (2 * (1 + poisson_ratio)); }
    Real drained_bulk_modulus() const { return lame_lambda() + 2 * shear_modulus() / 3; }
    /// K_s from B = 1 - K_dr / K_s (infinite for B = 1: incompressible grains).
    Real grain_bulk_modulus() const {
        return biot_coefficient < 1 ? drained_bulk_modulus() / (1 - biot_coefficient)
                                    : std::numeric_limits<Real>::infinity();
    }
    /// Kim et al.'s coupling strength tau = B^2 M / K_dr: the fixed-strain split needs tau < 1.
    Real coupling_strength() const {
        return biot_coefficient * biot_coefficient / (storage * drained_bulk_modulus());
    }
};

/// Displacement components fixed at a node, as bits.
enum FixedAxes : std::uint8_t { FixX = 1, FixY = 2, FixZ = 4, FixAll = 7 };

/// Everything a Biot call needs besides the fields. Arrays are per node unless said otherwise;
/// empty optional arrays mean "none" (zero).
struct BiotProblem {
    BiotMaterial material;
    std::vector<Mat3> mobility;          ///< per tet: k_r K / eta, m^2/(Pa s)
    std::vector<std::uint8_t> fixed;     ///< FixedAxes bits (u = prescribed_u there)
    std::vector<Vec3> prescribed_u;      ///< optional, m
    std::vector<char> drained;           ///< p prescribed (drained boundary)
    std::vector<Real> drained_pressure;  ///< optional, Pa
    std::vector<Vec3> nodal_force;       ///< optional external loads (tractions, fluid), N
    Vec3 gravity = Vec3::Zero();         ///< m/s^2
    /// Rigid frictionless platens: the nodes of each share one displacement component `axis`
    /// (their loads along it add up on that one unknown). Nodes held on the axis are not members.
    struct Platen {
        std::vector<Index> nodes;
        int axis = 2;
    };
    std::vector<Platen> platens;
    /// A fragment without anchors: add eps diag(K) to remove the six rigid modes (§5.3).
    bool free_body = false;
    /// The nodes of each piece (tets joined by faces) that some rigid motion leaves untouched by
    /// the fixed nodes (none: an island left by dissolution, an anchored ledge in the air). Its
    /// loads are balanced against those motions before each mechanics solve, so eps diag(K)
    /// holds it in place, as its anchored fragment is, instead of a net load moving it by
    /// |f| / (eps K). With free_body and no pieces, the whole mesh is one piece.
    std::vector<std::vector<Index>> unheld_pieces;
    Real rigid_mode_spring = 1e-8;
};

enum class Splitting { FixedStress, FixedStrain };

/// How the elasticity and flow systems are solved. CHOLMOD factorises once per mesh and then
/// solves cheaply; BoomerAMG sets up fast but each CG solve costs tens of iterations. The
/// elasticity changes only with the mesh, so it is factorised; the flow matrix changes with dt
/// and the mobility (every call under permeability feedback), so AMG wins for it on big meshes.
/// Auto (the default) factorises the elasticity and picks the flow solver by size
/// (BiotOptions::amg_flow_unknowns). Amg suits a mesh rebuilt at nearly every call, or one too
/// big for the elastic factor's memory. Figures: bench/results/notes.md.
enum class LinearSolver { Auto, Direct, Amg };

struct BiotOptions {
    Splitting splitting = Splitting::FixedStress;
    int max_iterations = 5;  ///< M22: k_max
    Real tolerance = 1e-3;   ///< M22 stopping test on relative changes of p and u
    /// Anderson acceleration of the fixed-stress pressure iterates over this many previous ones
    /// (0: the plain M22 iteration).
    int anderson_depth = 3;
    /// M21: EDT polyhedra with Laplace shape functions instead of P1 tets (docs/method.md §5.2).
    bool polyhedral = false;
    LinearSolver linear_solver = LinearSolver::Auto;
    Real amg_tolerance = 1e-8;  ///< CG residual, relative to that of its warm start
    /// Auto: the flow goes to AMG from this many free pressure unknowns (the crossover of a call
    /// that refactorises the flow, bench_pfem --edge).
    Index amg_flow_unknowns = 30000;
    /// [D] A split mesh's elasticity is solved through the older factor (BiotSplitOf) while the
    /// crack jumps' dense block takes at most this share of that factor's entries: past it a
    /// new factorisation is smaller, and its solves are cheaper.
    Real split_memory_share = 0.25;
};

struct BiotFields {
    std::vector<Vec3> u;  ///< m, body frame
    std::vector<Real> p;  ///< Pa
};

struct BiotCallReport {
    int iterations = 0;
    bool converged = false;
    std::vector<Real> p_change, u_change;  ///< relative change at each iteration
    Real seconds_flow_factorisation = 0, seconds_iterations = 0;
    Index linear_iterations = 0;  ///< CG iterations of the elastic and flow solves (AMG only)
    int elastic_solves = 0;       ///< predictor (when needed) and one per iteration
};

class BiotSolver;

/// The solver of a mesh that fracture made from another's by splitting nodes (M27), and per
/// node of the new mesh the node of the old one that it is or copies.
struct BiotSplitOf {
    const BiotSolver& solver;
    const std::vector<Index>& node_source;
};

/// Owns the assembled, Dirichlet-reduced matrices and their factorisations (CHOLMOD). The
/// elasticity matrix is factorised once per mesh (in the constructor); the flow matrix once per
/// call, since dt and the mobility may change.
class BiotSolver {
public:
    /// With `split_of`, the elasticity of a split mesh is solved through the old solver's factor
    /// (SpdSolve::compute_split) where it can be, instead of a new factorisation.
    BiotSolver(const TetMesh& mesh, BiotProblem problem, BiotOptions options = {},
               const BiotSplitOf* split_of = nullptr);
    ~BiotSolver();
    BiotSolver(BiotSolver&&) noexcept;
    BiotSolver& operator=(BiotSolver&&) noexcept;

    /// One Biot call over dt (backward Euler): fields hold u^n, p^n on entry (p^n seeded from SPH
    /// by the caller) and u^{n+1}, p^{n+1} on return.
    BiotCallReport advance(Real dt, BiotFields& fields);

    /// New per-tet mobility (M24 feedback); H is reassembled at the next call.
    void set_mobility(std::vector<Mat3> mobility);

    /// The step the flow matrix (S + L M + dt H) was last factorised for; calls whose dt is
    /// within 1e-9 of it reuse that step in the matrix. A solver rebuilt for a run in progress
    /// (a resume) is given it back, so that it factorises the matrix the run was using.
    Real flow_time_step() const;
    void set_flow_time_step(Real dt);

    /// Nodal loads (N, per node) added to the body force and the problem's own nodal_force from
    /// the next call on: the fluid's forces on a coupled fragment (docs/method.md §5.3).
    void set_extra_loads(const std::vector<Vec3>& loads);

    /// The rest state the mesh stands in at u = 0 (a coupled fragment under its own weight,
    /// structure_stages.cpp): its elastic forces K u_rest act against the loads from the next
    /// call on, so u is measured from it and the stress of u_rest + u is the full one.
    void set_rest_displacement(const std::vector<Vec3>& u_rest);

    /// The drained elastic displacement under constant nodal `loads` (N) with every prescribed
    /// component at zero (a rest state), balanced as a call's loads are on unheld pieces.
    std::vector<Vec3> drained_displacement(const std::vector<Vec3>& loads);

    /// Boundary values from the next call on (time tables, docs/method.md §5.3): nodal loads that
    /// replace the problem's nodal_force, and the values of the already prescribed displacement
    /// components and drained pressures (an empty array leaves those unchanged).
    void set_boundary_values(const std::vector<Vec3>& nodal_force,
                             const std::vector<Vec3>& prescribed_u,
                             const std::vector<Real>& drained_pressure);

    /// The force each support exerts on its node (N, body frame) in the equilibrium of `fields`
    /// under the last call's loads: K u - Q p - f_ext on the prescribed components, zero on the
    /// free ones. A moving platen's total is the sum over its nodes.
    std::vector<Vec3> support_forces(const BiotFields& fields) const;

    const BiotProblem& problem() const;
    Real seconds_assembly() const;
    Real seconds_elastic_factorisation() const;
    Index displacement_unknowns() const;
    /// The solver each system got (LinearSolver): true where BoomerAMG-CG, false where CHOLMOD.
    bool elastic_by_amg() const;
    /// The crack jumps through which the elasticity is solved on an older factor (0: its own).
    Index elastic_split_unknowns() const;
    bool flow_by_amg() const;

private:
    struct Impl;
    std::unique_ptr<Impl> m_impl;
};

/// Nodal forces of a uniform traction (Pa, world frame) on the boundary facets whose three nodes
/// all satisfy `on_region`: each facet gives area/3 times the traction to each of its nodes.
template <class Predicate>
std::vector<Vec3> traction_loads(const TetMesh& mesh, const Vec3& traction,
                                 const Predicate& on_region) {
    std::vector<Vec3> force(mesh.node_count(), Vec3::Zero());
    for (const Triangle& t : mesh.boundary) {
        if (!on_region(mesh.nodes[t[0]]) || !on_region(mesh.nodes[t[1]]) ||
            !on_region(mesh.nodes[t[2]]))
            continue;
        const Real area = mesh.area_vector(t).norm();
        for (Index a : t) force[a] += traction * (area / 3);
    }
    return force;
}

}  // namespace karst
