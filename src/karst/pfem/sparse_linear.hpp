#pragma once
// Sparse linear algebra of the Biot solver: free and prescribed unknowns, and symmetric positive
// definite systems solved by CHOLMOD or by AMG-preconditioned CG (spd_solve.cpp keeps CHOLMOD's
// headers to itself).
#include "karst/pfem/amg_solver.hpp"

#include <Eigen/SparseCore>

#include <algorithm>
#include <memory>
#include <utility>
#include <vector>

namespace karst {

using SparseMatrix = Eigen::SparseMatrix<Real, Eigen::ColMajor, int>;
using Vector = Eigen::VectorXd;
using Triplets = std::vector<Eigen::Triplet<Real, int>>;

/// Splits the unknowns into free and prescribed ones: free_index[i] is the row in the reduced
/// system, or -1 where the unknown is prescribed.
struct DofSplit {
    std::vector<int> free_index;
    int free_count = 0;
    explicit DofSplit(const std::vector<char>& prescribed) : free_index(prescribed.size(), -1) {
        for (size_t i = 0; i < prescribed.size(); ++i)
            if (!prescribed[i]) free_index[i] = free_count++;
    }
    /// A(free, free) and A(free, prescribed) of a square matrix.
    std::pair<SparseMatrix, SparseMatrix> split(const SparseMatrix& A) const {
        const int n = int(free_index.size());
        std::vector<int> prescribed_index(n, -1);
        int prescribed_count = 0;
        for (int i = 0; i < n; ++i)
            if (free_index[i] < 0) prescribed_index[i] = prescribed_count++;
        Triplets ff, fc;
        for (int col = 0; col < A.outerSize(); ++col)
            for (SparseMatrix::InnerIterator it(A, col); it; ++it) {
                const int r = free_index[it.row()];
                if (r < 0) continue;
                if (free_index[col] >= 0)
                    ff.emplace_back(r, free_index[col], it.value());
                else
                    fc.emplace_back(r, prescribed_index[col], it.value());
            }
        SparseMatrix Aff(free_count, free_count), Afc(free_count, prescribed_count);
        Aff.setFromTriplets(ff.begin(), ff.end());
        Afc.setFromTriplets(fc.begin(), fc.end());
        return {std::move(Aff), std::move(Afc)};
    }
    /// A(prescribed, prescribed) of a square matrix.
    SparseMatrix prescribed_block(const SparseMatrix& A) const {
        std::vector<int> prescribed_index(free_index.size(), -1);
        int prescribed_count = 0;
        for (size_t i = 0; i < free_index.size(); ++i)
            if (free_index[i] < 0) prescribed_index[i] = prescribed_count++;
        Triplets cc;
        for (int col = 0; col < A.outerSize(); ++col)
            for (SparseMatrix::InnerIterator it(A, col); it; ++it)
                if (prescribed_index[it.row()] >= 0 && prescribed_index[col] >= 0)
                    cc.emplace_back(prescribed_index[it.row()], prescribed_index[col], it.value());
        SparseMatrix Acc(prescribed_count, prescribed_count);
        Acc.setFromTriplets(cc.begin(), cc.end());
        return Acc;
    }
    Vector gather_free(const Vector& x) const {
        Vector out(free_count);
        for (size_t i = 0; i < free_index.size(); ++i)
            if (free_index[i] >= 0) out[free_index[i]] = x[Eigen::Index(i)];
        return out;
    }
    Vector gather_prescribed(const Vector& x) const {
        Vector out(Eigen::Index(free_index.size()) - free_count);
        int k = 0;
        for (size_t i = 0; i < free_index.size(); ++i)
            if (free_index[i] < 0) out[k++] = x[Eigen::Index(i)];
        return out;
    }
    void scatter_free(const Vector& reduced, Vector& x) const {
        for (size_t i = 0; i < free_index.size(); ++i)
            if (free_index[i] >= 0) x[Eigen::Index(i)] = reduced[free_index[i]];
    }
};

/// |next - previous| / max(|next|, floor) (or the absolute change when both are zero).
inline Real relative_change(const Vector& next, const Vector& previous, Real floor = 0) {
    const Real norm = std::max(next.norm(), floor);
    const Real change = (next - previous).norm();
    return norm > 0 ? change / norm : change;
}

/// A symmetric positive definite system solved by CHOLMOD (exact; one factorisation, cheap solves)
/// or by AMG-preconditioned conjugate gradients (warm-started from the previous iterate).
class SpdSolve {
public:
    SpdSolve();
    ~SpdSolve();
    SpdSolve(SpdSolve&&) noexcept;
    SpdSolve& operator=(SpdSolve&&) noexcept;
    /// Factorises or sets up A. CHOLMOD's pattern analysis is done once: every A given to one
    /// SpdSolve has the same pattern (the mesh's).
    void compute(const SparseMatrix& A, bool iterative, const AmgOptions& amg_options);
    /// Sets up A (stored in full) as a split of the direct `parent`'s matrix A_p without a new
    /// factorisation: A's row r is parent row `parent_row[r]` or a copy of it (nodes duplicated
    /// along a crack, each copy where its source was), so that Z^T A Z = A_p for the Z that
    /// copies each parent row's value into its copies. In the unknowns W = [Z, E] (E: the
    /// copies' jumps) A is [[A_p, B], [B^T, C]], and A_p's factor (shared: the root of a chain
    /// of splits) with the dense Schur complement C - B^T A_p^{-1} B on the jumps solves it
    /// exactly, at one solve with A_p's factor. That solve preconditions CG on A, which ends at
    /// once where Z^T A Z = A_p holds and factorises A afresh where CG does not converge.
    /// Returns false, leaving this solve unset, when A is no split (a parent row without a row)
    /// or the jumps' dense block A_p^{-1} B would hold over `max_memory_share` of the factor's
    /// entries: then compute() is the way.
    bool compute_split(const SparseMatrix& A, const SpdSolve& parent,
                       const std::vector<Index>& parent_row, Real max_memory_share);
    /// The jumps of a split (0 after compute()).
    Index split_unknowns() const;
    /// x = A^{-1} b; `guess` starts the iteration.
    Vector solve(const Vector& b, const Vector& guess);
    Index iterations = 0;  ///< CG iterations so far (iterative mode)

private:
    struct Direct;
    struct Split;
    bool m_iterative = false;
    std::shared_ptr<Direct> m_direct;  // shared with the splits of this matrix
    std::unique_ptr<Split> m_split;
    std::unique_ptr<AmgSolver> m_amg;
};

}  // namespace karst
