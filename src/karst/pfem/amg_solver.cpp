#include "karst/pfem/amg_solver.hpp"

#include "karst/core/check.hpp"
#include "karst/core/timer.hpp"

#include <HYPRE.h>
#include <HYPRE_parcsr_ls.h>
#include <mpi.h>

#include <cmath>
#include <cstdlib>
#include <mutex>
#include <stdexcept>
#include <string>

namespace karst {

namespace {

/// hypre is built on MPI: karst runs it as a single process (a singleton MPI job, no mpirun),
/// started on first use and finished at exit.
class HypreRuntime {
public:
    static void ensure() { static HypreRuntime runtime; }

private:
    HypreRuntime() {
        int ready = 0;
        MPI_Initialized(&ready);
        if (!ready) {
            // One process on one machine: only the loopback transport, so that Open MPI neither
            // probes network interfaces nor warns about missing high-speed hardware.
            setenv("OMPI_MCA_btl", "self", 0);
            setenv("OMPI_MCA_btl_base_warn_component_unused", "0", 0);
            MPI_Init(nullptr, nullptr);
            m_owns_mpi = true;
        }
        HYPRE_Init();
    }
    ~HypreRuntime() {
        HYPRE_Finalize();
        int finished = 0;
        MPI_Finalized(&finished);
        if (m_owns_mpi && !finished) MPI_Finalize();
    }
    bool m_owns_mpi = false;
};

void check(HYPRE_Int error, const char* what) {
    if (error) {
        HYPRE_ClearAllErrors();
        throw NumericalFailure(std::string("hypre: ") + what + " failed");
    }
}

}  // namespace

struct AmgSolver::Impl {
    int n = 0;
    AmgOptions options;
    HYPRE_IJMatrix ij_matrix = nullptr;
    HYPRE_ParCSRMatrix matrix = nullptr;
    HYPRE_IJVector ij_b = nullptr, ij_x = nullptr, ij_r = nullptr;
    HYPRE_ParVector b = nullptr, x = nullptr, r = nullptr;
    HYPRE_Solver amg = nullptr, pcg = nullptr;
    std::vector<HYPRE_Int> rows;  // 0 .. n-1, for setting and getting whole vectors
    Real t_setup = 0;

    Impl(const Eigen::SparseMatrix<Real, Eigen::ColMajor, int>& A, AmgOptions o)
        : n(int(A.rows())), options(std::move(o)) {
        HypreRuntime::ensure();
        Stopwatch watch;
        const MPI_Comm comm = MPI_COMM_WORLD;
        // A is symmetric, so its compressed columns are the compressed rows hypre takes.
        check(HYPRE_IJMatrixCreate(comm, 0, n - 1, 0, n - 1, &ij_matrix), "matrix create");
        check(HYPRE_IJMatrixSetObjectType(ij_matrix, HYPRE_PARCSR), "matrix type");
        std::vector<HYPRE_Int> sizes(n);
        rows.resize(n);
        for (int r = 0; r < n; ++r)
            sizes[r] = A.outerIndexPtr()[r + 1] - A.outerIndexPtr()[r], rows[r] = r;
        check(HYPRE_IJMatrixSetRowSizes(ij_matrix, sizes.data()), "row sizes");
        check(HYPRE_IJMatrixInitialize(ij_matrix), "matrix initialise");
        check(HYPRE_IJMatrixSetValues(ij_matrix, n, sizes.data(), rows.data(), A.innerIndexPtr(),
                                      A.valuePtr()),
              "matrix values");
        check(HYPRE_IJMatrixAssemble(ij_matrix), "matrix assemble");
        HYPRE_IJMatrixGetObject(ij_matrix, reinterpret_cast<void**>(&matrix));
        for (HYPRE_IJVector* v : {&ij_b, &ij_x, &ij_r}) {
            check(HYPRE_IJVectorCreate(comm, 0, n - 1, v), "vector create");
            HYPRE_IJVectorSetObjectType(*v, HYPRE_PARCSR);
            HYPRE_IJVectorInitialize(*v);
            HYPRE_IJVectorAssemble(*v);
        }
        HYPRE_IJVectorGetObject(ij_b, reinterpret_cast<void**>(&b));
        HYPRE_IJVectorGetObject(ij_x, reinterpret_cast<void**>(&x));
        HYPRE_IJVectorGetObject(ij_r, reinterpret_cast<void**>(&r));

        // One V-cycle of BoomerAMG per CG iteration, with the settings hypre recommends for
        // 3D problems: HMIS coarsening, extended+i interpolation truncated to 4 entries,
        // l1-scaled symmetric Gauss-Seidel smoothing (a symmetric preconditioner for CG).
        HYPRE_BoomerAMGCreate(&amg);
        HYPRE_BoomerAMGSetPrintLevel(amg, 0);
        HYPRE_BoomerAMGSetCoarsenType(amg, 10);
        HYPRE_BoomerAMGSetInterpType(amg, 6);
        HYPRE_BoomerAMGSetPMaxElmts(amg, 4);
        HYPRE_BoomerAMGSetAggNumLevels(amg, 1);
        HYPRE_BoomerAMGSetStrongThreshold(amg, 0.5);
        HYPRE_BoomerAMGSetRelaxType(amg, 8);
        HYPRE_BoomerAMGSetNumSweeps(amg, 1);
        HYPRE_BoomerAMGSetTol(amg, 0);
        HYPRE_BoomerAMGSetMaxIter(amg, 1);
        if (options.functions > 1) {
            HYPRE_BoomerAMGSetNumFunctions(amg, options.functions);
            // hypre frees the dof function array with the solver: give it its own copy.
            auto* functions = static_cast<HYPRE_Int*>(std::malloc(sizeof(HYPRE_Int) * size_t(n)));
            for (int r = 0; r < n; ++r) functions[r] = options.row_function[r];
            HYPRE_BoomerAMGSetDofFunc(amg, functions);
        }
        HYPRE_ParCSRPCGCreate(comm, &pcg);
        HYPRE_PCGSetTol(pcg, 0);  // absolute, set per solve from the warm start's residual
        HYPRE_PCGSetMaxIter(pcg, options.max_iterations);
        HYPRE_PCGSetTwoNorm(pcg, 1);
        HYPRE_PCGSetPrintLevel(pcg, 0);
        HYPRE_PCGSetPrecond(pcg, reinterpret_cast<HYPRE_PtrToSolverFcn>(HYPRE_BoomerAMGSolve),
                            reinterpret_cast<HYPRE_PtrToSolverFcn>(HYPRE_BoomerAMGSetup), amg);
        check(HYPRE_ParCSRPCGSetup(pcg, matrix, b, x), "AMG set-up");
        t_setup = watch.seconds();
    }

    ~Impl() {
        if (pcg) HYPRE_ParCSRPCGDestroy(pcg);
        if (amg) HYPRE_BoomerAMGDestroy(amg);
        if (ij_x) HYPRE_IJVectorDestroy(ij_x);
        if (ij_b) HYPRE_IJVectorDestroy(ij_b);
        if (ij_r) HYPRE_IJVectorDestroy(ij_r);
        if (ij_matrix) HYPRE_IJMatrixDestroy(ij_matrix);
    }

    int solve(const Eigen::VectorXd& rhs, Eigen::VectorXd& solution) {
        HYPRE_IJVectorSetValues(ij_b, n, rows.data(), rhs.data());
        HYPRE_IJVectorSetValues(ij_x, n, rows.data(), solution.data());
        // The stopping test is relative to the residual of the warm start, b - A x0: a later
        // solve of the staggered iteration, started from the previous iterate, then pays only
        // for the accuracy of its own correction.
        HYPRE_ParVectorCopy(b, r);
        HYPRE_ParCSRMatrixMatvec(-1.0, matrix, x, 1.0, r);
        HYPRE_Real start = 0, right_side = 0;
        HYPRE_ParVectorInnerProd(r, r, &start);
        HYPRE_ParVectorInnerProd(b, b, &right_side);
        const Real target = options.tolerance * std::sqrt(start);
        if (target <= 1e-14 * std::sqrt(right_side)) return 0;  // the warm start already solves it
        HYPRE_PCGSetAbsoluteTol(pcg, target);
        HYPRE_ParCSRPCGSolve(pcg, matrix, b, x);
        HYPRE_Int iterations = 0;
        HYPRE_Real residual = 0;
        HYPRE_PCGGetNumIterations(pcg, &iterations);
        HYPRE_PCGGetFinalRelativeResidualNorm(pcg, &residual);
        HYPRE_ClearAllErrors();  // "not converged" is judged below, on the residual
        if (!(residual * std::sqrt(right_side) <= target * (1 + 1e-9)))
            throw NumericalFailure("AMG-preconditioned CG did not converge: relative residual " +
                                   std::to_string(residual) + " after " +
                                   std::to_string(iterations) + " iterations");
        HYPRE_IJVectorGetValues(ij_x, n, rows.data(), solution.data());
        return iterations;
    }
};

AmgSolver::AmgSolver(const Eigen::SparseMatrix<Real, Eigen::ColMajor, int>& A, AmgOptions options)
    : m_impl(std::make_unique<Impl>(A, std::move(options))) {}
AmgSolver::~AmgSolver() = default;
AmgSolver::AmgSolver(AmgSolver&&) noexcept = default;
AmgSolver& AmgSolver::operator=(AmgSolver&&) noexcept = default;

int AmgSolver::solve(const Eigen::VectorXd& b, Eigen::VectorXd& x) {
    return m_impl->solve(b, x);
}
Real AmgSolver::seconds_setup() const {
    return m_impl->t_setup;
}

}  // namespace karst
