#pragma once
// Where a structure cracks (docs/method.md §5.5, M25-M26) and which element links a crack cuts
// (§5.6): pure functions of the mesh and its nodal stresses, so they can be tested alone.
#include "karst/pfem/nodal_stress.hpp"
#include "karst/pfem/structure_state.hpp"
#include "karst/scene/scene.hpp"

#include <functional>
#include <numbers>
#include <span>

namespace karst {

/// A crack disk in the mesh's frame (the rest positions).
struct Crack {
    Index node = 0;               ///< the mesh node it starts from
    Vec3 centre = Vec3::Zero();   ///< m
    Vec3 normal = Vec3::UnitZ();  ///< eigenvector of sigma'_1, or the shear plane's (M25)
    Real radius = 0;              ///< sqrt(area / pi), clamped to [0.5 dx, 3 dx] (M26), m
    Real area = 0;                ///< U_a / G_c before the clamp (M26), m^2
    Real stress_ratio = 0;        ///< the criterion's ratio (sigma'_1 / sigma_t for Rankine)
};

struct CrackSettings {
    CrackCriterion criterion = CrackCriterion::Rankine;
    Real tensile_strength = 1e5;  ///< sigma_t, Pa
    Real fracture_energy = 10;    ///< G_c, J/m^2
    Real spacing = 0.02;          ///< dx, m
    Real exclusion = 0.04;        ///< no two cracks of one call closer than this (h), m
    int max_cracks = 8;           ///< N_crack per call
    /// Weak bedding planes: per node the unit normal of the layering, and the tensile strength
    /// across the layers (a crack along a layer opens when n . sigma' n exceeds it). Empty: none.
    std::vector<Vec3> layer_normal;
    Real strength_across = 1e5;  ///< Pa
    Real poisson_ratio = 0.25;   ///< nu of the extension strain
    /// Per node: its strengths over the material's (wet weakening, fracture_stage.cpp). Empty: 1.
    std::vector<Real> strength_scale;
    /// Mohr-Coulomb shear failure beside the tensile test: the uniaxial compressive strength
    /// sigma_c (0: no shear test) and the friction angle phi.
    Real compressive_strength = 0;               ///< Pa
    Real friction_angle = std::numbers::pi / 6;  ///< rad
    Vec3 down = Vec3::Zero();  ///< unit direction of gravity in the mesh's frame (zero: none)
};

/// Mohr-Coulomb (M25, shear): with the effective principal stresses s (tension positive,
/// largest first), the shear stress on the weakest plane over the strength there,
/// [(s1 - s3) + (s1 + s3) sin phi] / [sigma_c (1 - sin phi)]: 1 at failure, reached by uniaxial
/// compression sigma_c and pure shear c cos phi; hydrostatic compression never reaches it.
Real mohr_coulomb_ratio(const Vec3& principal, Real compressive_strength, Real friction_angle);

/// The normal of the Mohr-Coulomb failure plane at stress sigma: in the plane of the least (e1)
/// and most (e3) compressive directions, at 45 - phi/2 degrees to e1 (the plane itself at
/// 45 + phi/2 to the plane e3 acts on). Of the two conjugate planes, the one whose outer wedge
/// slides down: e1 pointing along `outward` and the normal's e3 part against `down` (along
/// `outward` where gravity is zero or lies in the plane of e1 and e2). Where e1 is not unique
/// (s1 = s2), it is `outward` across e3.
Vec3 mohr_coulomb_normal(const Mat3& sigma, Real friction_angle, const Vec3& outward,
                         const Vec3& down);

/// O'Brien & Hodgins 1999 at each node a: the element forces f_e = -V_e sigma'_e grad N_a, split
/// by the tensile and compressive parts of sigma'_e (sigma'_e the mean of its nodes'), give
/// varsigma = 1/2 [sum m(f+_e) - sum m(f-_e)], m(f) = f f^T / |f|. [D] Their unbalanced terms
/// -m(f+) + m(f-) cancel at a node in equilibrium (f+ = -f-); in a static mesh they are left only
/// where loads or supports act, and there they made a surface under hydrostatic compression
/// crack, so they are left out. Returns per
/// node its largest eigenvalue over the value sigma_t gives it in a uniform uniaxial stress along
/// its eigenvector, sigma_t / 2 sum V_e |grad N_a . n| (so that uniaxial tension cracks at
/// sigma_t, as Rankine does), and that eigenvector.
std::vector<std::pair<Real, Vec3>> separation_tensor_ratios(const TetMesh& mesh,
                                                            const NodalStress& stress,
                                                            Real tensile_strength);

/// M25: nodes whose largest effective principal stress exceeds sigma_t (or, with weak layers,
/// whose normal stress across the layers exceeds the strength across them: a crack along the
/// layer, whichever ratio is larger). With CrackCriterion::ExtensionStrain (Stacey 1981), the
/// largest principal strain E eps_1 = sigma'_1 - nu (sigma'_2 + sigma'_3) takes the place of
/// sigma'_1 (and the strain across the layers that of the stress across them): the same in
/// uniaxial tension, but a bar in uniaxial compression splits along the load once nu times the
/// compression exceeds sigma_t, as brittle rock and soil do. With a compressive strength, a node
/// also cracks in shear (mohr_coulomb_ratio, its normal from mohr_coulomb_normal with `outward`
/// pointing from the mesh's centroid), whichever ratio is larger. Each node's ratios are divided
/// by its strength_scale. In decreasing ratio (ties by the node's particle id,
/// so the order of the particles does not matter), skipping nodes within `exclusion` of a crack
/// already taken and cracks for which `accept` (when given) is false, at most `max_cracks`.
std::vector<Crack> find_cracks(const TetMesh& mesh, const NodalStress& stress,
                               std::span<const Index> node_id, const CrackSettings& settings,
                               const std::function<bool(const Crack&)>& accept = {});

/// Per link: the centroids of its two tets and of the face they share, what links_cut reads, and
/// the larger squared distance from the face's centroid to the tets'.
struct LinkGeometry {
    Vec3 a, b, face;
    Real reach2 = 0;  ///< m^2
};
std::vector<LinkGeometry> link_geometry(const TetMesh& mesh, std::span<const ElementLink> links);

/// §5.6: per link, the first crack whose disk cuts the face the link stands for (-1: none): the
/// two centroids lie on opposite sides of the crack plane and the shared face's centroid within
/// the disk's radius of its axis.
std::vector<Index> links_cut(std::span<const LinkGeometry> links, std::span<const Crack> cracks);
inline std::vector<Index> links_cut(const TetMesh& mesh, std::span<const ElementLink> links,
                                    std::span<const Crack> cracks) {
    return links_cut(link_geometry(mesh, links), cracks);
}

}  // namespace karst
