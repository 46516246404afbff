#pragma once
// Linear (P1) shape functions on one tetrahedron (docs/method.md §5.2): N_a are the barycentric
// coordinates, so their gradients are constant over the tet.
#include "karst/pfem/tet_mesh.hpp"

#include <Eigen/LU>

namespace karst {

struct P1Tet {
    Real volume = 0;             ///< m^3 (positive for a positively oriented tet)
    std::array<Vec3, 4> grad{};  ///< grad N_a, 1/m
};

inline P1Tet p1_tet(const TetMesh& mesh, Index e) {
    const Tet& t = mesh.tets[e];
    const Vec3& x0 = mesh.nodes[t[0]];
    Mat3 J;
    J.col(0) = mesh.nodes[t[1]] - x0, J.col(1) = mesh.nodes[t[2]] - x0,
    J.col(2) = mesh.nodes[t[3]] - x0;
    // x = x0 + J xi, so grad xi_k = row k of J^-1, and N_0 = 1 - xi_1 - xi_2 - xi_3.
    const Mat3 inverse = J.inverse();
    P1Tet p;
    p.volume = J.determinant() / 6;
    for (int k = 0; k < 3; ++k) p.grad[k + 1] = inverse.row(k).transpose();
    p.grad[0] = -(p.grad[1] + p.grad[2] + p.grad[3]);
    return p;
}

/// Small-strain tensor of a P1 displacement field on one tet.
inline Mat3 p1_strain(const P1Tet& p, const Tet& t, const std::vector<Vec3>& u) {
    Mat3 gradient = Mat3::Zero();  // (grad u)_ij = du_i/dx_j
    for (int a = 0; a < 4; ++a) gradient += u[t[a]] * p.grad[a].transpose();
    return 0.5 * (gradient + gradient.transpose());
}

}  // namespace karst
