// SpdSolve::compute_split: a matrix whose nodes were duplicated along a cut, solved through the
// factor of the uncut matrix, gives the solution of its own factorisation.
#include "karst/core/check.hpp"
#include "karst/pfem/sparse_linear.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace karst {
namespace {

// A grid of side x side nodes joined by springs, with a weak spring to the ground at every node:
// the scalar analogue of a P1 elasticity. Rows past side^2 are copies that cuts made.
struct SpringGrid {
    Index side = 0;
    std::vector<Real> stiffness;                     // per spring
    std::vector<std::pair<Index, Index>> edge_rows;  // per spring: the rows of its two ends
    std::vector<Index> source;                       // per row: the node it is or copies
    std::vector<Real> ground_share;                  // per row: its share of the ground spring

    explicit SpringGrid(Index n) : side(n) {
        std::mt19937 random(7);
        std::uniform_real_distribution<Real> k(0.5, 2.0);
        for (Index i = 0; i < n; ++i)
            for (Index j = 0; j < n; ++j) {
                if (i + 1 < n) edge_rows.push_back({i * n + j, (i + 1) * n + j});
                if (j + 1 < n) edge_rows.push_back({i * n + j, i * n + j + 1});
            }
        for (size_t e = 0; e < edge_rows.size(); ++e) stiffness.push_back(k(random));
        for (Index a = 0; a < n * n; ++a) source.push_back(a), ground_share.push_back(1);
    }
    Index column(Index row) const { return source[row] % side; }
    /// Scales every spring between two uncut rows (no copy at either end) by scale().
    template <class Scale>
    void scale_springs_off_copies(Scale scale) {
        for (size_t e = 0; e < edge_rows.size(); ++e)
            if (edge_rows[e].first < side * side && edge_rows[e].second < side * side)
                stiffness[e] *= scale();
    }
    /// Cuts between grid columns c and c + 1 over rows [i0, i1): the nodes of column c get a copy
    /// that takes their springs to the right.
    void cut(Index c, Index i0, Index i1) {
        const Index rows = Index(source.size());
        std::vector<Index> copy(size_t(rows), -1);
        for (Index r = 0; r < rows; ++r) {
            const Index i = source[r] / side;
            if (column(r) != c || i < i0 || i >= i1) continue;
            copy[r] = Index(source.size());
            source.push_back(source[r]), ground_share.push_back(ground_share[r] / 2);
            ground_share[r] /= 2;
        }
        for (auto& [a, b] : edge_rows) {
            if (copy[a] >= 0 && column(b) > c) a = copy[a];
            if (copy[b] >= 0 && column(a) > c) b = copy[b];
        }
    }
    SparseMatrix matrix() const {
        Triplets t;
        for (size_t e = 0; e < edge_rows.size(); ++e) {
            const auto [a, b] = edge_rows[e];
            const Real k = stiffness[e];
            t.emplace_back(int(a), int(a), k), t.emplace_back(int(b), int(b), k);
            t.emplace_back(int(a), int(b), -k), t.emplace_back(int(b), int(a), -k);
        }
        for (size_t r = 0; r < source.size(); ++r)
            t.emplace_back(int(r), int(r), 1e-3 * ground_share[r]);
        SparseMatrix A(Index(source.size()), Index(source.size()));
        A.setFromTriplets(t.begin(), t.end());
        return A;
    }
};

SpdSolve factorised(const SpringGrid& grid) {
    SpdSolve solve;
    solve.compute(grid.matrix(), false, {});
    return solve;
}

Vector load(Index rows) {
    Vector b(rows);
    for (Index r = 0; r < rows; ++r) b[r] = std::sin(Real(r)) + 0.5;
    return b;
}

Real solve_difference(SpdSolve& split, const SparseMatrix& A) {
    SpdSolve fresh;
    fresh.compute(A, false, {});
    const Vector b = load(A.rows());
    const Vector x = split.solve(b, Vector::Zero(A.rows()));
    const Vector y = fresh.solve(b, Vector::Zero(A.rows()));
    return (x - y).norm() / y.norm();
}

// Rows of the cut matrix as the parent rows they are or copy.
std::vector<Index> rows_in(const SpringGrid& now, const SpringGrid& before) {
    std::vector<Index> parent(now.source.size(), -1);
    for (size_t r = 0; r < now.source.size(); ++r)
        parent[r] = r < before.source.size() ? Index(r) : now.source[r];
    return parent;
}

TEST(SpdSplit, ACutMatrixSolvedThroughTheUncutFactorMatchesItsOwnFactorisation) {
    SpringGrid grid(30);
    const SpdSolve whole = factorised(grid);
    SpringGrid once = grid;
    once.cut(14, 5, 25);  // 20 nodes split: a crack inside the plate
    SpdSolve split;
    ASSERT_TRUE(split.compute_split(once.matrix(), whole, rows_in(once, grid), 100.0));
    EXPECT_EQ(split.split_unknowns(), 20);
    EXPECT_LT(solve_difference(split, once.matrix()), 1e-10);

    // The crack runs on: a split of the split, through the first factor still.
    SpringGrid twice = once;
    twice.cut(14, 0, 5);
    twice.cut(20, 10, 20);
    SpdSolve again;
    ASSERT_TRUE(again.compute_split(twice.matrix(), split, rows_in(twice, once), 100.0));
    EXPECT_EQ(again.split_unknowns(), 35);
    EXPECT_LT(solve_difference(again, twice.matrix()), 1e-10);
}

TEST(SpdSplit, ANearSplitIsSolvedByCgAndAFarOneByAFreshFactorisation) {
    SpringGrid grid(20);
    const SpdSolve whole = factorised(grid);
    SpringGrid cut = grid;
    cut.cut(9, 4, 16);  // a crack inside the plate
    // Springs away from the copies 10 % stiffer: Z^T A Z is no longer the factorised matrix,
    // and the split solve preconditions CG.
    SpringGrid moved = cut;
    moved.scale_springs_off_copies([] { return 1.1; });
    SpdSolve near;
    ASSERT_TRUE(near.compute_split(moved.matrix(), whole, rows_in(moved, grid), 100.0));
    EXPECT_LT(solve_difference(near, moved.matrix()), 1e-9);
    EXPECT_GT(near.iterations, 0);
    EXPECT_LT(near.iterations, 20);
    // Every spring off the copies changed by up to a factor 100 either way: CG gives up, and A
    // is factorised.
    SpringGrid far = cut;
    std::mt19937 random(3);
    std::uniform_real_distribution<Real> power(-2, 2);
    far.scale_springs_off_copies([&] { return std::pow(10.0, power(random)); });
    SpdSolve refactorised;
    ASSERT_TRUE(refactorised.compute_split(far.matrix(), whole, rows_in(far, grid), 100.0));
    EXPECT_LT(solve_difference(refactorised, far.matrix()), 1e-10);
    EXPECT_EQ(refactorised.split_unknowns(), 0) << "factorised afresh";
}

TEST(SpdSplit, AMatrixThatIsNoSplitOrTooBigASplitIsRefused) {
    SpringGrid grid(20);
    const SpdSolve whole = factorised(grid);
    SpringGrid cut = grid;
    cut.cut(9, 0, 20);  // cuts the plate in two
    SpdSolve split;
    std::vector<Index> lost = rows_in(cut, grid);
    lost[5] = 4;  // row 5 copies row 4, and parent row 5 is left without a row
    EXPECT_FALSE(split.compute_split(cut.matrix(), whole, lost, 100.0));
    EXPECT_FALSE(split.compute_split(cut.matrix(), whole, rows_in(cut, grid), 1e-6));
    EXPECT_TRUE(split.compute_split(cut.matrix(), whole, rows_in(cut, grid), 100.0));
    EXPECT_LT(solve_difference(split, cut.matrix()), 1e-10);
}

TEST(SpdSolve, AMatrixThatIsNotPositiveDefiniteIsANumericalFailure) {
    // A part of a solid without support, or an indefinite material, gives such a matrix: the
    // step reports it as a watchdog stop, not as a bug.
    std::vector<Eigen::Triplet<Real>> t{{0, 0, 1.0}, {0, 1, 2.0}, {1, 0, 2.0}, {1, 1, 1.0}};
    SparseMatrix A(2, 2);
    A.setFromTriplets(t.begin(), t.end());
    SpdSolve solve;
    EXPECT_THROW(solve.compute(A, false, {}), NumericalFailure);
}

}  // namespace
}  // namespace karst
