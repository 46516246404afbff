#include "karst/pfem/cracks.hpp"

#include "karst/pfem/face_links.hpp"
#include "karst/pfem/p1_tet.hpp"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace karst {

namespace {

/// Centroid of the face two linked tets share: the mean of the nodes they have in common.
Vec3 shared_face_centroid(const TetMesh& mesh, const ElementLink& link) {
    const SharedNodes shared = shared_nodes(mesh, link);
    Vec3 sum = Vec3::Zero();
    for (Index n : shared) sum += mesh.nodes[n];
    return sum / std::max(shared.count, 1);
}

}  // namespace

std::vector<std::pair<Real, Vec3>> separation_tensor_ratios(const TetMesh& mesh,
                                                            const NodalStress& stress,
                                                            Real tensile_strength) {
    const Index n = mesh.node_count();
    std::vector<Mat3> varsigma(n, Mat3::Zero());
    auto m = [](const Vec3& f) -> Mat3 {
        const Real length = f.norm();
        return length > 0 ? Mat3(f * f.transpose() / length) : Mat3::Zero();
    };
    std::vector<P1Tet> elements(mesh.tet_count());
    for (Index e = 0; e < mesh.tet_count(); ++e) {
        const Tet& t = mesh.tets[e];
        elements[e] = p1_tet(mesh, e);
        const Mat3 sigma = 0.25 * (stress.effective[t[0]] + stress.effective[t[1]] +
                                   stress.effective[t[2]] + stress.effective[t[3]]);
        const Eigen::SelfAdjointEigenSolver<Mat3> eigen(sigma);
        const Vec3 lambda = eigen.eigenvalues();
        const Mat3& V = eigen.eigenvectors();
        const Mat3 tensile = V * lambda.cwiseMax(0).asDiagonal() * V.transpose();
        const Mat3 compressive = sigma - tensile;
        for (int k = 0; k < 4; ++k) {
            const Vec3 g = elements[e].volume * elements[e].grad[k];
            varsigma[t[k]] += 0.5 * (m(tensile * g) - m(compressive * g));
        }
    }
    std::vector<std::pair<Real, Vec3>> result(n, {0.0, Vec3::UnitZ()});
    std::vector<Real> capacity(n, 0);
    for (Index a = 0; a < n; ++a) {
        const Eigen::SelfAdjointEigenSolver<Mat3> eigen(varsigma[a]);
        result[a] = {eigen.eigenvalues()[2], eigen.eigenvectors().col(2)};
    }
    for (Index e = 0; e < mesh.tet_count(); ++e)
        for (int k = 0; k < 4; ++k) {
            const Index a = mesh.tets[e][k];
            capacity[a] += 0.5 * tensile_strength * elements[e].volume *
                           std::abs(elements[e].grad[k].dot(result[a].second));
        }
    for (Index a = 0; a < n; ++a)
        result[a].first = capacity[a] > 0 ? result[a].first / capacity[a] : 0;
    return result;
}

Real mohr_coulomb_ratio(const Vec3& s, Real compressive_strength, Real friction_angle) {
    const Real sine = std::sin(friction_angle);
    return ((s[0] - s[2]) + (s[0] + s[2]) * sine) / (compressive_strength * (1 - sine));
}

Vec3 mohr_coulomb_normal(const Mat3& sigma, Real friction_angle, const Vec3& outward,
                         const Vec3& down) {
    const Eigen::SelfAdjointEigenSolver<Mat3> eigen(sigma);  // eigenvalues ascending
    const Vec3& lambda = eigen.eigenvalues();
    Vec3 least = eigen.eigenvectors().col(2), most = eigen.eigenvectors().col(0);
    // With the two least compressive stresses equal (a column under its weight), any direction
    // across the load is e1: take the one pointing out.
    const Vec3 across = outward - outward.dot(most) * most;
    if (lambda[2] - lambda[1] <= 1e-6 * (lambda[2] - lambda[0]) && across.norm() > 0)
        least = across.normalized();
    if (least.dot(outward) < 0) least = -least;
    const bool by_gravity = std::abs(most.dot(down)) > 1e-3;
    if (by_gravity ? most.dot(down) > 0 : most.dot(outward) < 0) most = -most;
    const Real theta = std::numbers::pi / 4 - friction_angle / 2;
    return std::cos(theta) * least + std::sin(theta) * most;
}

std::vector<Crack> find_cracks(const TetMesh& mesh, const NodalStress& stress,
                               std::span<const Index> node_id, const CrackSettings& settings,
                               const std::function<bool(const Crack&)>& accept) {
    std::vector<Crack> candidates;
    const bool separation = settings.criterion == CrackCriterion::SeparationTensor;
    const std::vector<std::pair<Real, Vec3>> separation_test =
        separation ? separation_tensor_ratios(mesh, stress, settings.tensile_strength)
                   : std::vector<std::pair<Real, Vec3>>{};
    const bool strain = settings.criterion == CrackCriterion::ExtensionStrain;
    const Real nu = settings.poisson_ratio;
    const bool shear = settings.compressive_strength > 0;
    Vec3 centroid = Vec3::Zero();
    if (shear) {
        for (const Vec3& x : mesh.nodes) centroid += x;
        centroid /= Real(std::max<Index>(mesh.node_count(), 1));
    }
    for (Index a = 0; a < mesh.node_count(); ++a) {
        const Vec3& s = stress.principal[a];
        const Real first = strain ? s[0] - nu * (s[1] + s[2]) : s[0];  // E eps_1 or sigma'_1
        Real ratio = separation ? separation_test[a].first : first / settings.tensile_strength;
        Vec3 n = separation ? separation_test[a].second
                            : Vec3(stress.principal_direction[a].normalized());
        if (!settings.layer_normal.empty()) {
            const Vec3& m = settings.layer_normal[a];
            const Real normal = m.dot(stress.effective[a] * m);
            const Real across =
                (strain ? normal - nu * (stress.effective[a].trace() - normal) : normal) /
                settings.strength_across;
            if (across > ratio) ratio = across, n = m;
        }
        bool slips = false;
        if (shear && std::isfinite(s[0])) {
            const Real slip =
                mohr_coulomb_ratio(s, settings.compressive_strength, settings.friction_angle);
            if (slip > ratio) ratio = slip, slips = true;
        }
        if (!settings.strength_scale.empty()) ratio /= settings.strength_scale[a];
        if (!(ratio > 1)) continue;
        // The shear plane needs all three principal directions: found only for a node that cracks.
        if (slips)
            n = mohr_coulomb_normal(stress.effective[a], settings.friction_angle,
                                    mesh.nodes[a] - centroid, settings.down);
        Crack c;
        c.node = a, c.centre = mesh.nodes[a], c.stress_ratio = ratio;
        // The eigenvector's sign is arbitrary: fix it so that the disk does not depend on the
        // eigen solver's choice (its largest component positive).
        Index k;
        n.cwiseAbs().maxCoeff(&k);
        c.normal = n[k] < 0 ? Vec3(-n) : n;
        c.area = std::max<Real>(stress.strain_energy[a], 0) / settings.fracture_energy;
        c.radius = std::clamp(std::sqrt(c.area / std::numbers::pi), 0.5 * settings.spacing,
                              3 * settings.spacing);
        candidates.push_back(c);
    }
    std::sort(candidates.begin(), candidates.end(), [&](const Crack& x, const Crack& y) {
        return x.stress_ratio != y.stress_ratio ? x.stress_ratio > y.stress_ratio
                                                : node_id[x.node] < node_id[y.node];
    });
    std::vector<Crack> taken;
    const Real min_distance2 = settings.exclusion * settings.exclusion;
    for (const Crack& c : candidates) {
        if (int(taken.size()) >= settings.max_cracks) break;
        const bool near = std::any_of(taken.begin(), taken.end(), [&](const Crack& t) {
            return (t.centre - c.centre).squaredNorm() < min_distance2;
        });
        if (!near && (!accept || accept(c))) taken.push_back(c);
    }
    return taken;
}

std::vector<LinkGeometry> link_geometry(const TetMesh& mesh, std::span<const ElementLink> links) {
    std::vector<LinkGeometry> geometry(links.size());
    for (size_t k = 0; k < links.size(); ++k) {
        LinkGeometry& g = geometry[k];
        g.a = mesh.tet_centroid(links[k].a), g.b = mesh.tet_centroid(links[k].b);
        g.face = shared_face_centroid(mesh, links[k]);
        g.reach2 = std::max((g.a - g.face).squaredNorm(), (g.b - g.face).squaredNorm());
    }
    return geometry;
}

std::vector<Index> links_cut(std::span<const LinkGeometry> links, std::span<const Crack> cracks) {
    std::vector<Index> cut(links.size(), -1);
    if (cracks.empty()) return cut;
    for (size_t k = 0; k < links.size(); ++k) {
        const LinkGeometry& l = links[k];
        for (size_t m = 0; m < cracks.size(); ++m) {
            const Crack& c = cracks[m];
            const Vec3 r = l.face - c.centre;
            // A plane between the centroids passes within reach of the face's centroid, so a
            // face farther than radius and reach from the centre is not cut: a cheap first test.
            if (r.squaredNorm() > c.radius * c.radius + l.reach2) continue;
            const Real sa = (l.a - c.centre).dot(c.normal), sb = (l.b - c.centre).dot(c.normal);
            if (!((sa < 0 && sb > 0) || (sa > 0 && sb < 0))) continue;
            if ((r - r.dot(c.normal) * c.normal).squaredNorm() < c.radius * c.radius) {
                cut[k] = Index(m);
                break;
            }
        }
    }
    return cut;
}

}  // namespace karst
