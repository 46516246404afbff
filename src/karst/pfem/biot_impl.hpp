#pragma once
// The Biot solver's assembled state (private to pfem/biot*.cpp): the matrices of the weak form
// (biot.cpp's header states it), the free/prescribed split and the linear solvers.
#include "karst/pfem/biot.hpp"
#include "karst/pfem/load_balance.hpp"
#include "karst/pfem/p1_tet.hpp"
#include "karst/pfem/polyhedral_elements.hpp"
#include "karst/pfem/sparse_linear.hpp"

namespace karst {

struct BiotSolver::Impl {
    const TetMesh mesh;  // a copy: the solver is a cache that outlives moves of the state's mesh
    BiotProblem problem;
    BiotOptions options;
    Index n = 0;
    std::vector<P1Tet> elements;
    std::vector<PolyhedralElement> polyhedra;  // M21 option only

    SparseMatrix K, Q, H;  // full matrices (3n x 3n, 3n x n, n x n)
    SparseMatrix mass;     // consistent P1 mass (n x n) of the fixed-stress term
    SparseMatrix mass_ff;
    Vector lumped_volume, storage;  // per node: M_a, S_a
    Vector gravity_flux;            // b
    Vector f_ext;                   // body force + nodal loads
    Vector f_body;                  // body force
    Vector f_problem;  // body force + the nodal loads of the boundary (the problem's at first)
    Vector f_extra;    // set_extra_loads
    Vector f_rest;     // K u_rest of set_rest_displacement (zero without one)
    Vector u_prescribed, p_prescribed;

    DofSplit u_dofs{{}}, p_dofs{{}};
    SparseMatrix K_ff, K_fc, H_ff, H_fc;
    SparseMatrix K_cc;    // prescribed rows and columns: with K_fc, the supports' reactions
    Vector elastic_lift;  // K_fc u_c
    // Rigid platens: free displacement rows = tie * (unknowns with each platen's members as one);
    // the elasticity solved is tie^T K_ff tie. Empty (0 columns) without platens.
    SparseMatrix tie;
    Vector last_elastic_rhs, last_elastic_u;  // the last mechanics solve: its right side and full u
    SpdSolve elastic, flow;                   // LinearSolver in biot.hpp says which each gets
    bool elastic_iterative = false, flow_iterative = false;
    bool mobility_changed = true;
    Real flow_dt = -1;
    Real t_assembly = 0, t_elastic_factor = 0;

    LoadBalance balance;  // the unheld pieces' loads against their rigid modes

    Impl(const TetMesh& m, BiotProblem p, BiotOptions o, const BiotSplitOf* split_of);
    /// K_ff set up through the factor of the solver it splits; false where it cannot be.
    bool split_elastic(const BiotSplitOf& split_of);
    /// Systems AMG over the free displacement rows: each row keeps its component.
    AmgOptions elastic_amg_options() const;
    /// P1 mechanics straight into compressed columns, in parallel over nodes (each node owns its
    /// three columns, so no two tasks write one entry): K_ff with the lift K_fc u_c, Q, the
    /// consistent mass, the lumped volume and the body force. With isotropic elasticity the 3 x 3
    /// block of nodes b, a in one tet is V [lambda g_b g_a^T + mu (g_a.g_b) I + mu g_a g_b^T].
    /// The sparsity pattern is built once, without triplets (bench/results/notes.md says why).
    void assemble_p1_mechanics();
    /// M21 elements: K_e = sum_q w B^T D B, Q_e[3a+c, b] = sum_q w B (dN_a/dx_c) N_b, lumped
    /// volume and body force sum_q w N_a. The fixed-stress term uses the lumped volume here.
    void assemble_polyhedral_mechanics();
    /// H of M21 elements and their gravity flux b into h_entries and gravity_flux.
    void assemble_polyhedral_flow(Triplets& h_entries, const Vec3& rho_g);
    /// H (P1 or M21) with the gravity flux b, and its free/prescribed split.
    void assemble_flow();
    /// Free and prescribed unknowns, with the prescribed values.
    void split_dofs();
    /// New nodal loads (replacing the problem's), prescribed displacements and drained pressures
    /// (empty: unchanged), and the lift K_fc u_c of the new displacements.
    void apply_boundary_values(const std::vector<Vec3>& nodal_force,
                               const std::vector<Vec3>& prescribed_u,
                               const std::vector<Real>& drained_pressure);
    /// (S + L M + dt H)_ff, factorised when dt or the mobility changed.
    void factorise_flow(Real dt, Real L);
    /// tie from the problem's platens.
    void tie_platens();
    /// K_ff u = rhs on the free rows (through the platen tie when there is one).
    Vector solve_elastic(const Vector& rhs, const Vector& guess);
    /// One call: the fixed-stress (or fixed-strain) iteration of M22.
    BiotCallReport advance(Real dt, BiotFields& fields);
};

}  // namespace karst
