#pragma once
// Loads of unanchored pieces balanced against their rigid motions (docs/method.md §5.3). A piece
// of an anchored fragment that no fixed node holds (an island left by dissolution, a ledge
// anchored in the air) has a singular elasticity; eps diag(K) makes it invertible, but a net load
// f then moves it rigidly by about |f| / (eps K), kilometres. Removing from the mechanics' right
// side its part along the piece's free rigid modes lets the anchor that holds the fragment take
// the net force and moment, and leaves the deformation.
#include "karst/pfem/biot.hpp"
#include "karst/pfem/sparse_linear.hpp"

#include <Eigen/Dense>

namespace karst {

class LoadBalance {
public:
    LoadBalance() = default;
    /// The free rigid modes of `problem.unheld_pieces` (of the whole mesh for a free body without
    /// pieces), on the free displacement rows of `dofs`. Pieces that share a node (a hinge) are
    /// balanced together.
    LoadBalance(const std::vector<Vec3>& nodes, const BiotProblem& problem, const DofSplit& dofs);
    /// Removes from `rhs` (free displacement rows) its part along the modes.
    void apply(Vector& rhs) const;

private:
    /// A group of pieces joined by shared nodes: its free rows and an orthonormal basis of its
    /// modes on them; without a basis (a group too big for a dense one) its loads are removed.
    struct Group {
        std::vector<int> rows;
        Eigen::MatrixXd basis;
        bool all_rows = false;
    };
    std::vector<Group> m_groups;
};

}  // namespace karst
