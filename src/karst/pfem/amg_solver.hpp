#pragma once
// Conjugate gradients preconditioned by hypre's BoomerAMG (algebraic multigrid), for the
// symmetric positive definite systems of the Biot call (docs/method.md §5.3) when the mesh is too
// big or changes too often for a direct factorisation (see LinearSolver in biot.hpp). hypre types
// stay in amg_solver.cpp.
#include "karst/core/types.hpp"

#include <Eigen/SparseCore>

#include <memory>
#include <vector>

namespace karst {

struct AmgOptions {
    /// Unknown function of each row (0, 1, 2 for the x, y, z displacement of a node), so that
    /// coarsening and interpolation keep the components apart (systems AMG); empty for a scalar
    /// problem.
    std::vector<int> row_function;
    int functions = 1;
    Real tolerance = 1e-8;  ///< on the residual, relative to that of the warm start
    int max_iterations = 1000;
};

class AmgSolver {
public:
    /// Builds the multigrid hierarchy of the symmetric matrix A (both triangles stored).
    AmgSolver(const Eigen::SparseMatrix<Real, Eigen::ColMajor, int>& A, AmgOptions options);
    ~AmgSolver();
    AmgSolver(AmgSolver&&) noexcept;
    AmgSolver& operator=(AmgSolver&&) noexcept;

    /// Solves A x = b starting from x (a warm start); returns the iterations taken. Throws when
    /// the tolerance is not reached.
    int solve(const Eigen::VectorXd& b, Eigen::VectorXd& x);

    Real seconds_setup() const;

private:
    struct Impl;
    std::unique_ptr<Impl> m_impl;
};

}  // namespace karst
