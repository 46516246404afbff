#include "karst/pfem/load_balance.hpp"

#include "karst/core/disjoint_sets.hpp"
#include "karst/pfem/rigid_modes.hpp"

#include <Eigen/QR>

#include <algorithm>
#include <numeric>
#include <tuple>

namespace karst {

namespace {

/// [D] A group whose dense basis would pass this many entries (a mesh shattered into thousands
/// of hinged pieces) has all its loads removed instead: it stays where its anchor holds it.
constexpr double k_max_basis_entries = 2e7;

/// One piece's free modes, row by row: (group row, the k modes' values there).
struct PieceModes {
    Eigen::Index first_column = 0, count = 0;
    std::vector<std::pair<int, Eigen::VectorXd>> values;
};

/// The rigid motions R of a group's nodes that leave their `held_axes` (FixedAxes bits) in
/// place, on the group's rows (`local`: free row -> group row, of `m`), and their least-squares
/// fit (R^T R)^-1 R^T: every node weighs alike, as the particles of a structure do.
std::pair<Eigen::MatrixXd, Eigen::MatrixXd> rigid_fit(const std::vector<Vec3>& nodes,
                                                      const std::vector<std::uint8_t>& held_axes,
                                                      const DofSplit& dofs,
                                                      const std::vector<Index>& group,
                                                      const std::vector<int>& local,
                                                      Eigen::Index m) {
    std::vector<Vec3> x;
    std::vector<std::uint8_t> held;
    for (Index a : group) x.push_back(nodes[a]), held.push_back(held_axes[a]);
    const Eigen::Matrix<Real, 6, Eigen::Dynamic> free = free_rigid_modes(x, held);
    if (free.cols() == 0) return {};
    const RigidFrame frame(x);
    Eigen::MatrixXd R = Eigen::MatrixXd::Zero(m, free.cols());
    for (size_t i = 0; i < group.size(); ++i)
        for (int d = 0; d < 3; ++d)
            if (const int row = dofs.free_index[3 * group[i] + d]; row >= 0 && local[row] >= 0)
                R.row(local[row]) = frame.row(x[i], d) * free;
    Eigen::MatrixXd fit =
        (R.transpose() * R).completeOrthogonalDecomposition().solve(R.transpose());
    return {std::move(R), std::move(fit)};
}

}  // namespace

LoadBalance::LoadBalance(const TetMesh& mesh, const BiotProblem& problem, const DofSplit& dofs,
                         const Vector& relief_weight) {
    const std::vector<Vec3>& nodes = mesh.nodes;
    const Index n = Index(nodes.size());
    std::vector<std::vector<Index>> whole;
    if (problem.free_body && problem.unheld_pieces.empty()) {
        whole.emplace_back(n);
        std::iota(whole[0].begin(), whole[0].end(), Index(0));
    }
    const std::vector<std::vector<Index>>& pieces = whole.empty() ? problem.unheld_pieces : whole;
    // Groups: the pieces joined where they share a node.
    DisjointSets groups(Index(pieces.size()));
    std::vector<Index> owner(n, -1);
    std::vector<int> pieces_at(n, 0);
    for (size_t k = 0; k < pieces.size(); ++k)
        for (Index a : pieces[k]) {
            ++pieces_at[a];
            if (owner[a] < 0) owner[a] = Index(k);
            groups.join(owner[a], Index(k));
        }
    const auto root = [&](Index k) { return groups.find(k); };

    std::vector<std::vector<int>> rows(pieces.size());
    std::vector<std::vector<PieceModes>> members(pieces.size());
    std::vector<Eigen::Index> columns(pieces.size(), 0);
    std::vector<int> local(dofs.free_index.size(), -1);
    const auto add_row = [&](Index g, int row) {
        if (local[row] < 0) local[row] = int(rows[g].size()), rows[g].push_back(row);
        return local[row];
    };
    for (size_t k = 0; k < pieces.size(); ++k) {
        std::vector<Vec3> x;
        std::vector<std::uint8_t> fixed;
        for (Index a : pieces[k]) x.push_back(nodes[a]), fixed.push_back(problem.fixed[a]);
        const Eigen::Matrix<Real, 6, Eigen::Dynamic> free = free_rigid_modes(x, fixed);
        if (free.cols() == 0) continue;
        const RigidFrame frame(x);
        const Index g = root(Index(k));
        PieceModes piece{columns[g], free.cols(), {}};
        columns[g] += free.cols();
        // A node shared with another piece (a hinge) follows neither piece's modes alone: its
        // rows get a column each below, so that the span holds the hinged motions.
        for (size_t i = 0; i < x.size(); ++i)
            for (int d = 0; d < 3; ++d)
                if (const int row = dofs.free_index[3 * pieces[k][i] + d];
                    row >= 0 && pieces_at[pieces[k][i]] == 1)
                    piece.values.emplace_back(add_row(g, row),
                                              (frame.row(x[i], d) * free).transpose());
        members[g].push_back(std::move(piece));
    }
    for (Index a = 0; a < n; ++a)
        for (int d = 0; d < 3 && pieces_at[a] > 1; ++d)
            if (const int row = dofs.free_index[3 * a + d]; row >= 0) {
                const Index g = root(owner[a]);
                members[g].push_back(
                    {columns[g]++, 1, {{add_row(g, row), Eigen::VectorXd::Ones(1)}}});
            }

    // Each group's nodes, once each (a hinge node is in several of its pieces), and the nodes
    // that a held piece shares with them (a tet with a node in no unheld piece is held): the
    // fitted motion leaves those where the held piece puts them.
    std::vector<std::vector<Index>> group_nodes(pieces.size());
    for (Index a = 0; a < n; ++a)
        if (pieces_at[a] > 0) group_nodes[root(owner[a])].push_back(a);
    std::vector<std::uint8_t> held = problem.fixed;
    for (const Tet& t : mesh.tets)
        if (std::any_of(t.begin(), t.end(), [&](Index a) { return pieces_at[a] == 0; }))
            for (Index a : t) held[a] = FixAll;

    for (size_t g = 0; g < pieces.size(); ++g) {
        if (rows[g].empty()) continue;
        Group out;
        const Eigen::Index m = Eigen::Index(rows[g].size());
        Eigen::VectorXd w = Eigen::VectorXd::Zero(m);  // the rows' relief weights
        for (Index a : group_nodes[g])
            for (int d = 0; d < 3; ++d)
                if (const int row = dofs.free_index[3 * a + d]; row >= 0 && local[row] >= 0)
                    w[local[row]] = relief_weight[a];
        std::tie(out.rigid, out.fit) = rigid_fit(nodes, held, dofs, group_nodes[g], local, m);
        out.rows = std::move(rows[g]);
        if (double(m) * double(columns[g]) > k_max_basis_entries) {
            out.all_rows = true;
        } else {
            Eigen::MatrixXd R = Eigen::MatrixXd::Zero(m, columns[g]);
            for (const PieceModes& piece : members[g])
                for (const auto& [at, v] : piece.values)
                    R.block(at, piece.first_column, 1, piece.count) = v.transpose();
            const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(R);
            out.basis = qr.householderQ() * Eigen::MatrixXd::Identity(m, qr.rank());
            const Eigen::MatrixXd WQ = w.asDiagonal() * out.basis;
            out.relief = WQ * (out.basis.transpose() * WQ).inverse();
        }
        m_groups.push_back(std::move(out));
    }
}

void LoadBalance::apply(Vector& rhs) const {
    for (const Group& g : m_groups) {
        if (g.all_rows) {
            for (int row : g.rows) rhs[row] = 0;
            continue;
        }
        Eigen::VectorXd v(g.rows.size());
        for (size_t i = 0; i < g.rows.size(); ++i) v[Eigen::Index(i)] = rhs[g.rows[i]];
        v -= g.relief * (g.basis.transpose() * v);
        for (size_t i = 0; i < g.rows.size(); ++i) rhs[g.rows[i]] = v[Eigen::Index(i)];
    }
}

void LoadBalance::remove_rigid_motion(Vector& u) const {
    for (const Group& g : m_groups) {
        if (g.rigid.cols() == 0) continue;
        Eigen::VectorXd v(g.rows.size());
        for (size_t i = 0; i < g.rows.size(); ++i) v[Eigen::Index(i)] = u[g.rows[i]];
        v -= g.rigid * (g.fit * v);
        for (size_t i = 0; i < g.rows.size(); ++i) u[g.rows[i]] = v[Eigen::Index(i)];
    }
}

}  // namespace karst
