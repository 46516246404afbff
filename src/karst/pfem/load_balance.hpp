#pragma once
// Loads of unanchored pieces balanced against their rigid motions (docs/method.md §5.3). A piece
// of an anchored fragment that no fixed node holds (an island left by dissolution, a ledge
// anchored in the air) has a singular elasticity; eps diag(K) makes it invertible, but a net load
// f then moves it rigidly by about |f| / (eps K), kilometres. Its loads are balanced by the
// inertia of a rigid acceleration (inertia relief: a load f_a at node a less w_a (a + alpha x r_a),
// with a and alpha such that the net force and moment vanish, w_a spread as the weight is), so
// the anchor that holds the fragment takes the net force and moment and the piece deforms under
// the rest; its own weight then strains nothing. The solution's rigid part, which the weak spring
// leaves weighted by diag(K), is removed by a least-squares fit with every node alike (the
// particles of a structure weigh alike): the deformation moves neither the particles' centre of
// mass nor their mean turn (a free block rose by microns per call otherwise, potential energy
// that the run's account reported as gained). Nodes a held piece shares stay where it puts them.
#include "karst/pfem/biot.hpp"
#include "karst/pfem/sparse_linear.hpp"

#include <Eigen/Dense>

namespace karst {

class LoadBalance {
public:
    LoadBalance() = default;
    /// The free rigid modes of `problem.unheld_pieces` (of the whole mesh for a free body without
    /// pieces), on the free displacement rows of `dofs`. Pieces that share a node (a hinge) are
    /// balanced together. `relief_weight` spreads the relief over the nodes as the weight is
    /// spread (lumped volumes where the problem carries gravity).
    LoadBalance(const TetMesh& mesh, const BiotProblem& problem, const DofSplit& dofs,
                const Vector& relief_weight);
    /// Balances `rhs` (free displacement rows) by the modes' inertia: afterwards Q^T rhs = 0 (a
    /// hinge node's rows, a mode each, lose their loads).
    void apply(Vector& rhs) const;
    /// Removes from `u` (free displacement rows) each group's rigid motion, its least-squares fit
    /// with every node alike; motions that would move a node shared with a held piece are not
    /// among them.
    void remove_rigid_motion(Vector& u) const;

private:
    /// A group of pieces joined by shared nodes: its free rows, an orthonormal basis Q of its
    /// modes on them (each piece's, and a hinge node's rows alone) and the inertia relief
    /// W Q (Q^T W Q)^-1, W the rows' relief weights; without a basis (a group too big for a
    /// dense one) its loads are removed. `rigid` holds the group's rigid motions R as one body,
    /// `fit` = (R^T R)^-1 R^T.
    struct Group {
        std::vector<int> rows;
        Eigen::MatrixXd basis, relief;
        bool all_rows = false;
        Eigen::MatrixXd rigid, fit;
    };
    std::vector<Group> m_groups;
};

}  // namespace karst
