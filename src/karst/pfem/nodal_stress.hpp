#pragma once
// Stresses at the nodes (docs/method.md §5.5): the element strains recovered at the nodes by a
// linear patch fit (nodal_stress.cpp says why), eps_v as the volume-weighted average.
#include "karst/pfem/biot.hpp"

namespace karst {

struct NodalStress {
    std::vector<Mat3> effective;            ///< sigma' = C : eps, Pa
    std::vector<Mat3> total;                ///< sigma = sigma' - B p I (Eq. 16), Pa
    std::vector<Vec3> principal;            ///< eigenvalues of sigma', largest first, Pa
    std::vector<Vec3> principal_direction;  ///< unit eigenvector of the largest (crack normal, M25)
    std::vector<Real> volumetric_strain;    ///< eps_v, volume-weighted (feeds M23)
    std::vector<Real> strain_energy;        ///< M26: U_a = 1/2 V_a sigma'_a : eps_a, J
};

NodalStress nodal_stress(const TetMesh& mesh, const BiotMaterial& material,
                         const BiotFields& fields);

}  // namespace karst
