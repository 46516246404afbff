// Fracture (issue 13, docs/method.md §5.5-5.6): the Rankine test on the effective stress of solved
// Biot problems (tension, shear, compression, pore pressure alone), and node splitting along
// broken links.
#include "karst/core/disjoint_sets.hpp"
#include "karst/pfem/box_nodes.hpp"
#include "karst/pfem/cracks.hpp"
#include "karst/pfem/face_links.hpp"
#include "karst/pfem/mesh_split.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>

namespace karst {
namespace {

constexpr Real k_strength = 1e5, k_dx = 0.1;

CrackSettings settings(Real strength, CrackCriterion criterion = CrackCriterion::Rankine) {
    CrackSettings s;
    s.criterion = criterion;
    s.tensile_strength = strength, s.fracture_energy = 10, s.spacing = k_dx;
    s.exclusion = 2 * k_dx, s.max_cracks = 8;
    return s;
}

/// A box sample [0, size] on a lattice of spacing k_dx, turned by `turn` about the origin,
/// solved as a free, drained Biot body with pore pressure `p` and the tractions of `stress`
/// (given in the box's own frame) on its six faces.
struct Sample {
    TetMesh mesh;
    BiotProblem problem;
    BiotFields fields;
    NodalStress stress;

    Sample(const Vec3& size, const Mat3& turn, const Mat3& stress_local, Real p = 0) {
        // Meshed in the box's frame, then turned: the same mesh in any orientation.
        const std::vector<Vec3> nodes = box_lattice_nodes(Vec3::Zero(), size, k_dx);
        mesh = build_tet_mesh(nodes, std::vector<Real>(nodes.size(), k_dx), MeshOptions{});
        for (Vec3& x : mesh.nodes) x = turn * x;
        BiotMaterial& m = problem.material;
        m.youngs_modulus = 1e6, m.poisson_ratio = 0.25, m.biot_coefficient = 0.9;
        m.storage = 1e-6, m.bulk_density = 0;
        const Index n = mesh.node_count();
        problem.mobility.assign(mesh.tet_count(), 1e-9 * Mat3::Identity());
        problem.drained.assign(n, 1), problem.drained_pressure.assign(n, p);
        problem.fixed.assign(n, 0), problem.free_body = true;
        problem.nodal_force.assign(n, Vec3::Zero());
        for (int axis = 0; axis < 3; ++axis)
            for (int side = 0; side < 2; ++side) {
                const Vec3 normal = (side ? 1.0 : -1.0) * Vec3::Unit(axis);
                const Vec3 traction = turn * (stress_local * normal);
                const auto on_face = [&](const Vec3& x) {
                    const Real local = (turn.transpose() * x)[axis];
                    return std::abs(local - (side ? size[axis] : 0)) < 1e-9;
                };
                const auto loads = traction_loads(mesh, traction, on_face);
                for (Index a = 0; a < n; ++a) problem.nodal_force[a] += loads[a];
            }
        BiotSolver solver(mesh, problem);
        fields = {std::vector<Vec3>(n, Vec3::Zero()), std::vector<Real>(n, p)};
        solver.advance(1.0, fields);
        stress = nodal_stress(mesh, problem.material, fields);
    }

    std::vector<Crack> cracks(CrackCriterion criterion = CrackCriterion::Rankine) const {
        return cracks(settings(k_strength, criterion));
    }
    std::vector<Crack> cracks(const CrackSettings& with) const {
        std::vector<Index> ids(mesh.node_count());
        for (Index a = 0; a < mesh.node_count(); ++a) ids[a] = a;
        return find_cracks(mesh, stress, ids, with);
    }
};

Mat3 uniaxial(Real s) {
    return s * Vec3::UnitX() * Vec3::UnitX().transpose();
}

Mat3 turned_30_about_two_axes() {
    const Real a = std::numbers::pi / 6;
    return (Eigen::AngleAxisd(a, Vec3::UnitZ()) * Eigen::AngleAxisd(a, Vec3::UnitY()))
        .toRotationMatrix();
}

Real angle_deg(const Vec3& a, const Vec3& b) {
    return std::acos(std::min<Real>(1, std::abs(a.normalized().dot(b.normalized())))) * 180 /
           std::numbers::pi;
}

TEST(Cracks, BarInTensionCracksBetween95And105PercentOfTheStrengthNormalToTheLoad) {
    const Vec3 size(1.2, 0.3, 0.3);
    for (const Mat3& turn : {Mat3(Mat3::Identity()), turned_30_about_two_axes()}) {
        EXPECT_TRUE(Sample(size, turn, uniaxial(0.95 * k_strength)).cracks().empty());
        const std::vector<Crack> cracks = Sample(size, turn, uniaxial(1.05 * k_strength)).cracks();
        ASSERT_FALSE(cracks.empty());
        EXPECT_LE(cracks.size(), 8u);
        for (const Crack& c : cracks) {
            EXPECT_LT(angle_deg(c.normal, turn * Vec3::UnitX()), 5);
            EXPECT_NEAR(c.stress_ratio, 1.05, 0.01);
        }
        // None of one call within h of another.
        for (size_t i = 0; i < cracks.size(); ++i)
            for (size_t j = 0; j < i; ++j)
                EXPECT_GE((cracks[i].centre - cracks[j].centre).norm(), 2 * k_dx);
    }
}

TEST(Cracks, PureShearCracksAt45DegreesToTheShearAxes) {
    Mat3 shear = Mat3::Zero();
    shear(0, 1) = shear(1, 0) = 1.1 * k_strength;
    const std::vector<Crack> cracks = Sample(Vec3(0.6, 0.6, 0.3), Mat3::Identity(), shear).cracks();
    ASSERT_FALSE(cracks.empty());
    for (const Crack& c : cracks) EXPECT_LT(angle_deg(c.normal, Vec3(1, 1, 0)), 5);
    shear *= 0.95 / 1.1;
    EXPECT_TRUE(Sample(Vec3(0.6, 0.6, 0.3), Mat3::Identity(), shear).cracks().empty());
}

TEST(Cracks, HydrostaticCompressionNeverCracks) {
    const Sample s(Vec3(0.6, 0.4, 0.5), Mat3::Identity(), -100 * k_strength * Mat3::Identity());
    EXPECT_LT(s.stress.principal[0][0], -99 * k_strength);
    EXPECT_TRUE(s.cracks().empty());
    EXPECT_TRUE(s.cracks(CrackCriterion::ExtensionStrain).empty());
}

TEST(Cracks, TheExtensionStrainCracksTensionAtTheStrengthAndSplitsCompressionAlongTheLoad) {
    constexpr auto strain = CrackCriterion::ExtensionStrain;
    const Vec3 size(1.2, 0.3, 0.3);
    for (const Mat3& turn : {Mat3(Mat3::Identity()), turned_30_about_two_axes()}) {
        // Uniaxial tension: E eps_1 = sigma_1, as Rankine.
        EXPECT_TRUE(Sample(size, turn, uniaxial(0.95 * k_strength)).cracks(strain).empty());
        const std::vector<Crack> pulled =
            Sample(size, turn, uniaxial(1.05 * k_strength)).cracks(strain);
        ASSERT_FALSE(pulled.empty());
        for (const Crack& c : pulled) {
            EXPECT_LT(angle_deg(c.normal, turn * Vec3::UnitX()), 5);
            EXPECT_NEAR(c.stress_ratio, 1.05, 0.01);
        }
        // Uniaxial compression q: the sides stretch by nu q / E, so it splits along the load
        // once nu q exceeds sigma_t (nu = 0.25), where Rankine never cracks.
        const Real q = k_strength / 0.25;
        EXPECT_TRUE(Sample(size, turn, uniaxial(-0.95 * q)).cracks(strain).empty());
        const Sample pressed(size, turn, uniaxial(-1.05 * q));
        EXPECT_TRUE(pressed.cracks().empty());
        const std::vector<Crack> split = pressed.cracks(strain);
        ASSERT_FALSE(split.empty());
        for (const Crack& c : split) {
            EXPECT_GT(angle_deg(c.normal, turn * Vec3::UnitX()), 85);
            EXPECT_NEAR(c.stress_ratio, 1.05, 0.01);
        }
    }
}

/// Rankine at `tensile` with a Mohr-Coulomb shear test at sigma_c and phi (degrees).
CrackSettings mohr_coulomb(Real tensile, Real compressive, Real phi_deg) {
    CrackSettings s = settings(tensile);
    s.compressive_strength = compressive, s.friction_angle = phi_deg * std::numbers::pi / 180;
    return s;
}

TEST(Cracks, MohrCoulombCracksUniaxialCompressionAtItsStrengthAlongTheFailurePlane) {
    const Real compressive = 4 * k_strength;
    const Vec3 size(1.2, 0.3, 0.3);
    for (const Real phi : {0.0, 30.0, 45.0})
        for (const Mat3& turn : {Mat3(Mat3::Identity()), turned_30_about_two_axes()}) {
            const CrackSettings with = mohr_coulomb(k_strength, compressive, phi);
            EXPECT_TRUE(Sample(size, turn, uniaxial(-0.95 * compressive)).cracks(with).empty());
            const Sample pressed(size, turn, uniaxial(-1.05 * compressive));
            EXPECT_TRUE(pressed.cracks().empty()) << "Rankine alone";
            const std::vector<Crack> slips = pressed.cracks(with);
            ASSERT_FALSE(slips.empty()) << phi;
            for (const Crack& c : slips) {
                // The plane at 45 + phi/2 to the plane the load acts on: its normal at that
                // angle to the load axis.
                EXPECT_NEAR(angle_deg(c.normal, turn * Vec3::UnitX()), 45 + phi / 2, 5) << phi;
                EXPECT_NEAR(c.stress_ratio, 1.05, 0.01);
            }
        }
}

TEST(Cracks, MohrCoulombSlipsInPureShearAtTheCohesionAndNeverUnderHydrostaticCompression) {
    // Tensile strength out of reach: pure shear tau fails at c cos phi = sigma_c (1 - sin phi) / 2.
    for (const Real phi : {0.0, 30.0}) {
        const Real compressive = 4 * k_strength;
        const Real tau = compressive * (1 - std::sin(phi * std::numbers::pi / 180)) / 2;
        const CrackSettings with = mohr_coulomb(1e3 * k_strength, compressive, phi);
        Mat3 shear = Mat3::Zero();
        shear(0, 1) = shear(1, 0) = 0.95 * tau;
        EXPECT_TRUE(Sample(Vec3(0.6, 0.6, 0.3), Mat3::Identity(), shear).cracks(with).empty());
        shear *= 1.05 / 0.95;
        const std::vector<Crack> slips =
            Sample(Vec3(0.6, 0.6, 0.3), Mat3::Identity(), shear).cracks(with);
        ASSERT_FALSE(slips.empty());
        for (const Crack& c : slips) {
            EXPECT_NEAR(c.stress_ratio, 1.05, 0.01);
            // At 45 - phi/2 to the tension (1, 1, 0), in the plane z = 0.
            EXPECT_NEAR(angle_deg(c.normal, Vec3(1, 1, 0)), 45 - phi / 2, 5);
            EXPECT_LT(std::abs(c.normal.z()), 0.05);
        }
    }
    const Sample squeezed(Vec3(0.6, 0.4, 0.5), Mat3::Identity(),
                          -100 * k_strength * Mat3::Identity());
    EXPECT_TRUE(squeezed.cracks(mohr_coulomb(k_strength, 4 * k_strength, 30)).empty());
}

TEST(Cracks, TheMohrCoulombPlaneChosenLetsTheOuterWedgeSlideDown) {
    // A column's foot under its weight (vertical compression): beside the +x face, the plane
    // dips towards that face at 45 + phi/2 from the horizontal, so the wedge outside it rests on
    // a slope, not on the floor: the normal points out and up.
    const Mat3 sigma = Vec3(0, 0, -1e4).asDiagonal();
    const Real theta = std::numbers::pi / 4 - std::numbers::pi / 12;  // phi = 30 degrees
    const Vec3 down(0, 0, -1);
    for (const Real side : {1.0, -1.0}) {
        const Vec3 n = mohr_coulomb_normal(sigma, std::numbers::pi / 6, Vec3(side, 0, -0.2), down);
        EXPECT_NEAR(n.x(), side * std::cos(theta), 1e-12);
        EXPECT_NEAR(n.z(), std::sin(theta), 1e-12);
    }
    // Turned with the world, gravity included, the plane turns with them.
    const Mat3 turn = turned_30_about_two_axes();
    const Vec3 n = mohr_coulomb_normal(turn * sigma * turn.transpose(), std::numbers::pi / 6,
                                       turn * Vec3(1, 0, -0.2), turn * down);
    EXPECT_LT((n - turn * Vec3(std::cos(theta), 0, std::sin(theta))).norm(), 1e-12);
}

TEST(Cracks, ANodeCracksAtItsScaledStrength) {
    const Sample s(Vec3(1.2, 0.3, 0.3), Mat3::Identity(), uniaxial(0.6 * k_strength));
    std::vector<Index> ids(s.mesh.node_count());
    std::iota(ids.begin(), ids.end(), Index(0));
    CrackSettings weak = settings(k_strength);
    EXPECT_TRUE(find_cracks(s.mesh, s.stress, ids, weak).empty());
    weak.strength_scale.assign(s.mesh.node_count(), 0.5);
    const std::vector<Crack> cracks = find_cracks(s.mesh, s.stress, ids, weak);
    ASSERT_FALSE(cracks.empty());
    for (const Crack& c : cracks) EXPECT_NEAR(c.stress_ratio, 1.2, 0.01);
}

TEST(Cracks, TheSeparationTensorCracksUniaxialTensionAtTheStrengthAndShearAt45Degrees) {
    constexpr auto separation = CrackCriterion::SeparationTensor;
    const Vec3 size(1.2, 0.3, 0.3);
    for (const Mat3& turn : {Mat3(Mat3::Identity()), turned_30_about_two_axes()}) {
        EXPECT_TRUE(Sample(size, turn, uniaxial(0.95 * k_strength)).cracks(separation).empty());
        const std::vector<Crack> cracks =
            Sample(size, turn, uniaxial(1.05 * k_strength)).cracks(separation);
        ASSERT_FALSE(cracks.empty());
        for (const Crack& c : cracks) {
            EXPECT_LT(angle_deg(c.normal, turn * Vec3::UnitX()), 5);
            EXPECT_NEAR(c.stress_ratio, 1.05, 0.01);
        }
    }
    Mat3 shear = Mat3::Zero();
    shear(0, 1) = shear(1, 0) = 1.1 * k_strength;
    const Vec3 plate(0.6, 0.6, 0.3);
    const std::vector<Crack> cracks = Sample(plate, Mat3::Identity(), shear).cracks(separation);
    ASSERT_FALSE(cracks.empty());
    for (const Crack& c : cracks) EXPECT_LT(angle_deg(c.normal, Vec3(1, 1, 0)), 5);
    EXPECT_TRUE(Sample(plate, Mat3::Identity(), shear * 0.95 / 1.1).cracks(separation).empty());
    const Sample squeezed(Vec3(0.6, 0.4, 0.5), Mat3::Identity(),
                          -100 * k_strength * Mat3::Identity());
    EXPECT_TRUE(squeezed.cracks(separation).empty());
    // Pore pressure alone, through the effective stress.
    const Real B = 0.9;
    const Vec3 block(0.5, 0.4, 0.3);
    EXPECT_TRUE(Sample(block, Mat3::Identity(), Mat3::Zero(), 0.95 * k_strength / B)
                    .cracks(separation)
                    .empty());
    EXPECT_FALSE(Sample(block, Mat3::Identity(), Mat3::Zero(), 1.05 * k_strength / B)
                     .cracks(separation)
                     .empty());
}

TEST(Cracks, PorePressureAloneCracksWhenBTimesPReachesTheStrength) {
    // No load: the total stress stays zero, so sigma' = B p I (Terzaghi-Biot) turns tensile.
    const Real B = 0.9, p_crack = k_strength / B;
    const Vec3 size(0.5, 0.4, 0.3);
    EXPECT_TRUE(Sample(size, Mat3::Identity(), Mat3::Zero(), 0.95 * p_crack).cracks().empty());
    const Sample wet(size, Mat3::Identity(), Mat3::Zero(), 1.05 * p_crack);
    EXPECT_FALSE(wet.cracks().empty());
    for (Index a = 0; a < wet.mesh.node_count(); ++a)
        ASSERT_NEAR(wet.stress.principal[a][0] / (B * 1.05 * p_crack), 1, 0.01) << "node " << a;
}

TEST(Cracks, CrackRadiusComesFromTheStrainEnergyOverGc) {
    const Sample s(Vec3(1.2, 0.3, 0.3), Mat3::Identity(), uniaxial(2 * k_strength));
    std::vector<Index> ids(s.mesh.node_count());
    for (Index a = 0; a < s.mesh.node_count(); ++a) ids[a] = a;
    for (Real Gc : {1e-4, 1.0, 1e4}) {
        CrackSettings with_gc = settings(k_strength);
        with_gc.fracture_energy = Gc;
        const auto cracks = find_cracks(s.mesh, s.stress, ids, with_gc);
        ASSERT_FALSE(cracks.empty());
        const Crack& c = cracks[0];
        EXPECT_NEAR(c.area, s.stress.strain_energy[c.node] / Gc, 1e-12 * c.area);
        EXPECT_NEAR(c.radius,
                    std::clamp(std::sqrt(c.area / std::numbers::pi), 0.5 * k_dx, 3 * k_dx), 1e-15);
    }
}

TEST(Cracks, LayeredRockSplitsAlongItsWeakLayers) {
    // A bar pulled along x, its bedding normal 30 degrees off x: sigma_nn = 0.75 sigma. With half
    // the strength across the layers, a crack along a layer opens from sigma = 2/3 sigma_t.
    const Real a = std::numbers::pi / 6;
    const Vec3 normal(std::cos(a), std::sin(a), 0);
    auto layered_cracks = [&](Real load) {
        const Sample s(Vec3(1.2, 0.3, 0.3), Mat3::Identity(), uniaxial(load));
        CrackSettings layered = settings(k_strength);
        layered.strength_across = 0.5 * k_strength;
        layered.layer_normal.assign(s.mesh.node_count(), normal);
        std::vector<Index> ids(s.mesh.node_count());
        for (Index k = 0; k < s.mesh.node_count(); ++k) ids[k] = k;
        return find_cracks(s.mesh, s.stress, ids, layered);
    };
    EXPECT_TRUE(layered_cracks(0.95 * 2.0 / 3 * k_strength).empty());
    const auto cracks = layered_cracks(1.05 * 2.0 / 3 * k_strength);
    ASSERT_FALSE(cracks.empty());
    for (const Crack& c : cracks) {
        EXPECT_LT(angle_deg(c.normal, normal), 1e-6);
        EXPECT_NEAR(c.stress_ratio, 1.05, 0.01);
    }
}

// A chain of 40 tets cut after its 5th: the 5-tet piece is under the resolution and is spared,
// unless it stays anchored (then it is no fragment, and the 35 tets hanging from it break off).
TEST(MeshSplit, SmallPiecesAreSparedUnlessTheyStayAnchored) {
    const Index n = 40;
    std::vector<ElementLink> links;
    for (Index e = 0; e + 1 < n; ++e) links.push_back({e, e + 1});
    const std::vector<char> cut_after_five = [&] {
        std::vector<char> cut(links.size(), 0);
        cut[4] = 1;
        return cut;
    }();
    std::vector<char> cut = cut_after_five;
    EXPECT_EQ(spare_small_pieces(n, links, cut, 24), 1);
    EXPECT_EQ(cut[4], 0);
    const auto holds_tet_zero = [](std::span<const Index> tets) {
        return std::find(tets.begin(), tets.end(), Index(0)) != tets.end();
    };
    cut = cut_after_five;
    EXPECT_EQ(spare_small_pieces(n, links, cut, 24, holds_tet_zero), 0);
    EXPECT_EQ(cut[4], 1);
    // An anchor in the big piece does not excuse the small free one.
    const auto holds_last_tet = [&](std::span<const Index> tets) {
        return std::find(tets.begin(), tets.end(), n - 1) != tets.end();
    };
    cut = cut_after_five;
    EXPECT_EQ(spare_small_pieces(n, links, cut, 24, holds_last_tet), 1);
    EXPECT_EQ(cut[4], 0);
}

// Two pieces of 30 and 35 tets, cut apart, with a crumb of 5 tets between them cut off both: the
// crumb rejoins the piece it shares the most cut faces with, and the two pieces stay apart. (It
// rejoined both before, and the crumb bridged the crack: a column cut at its foot hung on it.)
TEST(MeshSplit, ACrumbBetweenTwoPiecesRejoinsOneAndTheCrackBetweenThemStays) {
    const Index n = 70;  // A: 0-29, the crumb: 30-34, B: 35-69
    const auto spared = [&](bool second_face_on_a, Index expect_restored) {
        std::vector<ElementLink> links;
        std::vector<char> cut;
        for (Index e = 0; e + 1 < n; ++e)
            links.push_back({e, e + 1}), cut.push_back(e == 29 || e == 34);
        links.push_back({0, 69}), cut.push_back(1);  // A and B touch across the crack
        if (second_face_on_a) links.push_back({28, 31}), cut.push_back(1);
        EXPECT_EQ(spare_small_pieces(n, links, cut, 24), expect_restored);
        DisjointSets pieces(n);
        for (size_t k = 0; k < links.size(); ++k)
            if (!cut[k]) pieces.join(links[k].a, links[k].b);
        EXPECT_NE(pieces.find(0), pieces.find(69)) << "the crack between A and B stays";
        const Index crumb = pieces.find(32);
        return crumb == pieces.find(0) ? 'A' : crumb == pieces.find(69) ? 'B' : '-';
    };
    EXPECT_EQ(spared(true, 2), 'A') << "two faces on A against one on B";
    EXPECT_EQ(spared(false, 1), 'B') << "one face on each: the larger piece";
}

/// A bar 1 x 0.3 x 0.3 m on the lattice, its links, and those a crack disk at x = 0.5 with
/// normal x (unless given), centred at (y, z), cuts.
struct CutBar {
    TetMesh mesh;
    std::vector<ElementLink> links;
    std::vector<char> broken;

    CutBar(Real y, Real z, Real radius, const Vec3& normal = Vec3::UnitX()) {
        const std::vector<Vec3> nodes = box_lattice_nodes(Vec3::Zero(), Vec3(1, 0.3, 0.3), k_dx);
        mesh = build_tet_mesh(nodes, std::vector<Real>(nodes.size(), k_dx), MeshOptions{});
        links = face_links(mesh);
        Crack c;
        c.centre = Vec3(0.5, y, z), c.normal = normal.normalized(), c.radius = radius;
        const std::vector<Index> cutter = links_cut(mesh, links, std::span(&c, 1));
        for (Index k : cutter) broken.push_back(k >= 0);
    }

    /// Per node of the bar, whether it lies on a broken face.
    std::vector<char> on_crack() const {
        std::vector<char> on(mesh.node_count(), 0);
        for (size_t k = 0; k < links.size(); ++k)
            if (broken[k])
                for (Index a : shared_nodes(mesh, links[k])) on[a] = 1;
        return on;
    }
};

TEST(MeshSplit, ARemeshOfACrackedBarKeepsTheCrackOpen) {
    // A crack through the half of the section at y < 0.15: the bar stays one piece.
    const CutBar bar(0, 0.15, 0.16);
    const std::vector<char> source_on_crack = bar.on_crack();
    const MeshSplit split = split_mesh(bar.mesh, bar.links, bar.broken, 0.05 * k_dx);
    ASSERT_EQ(split.components, 1);
    ASSERT_GT(split.split_nodes, 0);
    // The particles sit where the split moved them; a fresh triangulation of them fills the gap.
    const Index n = split.mesh.node_count();
    TetMesh fresh =
        build_tet_mesh(split.mesh.nodes, std::vector<Real>(size_t(n), k_dx), MeshOptions{});
    ASSERT_EQ(fresh.node_count(), n);
    const auto closing = [](const TetMesh& m) {  // tets across the cut half of the plane
        Index count = 0;
        for (Index e = 0; e < m.tet_count(); ++e) {
            bool left = false, right = false;
            for (Index a : m.tets[e]) {
                const Real x = m.nodes[a].x();
                left = left || x < 0.499;
                right = right || x > 0.501;
            }
            count += left && right && m.tet_centroid(e).y() < 0.1;
        }
        return count;
    };
    const Index closing_before = closing(fresh);
    ASSERT_GT(closing_before, 0);
    std::vector<Index> old_node(static_cast<size_t>(n));
    std::iota(old_node.begin(), old_node.end(), Index(0));
    std::vector<char> on_crack(static_cast<size_t>(n));
    for (Index k = 0; k < n; ++k) on_crack[k] = source_on_crack[split.source[k]];
    const Index removed =
        drop_tets_across_cracks(fresh, split.mesh, split.links, old_node, on_crack);
    EXPECT_EQ(closing(fresh), 0);
    EXPECT_GE(removed, closing_before);
    // Only the gap's tets go: the rest of the bar is meshed as before, and it is still one piece.
    EXPECT_GE(fresh.tet_count(), split.mesh.tet_count() - 12);
    EXPECT_LE(fresh.tet_count(), split.mesh.tet_count() + 12);
    Index pieces = 0;
    tet_components(fresh.tet_count(), face_links(fresh), pieces);
    EXPECT_EQ(pieces, 1);
}

TEST(MeshSplit, ARemeshOfAnObliquelyCrackedBarKeepsItsTetsAndMeshesOnlyTheNewPoints) {
    // An oblique crack through the whole section: two pieces, their copies moved off the crack.
    const CutBar bar(0.1, 0.13, 0.5, Vec3(1, 0.6, 0.35));
    const MeshSplit split = split_mesh(bar.mesh, bar.links, bar.broken, 0.05 * k_dx);
    ASSERT_EQ(split.components, 2);
    const Index n_split = split.mesh.node_count();
    // The structure's mesh keeps each copy where its source was; the particles sit off it.
    TetMesh old = split.mesh;
    for (Index k = 0; k < n_split; ++k) old.nodes[k] = bar.mesh.nodes[split.source[k]];
    const std::vector<char> source_on_crack = bar.on_crack();
    // The remesh: the bar's corner node (1, 0.3, 0.3) is lost, a block of 8 new particles
    // lies against the side y = 0.3.
    std::vector<Vec3> x;
    std::vector<Index> old_node;
    std::vector<char> on_crack;
    Index lost = -1;
    for (Index k = 0; k < n_split; ++k) {
        if ((old.nodes[k] - Vec3(1, 0.3, 0.3)).norm() < 1e-9) {
            lost = k;
            continue;
        }
        x.push_back(split.mesh.nodes[k]), old_node.push_back(k);
        on_crack.push_back(source_on_crack[split.source[k]]);
    }
    ASSERT_GE(lost, 0);
    const std::vector<Vec3> added = box_lattice_nodes(Vec3(0.2, 0.4, 0), Vec3(0.3, 0.5, 0.1), k_dx);
    for (const Vec3& p : added) x.push_back(p), old_node.push_back(-1), on_crack.push_back(0);
    const Index n = Index(x.size());
    TetMesh fresh = build_tet_mesh(x, std::vector<Real>(size_t(n), k_dx), MeshOptions{});
    ASSERT_EQ(fresh.node_count(), n);
    // A fresh triangulation with the drop alone splits the lattice cells otherwise than the old
    // mesh: its tets cross the crack surface, and dropping them leaves crack nodes under-meshed.
    TetMesh dropped_only = fresh;
    drop_tets_across_cracks(dropped_only, old, split.links, old_node, on_crack);
    const auto nodal_volume = [&](const TetMesh& m) {
        std::vector<Real> v(m.node_count(), 0);
        for (Index e = 0; e < m.tet_count(); ++e)
            for (Index a : m.tets[e]) v[a] += m.tet_volume(e) / 4;
        return v;
    };
    const std::vector<Real> before = nodal_volume(old);
    const auto least_crack_volume = [&](const TetMesh& m) {  // relative to the split mesh's
        const std::vector<Real> v = nodal_volume(m);
        Real least = 1e9;
        for (Index a = 0; a < n; ++a)
            if (on_crack[a]) least = std::min(least, v[a] / before[old_node[a]]);
        return least;
    };
    EXPECT_LT(least_crack_volume(dropped_only), 0.25);
    keep_old_tets(fresh, old, old_node);
    drop_tets_across_cracks(fresh, old, split.links, old_node, on_crack);
    // Every old tet off the lost node is kept, so each crack node keeps its volume (within the
    // copies' offset of 0.05 dx), the crack stays as it was, and the new particles are meshed
    // onto one side: still two pieces.
    Index off_lost = 0;
    for (const Tet& t : old.tets) off_lost += std::find(t.begin(), t.end(), lost) == t.end();
    Index old_kept = 0;
    for (const Tet& t : fresh.tets)
        old_kept += std::all_of(t.begin(), t.end(), [&](Index a) { return old_node[a] >= 0; });
    EXPECT_EQ(old_kept, off_lost);
    EXPECT_GT(least_crack_volume(fresh), 0.8);
    std::vector<char> meshed(n, 0);
    for (const Tet& t : fresh.tets)
        for (Index a : t) meshed[a] = 1;
    for (Index a = n - Index(added.size()); a < n; ++a) EXPECT_TRUE(meshed[a]) << "new node " << a;
    Index pieces = 0;
    tet_components(fresh.tet_count(), face_links(fresh), pieces);
    EXPECT_EQ(pieces, 2);
}

TEST(MeshSplit, ACutThroughABarSplitsItsNodesAndSharesTheirVolume) {
    // A crack disk at x = 0.5 across the whole section (the plane runs through a lattice layer:
    // every tet lies on one side of it).
    const CutBar bar(0.15, 0.15, 0.5);
    const TetMesh& mesh = bar.mesh;
    const std::vector<ElementLink>& links = bar.links;
    const std::vector<char>& broken = bar.broken;
    const MeshSplit split = split_mesh(mesh, links, broken, 0.05 * k_dx);
    EXPECT_EQ(split.components, 2);
    EXPECT_EQ(split.split_nodes, 4 * 4);  // the 4 x 4 nodes of the layer x = 0.5
    ASSERT_EQ(split.mesh.node_count(), mesh.node_count() + 16);
    // Shares of each source sum to one; share-weighted positions are unchanged.
    std::vector<Real> total(mesh.node_count(), 0);
    std::vector<Vec3> moment(mesh.node_count(), Vec3::Zero());
    for (Index k = 0; k < split.mesh.node_count(); ++k) {
        total[split.source[k]] += split.share[k];
        moment[split.source[k]] += split.share[k] * split.mesh.nodes[k];
    }
    for (Index a = 0; a < mesh.node_count(); ++a) {
        ASSERT_NEAR(total[a], 1, 1e-14);
        ASSERT_LT((moment[a] - mesh.nodes[a]).norm(), 1e-15);
    }
    // Each split node's copies move apart, each to its own side of the cut.
    std::vector<Index> component_of_node(split.mesh.node_count(), -1);
    for (Index e = 0; e < split.mesh.tet_count(); ++e)
        for (Index k : split.mesh.tets[e]) {
            if (component_of_node[k] >= 0) {  // no tet of one component uses the other's nodes
                ASSERT_EQ(component_of_node[k], split.component[e]);
            }
            component_of_node[k] = split.component[e];
        }
    for (Index k = mesh.node_count(); k < split.mesh.node_count(); ++k) {
        const Index a = split.source[k];
        EXPECT_GT((split.mesh.nodes[k] - split.mesh.nodes[a]).norm(), 0.05 * k_dx);
        const Real side_k = split.mesh.nodes[k][0] - 0.5, side_a = split.mesh.nodes[a][0] - 0.5;
        EXPECT_LT(side_k * side_a, 0);
        EXPECT_NEAR(split.share[a] + split.share[k], 1, 1e-14);
    }
    // Unmoved, the boundary closes each half: it gains the two crack faces (2 x 0.3 x 0.3).
    const MeshSplit unmoved = split_mesh(mesh, links, broken, 0);
    Real area = 0, area_before = 0;
    for (const Triangle& t : unmoved.mesh.boundary) area += unmoved.mesh.area_vector(t).norm();
    for (const Triangle& t : mesh.boundary) area_before += mesh.area_vector(t).norm();
    EXPECT_NEAR(area - area_before, 2 * 0.09, 1e-9);
    // The half beyond the cut, as a mesh of its own, is closed with the bar's other half's area.
    std::vector<char> keep(unmoved.mesh.tet_count());
    for (Index e = 0; e < unmoved.mesh.tet_count(); ++e) keep[e] = unmoved.component[e] == 1;
    std::vector<Index> node_of, tet_of;
    const TetMesh half = sub_mesh(unmoved.mesh, keep, false, node_of, tet_of);
    Real enclosed = 0;
    for (const Triangle& t : half.boundary)
        enclosed += half.nodes[t[0]].dot(half.area_vector(t)) / 3;
    EXPECT_NEAR(enclosed, 0.5 * 0.09, 1e-12);
    EXPECT_EQ(half.node_count(), 6 * 4 * 4);
}

}  // namespace
}  // namespace karst
