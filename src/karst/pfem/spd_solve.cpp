#include "karst/core/check.hpp"
#include "karst/pfem/sparse_linear.hpp"

#include <algorithm>

#include <Eigen/CholmodSupport>
#include <Eigen/Dense>

namespace karst {

struct SpdSolve::Direct {
    Eigen::CholmodSupernodalLLT<SparseMatrix> llt;
    bool analysed = false;
    Index rows = 0;
};

/// A split matrix A, solved by CG preconditioned by the split of the root factor
/// (compute_split).
struct SpdSolve::Split {
    SparseMatrix A;
    std::shared_ptr<Direct> root;       // the factor of the unsplit matrix
    std::vector<Index> root_row;        // per row: the root row it is or copies
    std::vector<Index> jump;            // per row: its index among the copies' jumps, or -1
    SparseMatrix B;                     // root rows x jumps: Z^T A E
    Eigen::MatrixXd X;                  // A_root^{-1} B
    Eigen::LLT<Eigen::MatrixXd> schur;  // C - B^T X

    Vector precondition(const Vector& b) const {
        const Index jumps = Index(X.cols());
        Vector g = Vector::Zero(root->rows), h(jumps);
        for (Index r = 0; r < Index(root_row.size()); ++r) {
            g[root_row[r]] += b[r];
            if (jump[r] >= 0) h[jump[r]] = b[r];
        }
        const Vector y0 = root->llt.solve(g);
        const Vector y_jump = schur.solve(h - B.transpose() * y0);
        const Vector y = y0 - X * y_jump;
        Vector x(Index(root_row.size()));
        for (Index r = 0; r < Index(root_row.size()); ++r)
            x[r] = y[root_row[r]] + (jump[r] >= 0 ? y_jump[jump[r]] : 0);
        return x;
    }
    /// x = A^{-1} b by preconditioned CG; false when it did not converge.
    bool solve(const Vector& b, Vector& x, Index& iterations) const;
};

SpdSolve::SpdSolve() = default;
SpdSolve::~SpdSolve() = default;
SpdSolve::SpdSolve(SpdSolve&&) noexcept = default;
SpdSolve& SpdSolve::operator=(SpdSolve&&) noexcept = default;

void SpdSolve::compute(const SparseMatrix& A, bool iterative, const AmgOptions& amg_options) {
    m_iterative = iterative;
    m_split.reset();
    if (iterative) {
        m_amg.reset();  // free the old hierarchy before building the next
        m_amg = std::make_unique<AmgSolver>(A, amg_options);
        return;
    }
    if (!m_direct) m_direct = std::make_shared<Direct>();
    if (!m_direct->analysed) m_direct->llt.analyzePattern(A), m_direct->analysed = true;
    m_direct->llt.factorize(A);
    m_direct->rows = Index(A.rows());
    if (m_direct->llt.info() != Eigen::Success)
        throw NumericalFailure(
            "the elasticity matrix is not positive definite (CHOLMOD's factorisation failed): a "
            "part of the solid has no support, or its material is degenerate");
}

namespace {

bool same_column(const SparseMatrix& a, Index i, const SparseMatrix& b, Index j) {
    SparseMatrix::InnerIterator x(a, i), y(b, j);
    for (; x && y; ++x, ++y)
        if (x.row() != y.row() || x.value() != y.value()) return false;
    return !x && !y;
}

}  // namespace

bool SpdSolve::compute_split(const SparseMatrix& A, const SpdSolve& parent,
                             const std::vector<Index>& parent_row, Real max_memory_share) {
    if (parent.m_iterative || !(parent.m_direct || parent.m_split)) return false;
    auto split = std::make_unique<Split>();
    split->root = parent.m_split ? parent.m_split->root : parent.m_direct;
    const Index roots = split->root->rows, rows = Index(A.rows()),
                parent_rows = parent.m_split ? Index(parent.m_split->root_row.size()) : roots;
    if (Index(parent_row.size()) != rows) return false;
    split->root_row.resize(size_t(rows));
    split->jump.assign(size_t(rows), -1);
    std::vector<char> taken(size_t(roots), 0);
    Index jumps = 0;
    for (Index r = 0; r < rows; ++r) {
        const Index p = parent_row[r];
        if (p < 0 || p >= parent_rows) return false;
        const Index root = parent.m_split ? parent.m_split->root_row[p] : p;
        split->root_row[r] = root;
        if (taken[root])
            split->jump[r] = jumps++;
        else
            taken[root] = 1;
    }
    if (std::find(taken.begin(), taken.end(), 0) != taken.end()) return false;
    const Real factor_entries = split->root->llt.cholmod().lnz;
    if (Real(jumps) * Real(roots) > max_memory_share * factor_entries) return false;

    Triplets b_entries;
    Eigen::MatrixXd C = Eigen::MatrixXd::Zero(jumps, jumps);
    for (Index col = 0; col < rows; ++col) {
        const Index k = split->jump[col];
        if (k < 0) continue;
        for (SparseMatrix::InnerIterator it(A, col); it; ++it) {
            b_entries.emplace_back(int(split->root_row[it.row()]), int(k), it.value());
            if (split->jump[it.row()] >= 0) C(split->jump[it.row()], k) += it.value();
        }
    }
    split->B.resize(roots, jumps);
    split->B.setFromTriplets(b_entries.begin(), b_entries.end());
    // X = A_root^{-1} B, solved for the jumps that are new or whose column changed: a jump the
    // parent split had already, with the same column of B, keeps its column of X.
    split->X.resize(roots, jumps);
    std::vector<Index> to_solve;
    for (Index r = 0; r < rows; ++r) {
        const Index k = split->jump[r];
        if (k < 0) continue;
        const Index before = parent.m_split ? parent.m_split->jump[parent_row[r]] : -1;
        if (before >= 0 && same_column(split->B, k, parent.m_split->B, before))
            split->X.col(k) = parent.m_split->X.col(before);
        else
            to_solve.push_back(k);
    }
    if (!to_solve.empty()) {
        Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(roots, Index(to_solve.size()));
        for (size_t j = 0; j < to_solve.size(); ++j) rhs.col(Index(j)) = split->B.col(to_solve[j]);
        const Eigen::MatrixXd solved = split->root->llt.solve(rhs);
        for (size_t j = 0; j < to_solve.size(); ++j)
            split->X.col(to_solve[j]) = solved.col(Index(j));
    }
    split->schur.compute(C - split->B.transpose() * split->X);
    if (split->schur.info() != Eigen::Success) return false;
    split->A = A;
    m_iterative = false;
    m_direct.reset();
    m_split = std::move(split);
    return true;
}

Index SpdSolve::split_unknowns() const {
    return m_split ? Index(m_split->X.cols()) : 0;
}

namespace {

/// [D] CG on a split stops at this residual relative to the right side: far below the Biot
/// iteration's tolerance, and above what the exact split attains in an ill-conditioned system.
constexpr Real k_split_tolerance = 1e-9;
/// [D] A split that CG has not solved in this many iterations is factorised afresh.
constexpr int k_split_max_iterations = 40;

}  // namespace

bool SpdSolve::Split::solve(const Vector& b, Vector& x, Index& iterations) const {
    const Real stop = k_split_tolerance * b.norm();
    x = precondition(b);
    Vector r = b - A * x;
    if (r.norm() <= stop) return true;
    Vector z = precondition(r), p = z;
    Real rz = r.dot(z);
    for (int k = 0; k < k_split_max_iterations; ++k) {
        ++iterations;
        const Vector Ap = A * p;
        const Real alpha = rz / p.dot(Ap);
        x += alpha * p, r -= alpha * Ap;
        if (r.norm() <= stop) return true;
        z = precondition(r);
        const Real rz_next = r.dot(z);
        p = z + (rz_next / rz) * p;
        rz = rz_next;
    }
    return false;
}

Vector SpdSolve::solve(const Vector& b, const Vector& guess) {
    if (m_split) {
        Vector x;
        if (m_split->solve(b, x, iterations)) return x;
        const SparseMatrix A = std::move(m_split->A);
        compute(A, false, {});
    }
    if (!m_iterative) return m_direct->llt.solve(b);
    Vector x = guess;
    iterations += m_amg->solve(b, x);
    return x;
}

}  // namespace karst
