#include "karst/pfem/nodal_stress.hpp"

#include "karst/pfem/p1_tet.hpp"

#include <Eigen/Eigenvalues>

namespace karst {

NodalStress nodal_stress(const TetMesh& mesh, const BiotMaterial& material,
                         const BiotFields& fields) {
    const Index n = mesh.node_count();
    const Real lambda = material.lame_lambda(), mu = material.shear_modulus();
    std::vector<Mat3> strain(n, Mat3::Zero());
    std::vector<Real> volume(n, 0);
    for (Index e = 0; e < mesh.tet_count(); ++e) {
        const P1Tet p = p1_tet(mesh, e);
        const Mat3 eps = p1_strain(p, mesh.tets[e], fields.u);
        for (Index a : mesh.tets[e]) strain[a] += p.volume * eps, volume[a] += p.volume;
    }
    NodalStress s;
    s.effective.resize(n), s.total.resize(n), s.principal.resize(n),
        s.principal_direction.resize(n);
    s.volumetric_strain.resize(n), s.strain_energy.resize(n);
    for (Index a = 0; a < n; ++a) {
        // Nodal strain first, then stress: for a linear material both orders agree.
        const Mat3 eps = volume[a] > 0 ? Mat3(strain[a] / volume[a]) : Mat3::Zero();
        const Real ev = eps.trace();
        const Mat3 sigma = lambda * ev * Mat3::Identity() + 2 * mu * eps;
        s.effective[a] = sigma;
        s.total[a] = sigma - material.biot_coefficient * fields.p[a] * Mat3::Identity();
        const Eigen::SelfAdjointEigenSolver<Mat3> eigen(sigma);  // ascending eigenvalues
        s.principal[a] = eigen.eigenvalues().reverse();
        s.principal_direction[a] = eigen.eigenvectors().col(2);
        s.volumetric_strain[a] = ev;
        s.strain_energy[a] = 0.5 * (volume[a] / 4) * (sigma.cwiseProduct(eps)).sum();
    }
    return s;
}

}  // namespace karst
