// Fracture inside the engine (issue 13, docs/method.md §5.6): what a crack does to State. Mass,
// pore water and momentum across node splits and new fragments; cracks that do not depend on the
// particle order or the thread count; an overhang that breaks off under its weight and falls.
#include "support/files.hpp"
#include "support/simulate.hpp"

#include "karst/core/parallel.hpp"
#include "karst/core/soa.hpp"
#include "karst/pfem/fracture_stage.hpp"
#include "karst/pfem/mesh_split.hpp"
#include "karst/pfem/structure_stages.hpp"
#include "karst/sim/energy.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>
#include <random>

namespace karst {
namespace {

/// A wet bar held at one end and pulled at the other at three times its strength: one call
/// cracks it into pieces. G_c is small, so each crack spans the section. `beside` adds a shape to
/// the bar's (a union), a JSON shape object.
std::string pulled_bar(bool fracture, const std::string& beside = "") {
    const std::string bar = R"({ "type": "box", "min": [0, 0, 0], "max": [1.0, 0.2, 0.2] })";
    const std::string shape =
        beside.empty() ? bar : R"({ "type": "union", "shapes": [)" + bar + ", " + beside + "] }";
    return fmt::format(R"({{
      "name": "pulled_bar", "particle_spacing": 0.05, "gravity": [0, 0, 0],
      "poroelastic": {{ "time_step": 0.05 }}, "fracture": {{ "enabled": {} }},
      "porous_solids": [ {{ "shape": {},
        "material": {{ "porosity": 0.3, "permeability": 1e-10, "youngs_modulus": 1e6, "initial_saturation": 0.7,
                        "tensile_strength": 1e5, "fracture_energy": 1e-3 }},
        "constraints": [
          {{ "kind": "drained", "region": {{ "type": "box", "min": [-1, -1, -1], "max": [2, 2, 2] }} }},
          {{ "kind": "fixed", "region": {{ "type": "box", "min": [-1, -1, -1], "max": [0, 2, 2] }} }},
          {{ "kind": "traction", "traction": [3e5, 0, 0], "region": {{ "type": "box", "min": [1, -1, -1], "max": [2, 2, 2] }} }} ] }} ]
    }})",
                       fracture, shape);
}

Real total_mechanical_energy(const test::Simulation& sim) {
    const Energy e = mechanical_energy(sim.model, sim.state);
    return e.total();
}

struct Totals {
    Real mass = 0, water = 0;
};

Totals totals(const PorousParticles& p) {
    Totals t;
    for (Index i = 0; i < p.size(); ++i) {
        t.mass += p.solid_mass[i] + p.absorbed_mass[i], t.water += p.absorbed_mass[i];
    }
    return t;
}

TEST(FractureScene, SplitsAndNewFragmentsKeepMassWaterAndMomentum) {
    test::Simulation sim(pulled_bar(false));
    sim.advance();  // one Biot call, not yet tested for cracks
    ASSERT_EQ(sim.state.structures.timings.biot_calls, 1);
    PorousParticles& p = sim.state.porous.particles;
    // The particles of an anchored body move only as its quasi-static u does, here a rigid
    // motion plus a shear: no momentum of a body (sim/energy.cpp), and none a piece may take.
    for (Index i = 0; i < p.size(); ++i)
        p.v[i] =
            Vec3(0.3, -0.2, 0.1) + Vec3(0.5, 1.0, -2.0).cross(p.x[i]) + Vec3(0, 0.4 * p.x[i][0], 0);
    const Totals before = totals(p);
    const Index n_before = p.size();
    sim.model.scene.fracture.enabled = true;
    ASSERT_TRUE(fracture_structures(sim.model, sim.state, sim.state.time));
    const FractureCounts& c = sim.state.structures.fracture;
    EXPECT_GT(c.cracks, 0);
    EXPECT_GT(c.nodes_split, 0);
    EXPECT_EQ(p.size(), n_before + c.nodes_split);  // one copy per split node (two-way cuts)
    EXPECT_GE(c.fragments_created, 1);
    const Totals after = totals(p);
    EXPECT_NEAR(after.mass, before.mass, 1e-12 * before.mass);
    EXPECT_NEAR(after.water, before.water, 1e-12 * before.water);
    // Every new fragment starts at rest (M27: the anchored body's rigid field is zero), and
    // carries exactly its members' momentum, about its centre and in total: none.
    const auto& fragments = sim.state.porous.fragments;
    for (size_t f = 1; f < fragments.size(); ++f) {
        const Fragment& fr = fragments[f];
        ASSERT_FALSE(fr.anchored);
        Real m = 0;
        Vec3 P = Vec3::Zero(), L = Vec3::Zero();
        for (Index i = 0; i < p.size(); ++i) {
            if (p.fragment[i] != Index(f)) continue;
            const Real mi = p.solid_mass[i] + p.absorbed_mass[i];
            m += mi, P += mi * p.v[i], L += mi * p.x[i].cross(p.v[i]);
        }
        EXPECT_NEAR(fr.mass, m, 1e-12 * m);
        EXPECT_EQ(fr.velocity, Vec3::Zero());
        EXPECT_EQ(fr.angular_momentum, Vec3::Zero());
        EXPECT_EQ(P, Vec3::Zero());
        EXPECT_EQ(L, Vec3::Zero());
    }
    // The structure keeps the rest, on a mesh whose nodes are its particles.
    const Structure& s = sim.state.structures.structures.at(0);
    for (Index a = 0; a < s.mesh.node_count(); ++a)
        ASSERT_EQ(sim.state.structures.node_of[s.node_id[a]], std::make_pair(Index(0), a));
    // ... and the run goes on: the next calls solve the cracked mesh.
    sim.run_until(sim.state.time + 3 * 0.05 - 1e-9);
    EXPECT_EQ(sim.state.structures.timings.biot_calls, 4);
}

std::vector<CrackRecord> sorted_cracks(std::vector<CrackRecord> c) {
    std::sort(c.begin(), c.end(), [](const CrackRecord& a, const CrackRecord& b) {
        return std::lexicographical_compare(a.centre.begin(), a.centre.end(), b.centre.begin(),
                                            b.centre.end());
    });
    return c;
}

TEST(FractureScene, APieceUnderTheResolutionThatNoCrackCutOffStaysInTheStructure) {
    // A crumb of 2 x 2 x 2 particles (one lattice cell) three spacings beside the bar, meshed
    // apart from it: a piece of a body that no crack cut off (as a remesh may leave one beside
    // a crack). When the bar cracks, it must not leave as a fragment of a few grams.
    test::Simulation sim(
        pulled_bar(true, R"({ "type": "box", "min": [0.5, 0.35, 0], "max": [0.6, 0.45, 0.1] })"));
    const PorousParticles& p = sim.state.porous.particles;
    std::vector<Index> crumb;
    for (Index i = 0; i < p.size(); ++i)
        if (p.x[i][1] > 0.3) crumb.push_back(p.id[i]);
    ASSERT_EQ(crumb.size(), 8u);
    const Structure& s = sim.state.structures.structures.at(0);
    Index pieces = 0;
    tet_components(s.mesh.tet_count(), s.links, pieces);
    ASSERT_EQ(pieces, 2) << "the crumb is meshed apart from the bar";
    const Index anchored = s.fragment;
    sim.advance();
    EXPECT_GE(sim.state.structures.fracture.fragments_created, 1) << "the bar broke";
    const std::vector<Index> index_of = index_by_id(p, sim.state.structures.node_of.size());
    for (Index id : crumb) EXPECT_EQ(p.fragment[index_of[id]], anchored) << "particle " << id;
    // Every free fragment is a piece of the bar, over the resolution.
    std::vector<Index> members(sim.state.porous.fragments.size(), 0);
    for (Index i = 0; i < p.size(); ++i) ++members[p.fragment[i]];
    for (size_t f = 0; f < members.size(); ++f)
        if (Index(f) != anchored && members[f] > 0) {
            EXPECT_GE(members[f], 16) << "fragment " << f;
        }
}

TEST(FractureScene, TheCrackSetDoesNotDependOnTheParticleOrder) {
    test::Simulation a(pulled_bar(true)), b(pulled_bar(true));
    // b: the same particles, shuffled, and its structures built anew on them.
    PorousParticles& p = b.state.porous.particles;
    std::vector<std::uint32_t> perm(p.size());
    std::iota(perm.begin(), perm.end(), 0);
    std::shuffle(perm.begin(), perm.end(), std::mt19937(7));
    permute_attributes(p, perm);
    b.state.structures = StructureState{};
    b.state.biot_cache = BiotCache{};
    build_structures(b.model, b.state);
    a.advance(), b.advance();
    const auto ca = sorted_cracks(a.state.structures.cracks),
               cb = sorted_cracks(b.state.structures.cracks);
    ASSERT_GT(ca.size(), 0u);
    ASSERT_EQ(ca.size(), cb.size());
    for (size_t k = 0; k < ca.size(); ++k) {
        EXPECT_LT((ca[k].centre - cb[k].centre).norm(), 1e-9);
        EXPECT_LT((ca[k].normal - cb[k].normal).norm(), 1e-9);
        EXPECT_EQ(ca[k].links_broken, cb[k].links_broken);
    }
    EXPECT_EQ(a.state.structures.fracture.nodes_split, b.state.structures.fracture.nodes_split);
    EXPECT_EQ(a.state.porous.fragments.size(), b.state.porous.fragments.size());
}

TEST(FractureScene, CracksAndFragmentsAreIdenticalOnOneAndTwoThreads) {
    auto run = [](int threads) {
        ThreadLimit limit(threads);
        test::Simulation sim(pulled_bar(true));
        sim.run_until(0.3 - 1e-9);
        return std::move(sim.state);
    };
    const State one = run(1), two = run(2);
    ASSERT_EQ(one.structures.timings.biot_calls, 6);
    ASSERT_GE(one.structures.fracture.cracks, 5);
    ASSERT_GE(one.structures.fracture.fragments_created, 2);
    ASSERT_EQ(one.structures.cracks.size(), two.structures.cracks.size());
    for (size_t k = 0; k < one.structures.cracks.size(); ++k)
        EXPECT_EQ(one.structures.cracks[k].centre, two.structures.cracks[k].centre);
    const PorousParticles &p = one.porous.particles, &q = two.porous.particles;
    ASSERT_EQ(p.size(), q.size());
    EXPECT_EQ(p.x, q.x);
    EXPECT_EQ(p.v, q.v);
    EXPECT_EQ(p.fragment, q.fragment);
}

/// A cantilever of rock 1 m long, 0.2 m square, held at its root, under its own weight: the root
/// stress 3 rho g L^2 / H is about 3.2e5 Pa.
std::string overhang(Real tensile_strength) {
    return fmt::format(R"({{
      "name": "overhang", "particle_spacing": 0.05, "domain": {{ "min": [-0.5, -0.5, -3], "max": [1.5, 0.7, 0.7] }},
      "poroelastic": {{ "time_step": 0.02 }},
      "porous_solids": [ {{ "shape": {{ "type": "box", "min": [0, 0, 0], "max": [1.0, 0.2, 0.2] }},
        "material": {{ "porosity": 0.3, "permeability": 1e-10, "youngs_modulus": 1e7, "tensile_strength": {} }},
        "constraints": [
          {{ "kind": "fixed", "region": {{ "type": "box", "min": [-1, -1, -1], "max": [0, 2, 2] }} }},
          {{ "kind": "drained", "region": {{ "type": "box", "min": [-1, -1, -1], "max": [2, 2, 2] }} }} ] }} ]
    }})",
                       tensile_strength);
}

TEST(FractureScene, AnOverhangHeavierThanItsStrengthBreaksOffAndFalls) {
    test::Simulation weak(overhang(1e5));
    const Index n0 = weak.state.porous.size();
    weak.run_until(0.3);
    const auto& fragments = weak.state.porous.fragments;
    ASSERT_GE(fragments.size(), 2u);
    // The biggest free fragment is most of the overhang, and it has fallen.
    std::vector<Index> members(fragments.size(), 0);
    for (Index f : weak.state.porous.particles.fragment) ++members[f];
    const size_t big = std::max_element(members.begin() + 1, members.end()) - members.begin();
    EXPECT_GT(members[big], n0 / 2);
    EXPECT_FALSE(fragments[big].anchored);
    EXPECT_LT(fragments[big].centre[2], 0.1 - 0.05) << "its centre started at 0.1 m";
    EXPECT_LT(weak.state.structures.structures.at(0).mesh.node_count(), n0 / 2)
        << "the structure keeps the stub";

    // Ten times stronger than its root stress: it never cracks.
    test::Simulation strong(overhang(3e6));
    strong.run_until(0.3);
    EXPECT_EQ(strong.state.structures.fracture.cracks, 0);
    EXPECT_EQ(strong.state.porous.fragments.size(), 1u);
}

/// The overhang in a coupled run: a tank around it with a puddle of water on its floor, far
/// below. The Biot problem then starts from the rest state under the rock's weight
/// (structure_stages.cpp), and the weight acts through that state's stress.
std::string coupled_overhang(Real tensile_strength) {
    return fmt::format(R"({{
      "name": "coupled_overhang", "particle_spacing": 0.05, "poroelastic": {{ "time_step": 0.02 }},
      "fluid_blocks": [ {{ "shape": {{ "type": "box", "min": [1.0, 0.3, -1.0], "max": [1.4, 0.6, -0.9] }} }} ],
      "walls": [ {{ "kind": "container", "shape": {{ "type": "box", "min": [-0.5, -0.5, -1], "max": [1.5, 0.7, 0.7] }} }} ],
      "porous_solids": [ {{ "shape": {{ "type": "box", "min": [0, 0, 0], "max": [1.0, 0.2, 0.2] }},
        "material": {{ "porosity": 0.3, "permeability": 1e-10, "youngs_modulus": 1e7, "tensile_strength": {} }},
        "constraints": [ {{ "kind": "fixed", "region": {{ "type": "box", "min": [-1, -1, -1], "max": [0, 2, 2] }} }} ] }} ]
    }})",
                       tensile_strength);
}

TEST(FractureScene, InACoupledRunAnOverhangStandsInItsRestStateAndBreaksOffWhenTooWeak) {
    // Strong: the rock stands where it was built (u is measured from its rest state under its
    // weight), while that state sags as a cantilever does, and it never cracks.
    test::Simulation strong(coupled_overhang(3e6));
    ASSERT_FALSE(strong.model.poroelastic_only());
    strong.run_until(0.3);
    EXPECT_EQ(strong.state.structures.fracture.cracks, 0);
    const StructureState& st = strong.state.structures;
    const Structure& s = st.structures.at(0);
    // The mesh spans the particles' centres: a beam of L = 0.95 m and a 0.15 m square section.
    Vec3 lo = s.mesh.nodes[0], hi = lo;
    for (const Vec3& x : s.mesh.nodes) lo = lo.cwiseMin(x), hi = hi.cwiseMax(x);
    Real largest_u = 0, tip_sag = 0;
    for (Index a = 0; a < s.mesh.node_count(); ++a) {
        largest_u = std::max(largest_u, s.fields.u[a].norm());
        if (s.mesh.nodes[a][0] > hi[0] - 1e-9)
            tip_sag = std::min(tip_sag, st.weight_u[s.node_id[a]][2]);
    }
    const PorousParticles& p = strong.state.porous.particles;
    const Real mass = std::accumulate(p.solid_mass.begin(), p.solid_mass.end(), Real(0));
    const Real L = hi[0] - lo[0], h = hi[2] - lo[2], q = mass * 9.81 / L;        // m, m, N/m
    const Real beam_sag = q * std::pow(L, 4) / (8 * 1e7 * std::pow(h, 4) / 12);  // q L^4 / 8 E I
    EXPECT_LT(largest_u, 1e-6 * beam_sag) << "m: the rest state holds the weight";
    // Linear tets three across bend stiffer than a beam (measured: 0.77 of it).
    EXPECT_GT(-tip_sag, 0.6 * beam_sag) << "m";
    EXPECT_LT(-tip_sag, 1.05 * beam_sag) << "m";

    // Weak: the root stress of the weight (3.2e5 Pa) cracks it, and the overhang falls.
    test::Simulation weak(coupled_overhang(1e5));
    weak.run_until(0.3);
    EXPECT_GT(weak.state.structures.fracture.cracks, 0);
    const auto& fragments = weak.state.porous.fragments;
    ASSERT_GE(fragments.size(), 2u);
    std::vector<Index> members(fragments.size(), 0);
    for (Index f : weak.state.porous.particles.fragment) ++members[f];
    const size_t big = std::max_element(members.begin() + 1, members.end()) - members.begin();
    EXPECT_FALSE(fragments[big].anchored);
    EXPECT_LT(fragments[big].centre[2], 0.1 - 0.05) << "its centre started at 0.1 m";
}

/// An arch on the floor of a box: two legs 0.1 m square and 0.3 m tall, 0.4 m apart, under a
/// 0.1 m lintel, its weight's corner stress (about 16 kPa) three times its strength.
std::string arch() {
    return R"({
      "name": "arch", "particle_spacing": 0.025, "poroelastic": { "time_step": 0.02 },
      "walls": [ { "kind": "container", "shape": { "type": "box", "min": [-0.2, -0.2, 0], "max": [0.8, 0.3, 0.6] } } ],
      "porous_solids": [ { "shape": { "type": "union", "shapes": [
            { "type": "box", "min": [0, 0, 0], "max": [0.1, 0.1, 0.3] },
            { "type": "box", "min": [0.5, 0, 0], "max": [0.6, 0.1, 0.3] },
            { "type": "box", "min": [0, 0, 0.3], "max": [0.6, 0.1, 0.4] } ] },
        "material": { "porosity": 0.3, "permeability": 1e-10, "youngs_modulus": 1e7, "solid_density": 2000,
                      "tensile_strength": 5e3, "fracture_energy": 1e-3 },
        "constraints": [ { "kind": "drained", "region": { "type": "box", "min": [-1, -1, -1], "max": [2, 2, 2] } } ] } ]
    })";
}

// A wall only pushes (fracture_stage.cpp): the arch breaks, and of the pieces standing on the
// floor only the biggest stays clamped to it; the others are free fragments resting on the floor
// by contact. Before, every piece touching the floor stayed clamped, so no column cut from a
// block could slide or topple. The free pieces settle without sinking into the floor (each
// fragment's own contact law) and without gaining energy.
TEST(FractureScene, PiecesOfAnArchStandingOnTheFloorAreFreeFragmentsThatRestOnIt) {
    test::Simulation sim(arch());
    ASSERT_TRUE(sim.model.poroelastic_only());
    const Real e0 = total_mechanical_energy(sim);
    Real highest = e0;
    sim.run_until(1.0, [&] { highest = std::max(highest, total_mechanical_energy(sim)); });
    EXPECT_GE(sim.state.structures.fracture.fragments_created, 2);
    // Issue 11's bound for impacts: never above the start by 2 % of what was released (about
    // 1 J; the split copies, moved 5 % of a spacing apart, overlap the other side's particles by
    // a few per cent of a spacing, and the springs give the pieces 0.01 J at birth).
    const Real released = e0 - total_mechanical_energy(sim);
    EXPECT_GT(released, 0.5) << "J";
    EXPECT_LT(highest - e0, 0.02 * released) << "J";
    const PorousParticles& p = sim.state.porous.particles;
    const auto& fragments = sim.state.porous.fragments;
    const Real dx = sim.model.dx;
    std::vector<Real> lowest(fragments.size(), 1e9);
    Real fastest = 0;
    for (Index i = 0; i < p.size(); ++i) {
        lowest[p.fragment[i]] = std::min(lowest[p.fragment[i]], p.x[i][2]);
        if (!fragments[p.fragment[i]].anchored) fastest = std::max(fastest, p.v[i].norm());
    }
    Index free_on_floor = 0;
    for (size_t f = 0; f < fragments.size(); ++f) {
        if (fragments[f].mass <= 0) continue;
        EXPECT_GT(lowest[f], 0.0) << "m: fragment " << f << " sank over half a spacing";
        free_on_floor += !fragments[f].anchored && lowest[f] < dx;
    }
    EXPECT_GE(free_on_floor, 1) << "a leg cut from the clamped piece stands free on the floor";
    EXPECT_LT(fastest, 0.3) << "m/s: the pieces have settled";
}

/// A column 0.2 m square and 0.8 m tall standing on the floor of a box, drained: its weight
/// presses its foot with about rho g H = 11 kPa; a tensile strength of 1 kPa and the given
/// compressive strength (none: 0).
std::string column(Real compressive_strength) {
    const std::string shear =
        compressive_strength > 0
            ? fmt::format(R"(, "compressive_strength": {}, "friction_angle": 30)",
                          compressive_strength)
            : "";
    return R"({
      "name": "column", "particle_spacing": 0.025, "poroelastic": { "time_step": 0.02 },
      "walls": [ { "kind": "container", "shape": { "type": "box", "min": [-0.4, -0.4, 0], "max": [0.6, 0.6, 1.0] } } ],
      "porous_solids": [ { "shape": { "type": "box", "min": [0, 0, 0], "max": [0.2, 0.2, 0.8] },
        "material": { "porosity": 0.3, "permeability": 1e-10, "youngs_modulus": 1e7, "solid_density": 2000,
                      "tensile_strength": 1e3, "fracture_energy": 1e-3)" +
           shear + R"( },
        "constraints": [ { "kind": "drained", "region": { "type": "box", "min": [-1, -1, -1], "max": [2, 2, 2] } } ] } ]
    })";
}

// A column too weak for its weight in shear fails at its foot along inclined planes (Mohr-Coulomb
// at phi = 30 degrees: normals 60 degrees off the vertical), and pieces come off it without
// gaining energy. Rankine alone sees no tension in it, and a column twice as strong as its foot's
// stress stands. Only the first round's planes are checked (later ones answer the cut foot);
// every crack must lie above the floor, and the cut column must come free.
TEST(FractureScene, AColumnWeakerThanItsWeightInShearSlipsAtItsFootAlongInclinedPlanes) {
    test::Simulation weak(column(5e3));
    ASSERT_TRUE(weak.model.poroelastic_only());
    const Real e0 = total_mechanical_energy(weak);
    Real highest = e0, lowest = e0, largest_gain = 0, largest_u = 0;
    weak.run_until(0.5, [&] {
        const Real e = total_mechanical_energy(weak);
        highest = std::max(highest, e), largest_gain = std::max(largest_gain, e - lowest);
        lowest = std::min(lowest, e);
        for (const Structure& s : weak.state.structures.structures)
            for (const Vec3& u : s.fields.u) largest_u = std::max(largest_u, u.norm());
    });
    const StructureState& st = weak.state.structures;
    ASSERT_GT(st.fracture.cracks, 0);
    ASSERT_GE(st.cracks.size(), 8u);
    Index inclined = 0;
    for (size_t k = 0; k < 8; ++k) {  // the first round, on the intact column
        const CrackRecord& c = st.cracks[k];
        EXPECT_LT(c.centre[2], 0.15) << "m: at the foot";
        inclined += std::abs(std::abs(c.normal[2]) - 0.5) < 0.1;
    }
    EXPECT_GE(inclined, 7) << "of 8 inclined";
    EXPECT_GE(st.fracture.fragments_created, 1);
    EXPECT_LT(highest, e0 + 0.02 * (e0 - total_mechanical_energy(weak))) << "J";
    // Nor after it falls: the contact springs count in the total, and a split loads none of them
    // (the split's offsets left pairs across the cut at 0.85-0.94 dx, whose springs held 1 J the
    // moment the column came free).
    EXPECT_LT(largest_gain, 0.02 * (e0 - lowest)) << "J over the running minimum";
    // Cut at its foot, the column comes down as a free piece. (It hung on crumbs of the cut foot
    // before, a near-mechanism whose linear solve moved its top by 2.3 m, with crack centres
    // 0.25 m under the floor.)
    const PorousParticles& p = weak.state.porous.particles;
    std::vector<Real> mass(weak.state.porous.fragments.size(), 0);
    Real total = 0;
    for (Index i = 0; i < p.size(); ++i)
        mass[p.fragment[i]] += p.solid_mass[i], total += p.solid_mass[i];
    Real largest_free = 0;
    for (size_t f = 0; f < mass.size(); ++f)
        if (!weak.state.porous.fragments[f].anchored)
            largest_free = std::max(largest_free, mass[f]);
    EXPECT_GT(largest_free, 0.5 * total) << "kg of " << total;
    EXPECT_LT(largest_u, 2 * weak.model.dx) << "m: the structure's linear solve stays small";
    for (const CrackRecord& c : st.cracks)
        EXPECT_GT(c.centre[2], 0) << "m: a crack under the floor";

    for (const Real strength : {0.0, 25e3}) {
        test::Simulation stands(column(strength));
        stands.run_until(0.3);
        EXPECT_EQ(stands.state.structures.fracture.cracks, 0) << strength;
    }
}

/// A free bar 1.2 m x 0.3 m x 0.3 m on a 0.1 m lattice, drained, with the given constraints
/// (and material keys).
std::string free_bar(const std::string& constraints, const std::string& material = "",
                     Real youngs_modulus = 1e6) {
    return R"({
      "name": "ramp", "particle_spacing": 0.1, "gravity": [0, 0, 0], "poroelastic": { "time_step": 0.01 },
      "porous_solids": [ { "shape": { "type": "box", "min": [0, 0, 0], "max": [1.2, 0.3, 0.3] },
        "material": { "porosity": 0.3, "permeability": 1e-10, "biot_coefficient": 0.9,
                      "tensile_strength": 1e5, "youngs_modulus": )" +
           fmt::format("{}", youngs_modulus) + material + R"( },
        "constraints": [ )" +
           constraints + R"( ] } ]
    })";
}

/// Runs until the first crack; returns its time (or a negative time when none by `end`).
Real first_crack_time(test::Simulation& sim, Real end) {
    while (sim.state.time < end && sim.state.structures.cracks.empty()) sim.advance();
    return sim.state.structures.cracks.empty() ? -1 : sim.state.structures.cracks[0].time;
}

TEST(FractureScene, ABarUnderARampedTractionCracksAtItsStrengthNormalToTheLoad) {
    // The traction rises by 1 % of sigma_t per call (1 kPa per 0.01 s).
    test::Simulation sim(free_bar(R"(
      { "kind": "drained", "region": { "type": "box", "min": [-1, -1, -1], "max": [2, 2, 2] } },
      { "kind": "traction", "traction": [-1e5, 0, 0], "table": [[0, 0], [2, 2]],
        "region": { "type": "box", "min": [-1, -1, -1], "max": [0, 2, 2] } },
      { "kind": "traction", "traction": [1e5, 0, 0], "table": [[0, 0], [2, 2]],
        "region": { "type": "box", "min": [1.2, -1, -1], "max": [2, 2, 2] } })"));
    const Real t = first_crack_time(sim, 2);
    ASSERT_GT(t, 0) << "no crack under twice the strength";
    EXPECT_GE(t, 0.95);
    EXPECT_LE(t, 1.05);
    for (const CrackRecord& c : sim.state.structures.cracks)
        EXPECT_GT(std::abs(c.normal[0]), std::cos(5 * std::numbers::pi / 180));
}

TEST(FractureScene, ABarUnderARampedCompressionSlipsAtItsCompressiveStrengthOnTheShearPlane) {
    // Mohr-Coulomb at sigma_c = 4 sigma_t, phi = 30 degrees: the compression rises by 1 % of
    // sigma_c per call; Rankine alone never cracks it.
    const std::string ramp = R"(
      { "kind": "drained", "region": { "type": "box", "min": [-1, -1, -1], "max": [2, 2, 2] } },
      { "kind": "traction", "traction": [4e5, 0, 0], "table": [[0, 0], [2, 2]],
        "region": { "type": "box", "min": [-1, -1, -1], "max": [0, 2, 2] } },
      { "kind": "traction", "traction": [-4e5, 0, 0], "table": [[0, 0], [2, 2]],
        "region": { "type": "box", "min": [1.2, -1, -1], "max": [2, 2, 2] } })";
    test::Simulation sim(
        free_bar(ramp, R"(, "compressive_strength": 4e5, "friction_angle": 30)", 1e8));
    const Real t = first_crack_time(sim, 2);
    ASSERT_GT(t, 0) << "no crack under twice the compressive strength";
    EXPECT_GE(t, 0.95);
    EXPECT_LE(t, 1.05);
    // 60 degrees off the load axis: the cracks of the uniaxial stress, the call's first round.
    // The rounds repeated after them solve a bar cut by shear cracks that nothing presses shut
    // (the Biot problem has no contact across a crack), a near-mechanism whose stress no
    // criterion is tested against here.
    int first_round = 0;
    for (const CrackRecord& c : sim.state.structures.cracks) {
        if (c.round > 0) continue;
        ++first_round;
        EXPECT_NEAR(std::abs(c.normal[0]), 0.5, std::sin(5 * std::numbers::pi / 180));
    }
    EXPECT_GE(first_round, 2);
    test::Simulation rankine(free_bar(ramp, "", 1e8));
    EXPECT_LT(first_crack_time(rankine, 2), 0) << "Rankine cracked a bar in compression";
}

TEST(FractureScene, WaterWeakensTheBarLinearlyWithItsSaturationToItsWetStrength) {
    // The ramp of the test above on bars at S = 1 and S = 0.5 with a wet strength half the dry
    // one: they crack at 0.5 and 0.75 of the dry strength. The bars are stiff, so that their
    // stretch hardly lowers S (at E = 1 MPa the stretched pores held 10 % less). At 0.9 of that
    // load the mesh frames' crack_candidate reads 0.9, the ratio to the wet strength.
    const std::string ramp = R"(
      { "kind": "drained", "region": { "type": "box", "min": [-1, -1, -1], "max": [2, 2, 2] } },
      { "kind": "traction", "traction": [-1e5, 0, 0], "table": [[0, 0], [2, 2]],
        "region": { "type": "box", "min": [-1, -1, -1], "max": [0, 2, 2] } },
      { "kind": "traction", "traction": [1e5, 0, 0], "table": [[0, 0], [2, 2]],
        "region": { "type": "box", "min": [1.2, -1, -1], "max": [2, 2, 2] } })";
    for (const Real saturation : {1.0, 0.5}) {
        test::Simulation sim(free_bar(
            ramp,
            fmt::format(R"(, "tensile_strength_wet": 5e4, "initial_saturation": {})", saturation),
            1e8));
        const Real expected = 1 - 0.5 * saturation;
        sim.run_until(0.9 * expected);
        ASSERT_TRUE(sim.state.structures.cracks.empty()) << "S = " << saturation;
        MeshFrame frame;
        append_structure_meshes(sim.model, sim.state, frame);
        const auto candidate =
            std::find_if(frame.nodes.arrays.begin(), frame.nodes.arrays.end(),
                         [](const auto& a) { return a.name == "crack_candidate"; });
        ASSERT_NE(candidate, frame.nodes.arrays.end());
        const Real largest = *std::max_element(candidate->values.begin(), candidate->values.end());
        EXPECT_NEAR(largest, 0.9, 0.05) << "S = " << saturation;
        const Real t = first_crack_time(sim, 2);
        ASSERT_GT(t, 0) << "S = " << saturation;
        EXPECT_GE(t, 0.95 * expected) << "S = " << saturation;
        EXPECT_LE(t, 1.05 * expected) << "S = " << saturation;
    }
}

TEST(FractureScene, RaisingThePorePressureAloneCracksWhenBTimesPReachesTheStrength) {
    // No load; the drained pressure rises by 1 % of sigma_t / B per call. sigma' = B p I.
    const Real p_crack = 1e5 / 0.9;
    test::Simulation sim(free_bar(fmt::format(
        R"({{ "kind": "drained", "pressure": {}, "table": [[0, 0], [2, 2]],
              "region": {{ "type": "box", "min": [-1, -1, -1], "max": [2, 2, 2] }} }})",
        p_crack)));
    const Real t = first_crack_time(sim, 2);
    ASSERT_GT(t, 0) << "no crack at twice the pressure";
    EXPECT_GE(t, 0.95);
    EXPECT_LE(t, 1.05);
}

TEST(FractureScene, ThreePointBendingCracksAtTheBottomOfMidSpanNearTheBeamTheoryLoad) {
    // Mesh extent: x 0.01..1.09, b = 0.08 (y), h = 0.18 (z); rollers (z held) under x = 0.05 and
    // x = 1.05 (span L = 1); a line load over x 0.53..0.57 on top rises by 1 % of the beam
    // theory's cracking load F = 2 sigma_t b h^2 / (3 L) per call.
    const Real b = 0.08, h = 0.18, L = 1.0, sigma_t = 1e5, F = 2 * sigma_t * b * h * h / (3 * L);
    const Real strip = 0.04 * b, traction = F / strip;
    test::Simulation sim(fmt::format(R"({{
      "name": "three_point_bending", "particle_spacing": 0.02, "gravity": [0, 0, 0],
      "poroelastic": {{ "time_step": 0.01 }},
      "porous_solids": [ {{ "shape": {{ "type": "box", "min": [0, 0, 0], "max": [1.1, 0.1, 0.2] }},
        "material": {{ "porosity": 0.3, "permeability": 1e-10, "youngs_modulus": 1e7, "tensile_strength": {} }},
        "constraints": [
          {{ "kind": "drained", "region": {{ "type": "box", "min": [-1, -1, -1], "max": [2, 2, 2] }} }},
          {{ "kind": "fixed", "axes": "z", "region": {{ "type": "box", "min": [0.0499, -1, -1], "max": [0.0501, 2, 0] }} }},
          {{ "kind": "fixed", "axes": "z", "region": {{ "type": "box", "min": [1.0499, -1, -1], "max": [1.0501, 2, 0] }} }},
          {{ "kind": "traction", "traction": [0, 0, {}], "table": [[0, 0], [2, 2]],
             "region": {{ "type": "box", "min": [0.535, -1, 0.2], "max": [0.565, 2, 1] }} }} ] }} ]
    }})",
                                     sigma_t, -traction));
    // The loaded strip is what the test assumes.
    const Structure& s0 = sim.state.structures.structures.at(0);
    const BiotProblem& problem = sim.state.biot_cache.find(0, s0.mesh_version)->solver->problem();
    Vec3 total = Vec3::Zero();
    for (const Vec3& f : problem.nodal_force) total += f;
    ASSERT_NEAR(total[2], 0, 1e-9);  // the table starts at 0
    const Real t = first_crack_time(sim, 2);
    ASSERT_GT(t, 0) << "no crack at twice the beam theory's load";
    EXPECT_NEAR(t, 1, 0.1) << "cracking load / F";
    const CrackRecord& first = sim.state.structures.cracks[0];
    EXPECT_NEAR(first.centre[0], 0.55, 0.05);
    EXPECT_LT(first.centre[2], 0.05) << "at the bottom";
    EXPECT_GT(std::abs(first.normal[0]), std::cos(10 * std::numbers::pi / 180)) << "vertical";
}

// The shipped demos run to their end without the watchdog (they throw if it fires) and crack.
TEST(FractureScene, TheShippedHydraulicFractureDemoCracksAroundItsPocket) {
    test::Simulation sim(
        test::read_text(std::string(KARST_SOURCE_DIR) + "/scenes/hydraulic_fracture.json"));
    sim.run_until(sim.model.scene.time.end - 1e-9);
    const StructureState& st = sim.state.structures;
    ASSERT_GT(st.fracture.cracks, 0);
    for (const CrackRecord& c : st.cracks)  // within a few spacings of the pocket (r = 0.06 m)
        EXPECT_LT((c.centre - Vec3(0.2, 0.2, 0.15)).norm(), 0.06 + 4 * 0.02);
}

TEST(FractureScene, TheShippedCollapsingSceneBreaksIntoFragmentsWithoutGainingEnergy) {
    test::Simulation sim(
        test::read_text(std::string(KARST_SOURCE_DIR) + "/scenes/collapsing.json"));
    const Real e0 = total_mechanical_energy(sim);
    Real highest = e0;
    sim.run_until(sim.model.scene.time.end - 1e-9,
                  [&] { highest = std::max(highest, total_mechanical_energy(sim)); });
    // The wall's foot is cut off as a free slab. (A second piece, a corner crumb, came off while
    // the split loaded the contact springs, whose kicks reached the wall's Biot loads.)
    EXPECT_GE(sim.state.structures.fracture.fragments_created, 1);
    EXPECT_LT(highest, e0 * 1.001) << "the total energy rose";
}

// Fig. 9 at its size: the water poured on the block soaks its foot from the pool, saturated
// pieces spall off it, and nothing gains energy. How many is not a stable figure: the cracks are
// threshold events, and a change of the fluid solve's summation order alone (its energy log
// equal to 9 digits at t = 0.2 s) took the run from 10 pieces created and 5 left to 1 created
// (bench/results/notes.md). So the test asks for a spall, and bounds the count loosely.
TEST(FractureScene, TheShippedSoakedBlockSpallsSaturatedPiecesWithoutGainingEnergy) {
    test::Simulation sim(
        test::read_text(std::string(KARST_SOURCE_DIR) + "/scenes/soaked_block.json"));
    const Real water0 = totals(sim.state.porous.particles).water;
    const Real e0 = total_mechanical_energy(sim);
    Real highest = e0;
    sim.run_until(sim.model.scene.time.end - 1e-9,
                  [&] { highest = std::max(highest, total_mechanical_energy(sim)); });
    EXPECT_LT(highest, e0 * 1.001) << "the total energy rose";
    const PorousParticles& p = sim.state.porous.particles;
    EXPECT_GT(totals(p).water - water0, 5.0) << "kg soaked in";
    const PoreWaterLaw& law = sim.model.pore_laws[0];
    const auto& fragments = sim.state.porous.fragments;
    std::vector<Real> saturation(fragments.size(), 0), members(fragments.size(), 0);
    for (Index i = 0; i < p.size(); ++i) {
        saturation[p.fragment[i]] += law.saturation(p.absorbed_mass[i], p.porosity[i], p.volume[i]);
        ++members[p.fragment[i]];
    }
    Index pieces = 0;
    for (size_t f = 0; f < fragments.size(); ++f) {
        if (fragments[f].anchored || members[f] == 0) continue;
        ++pieces;
        EXPECT_GT(saturation[f] / members[f], 0.95) << "fragment " << f << " is not soaked";
    }
    EXPECT_GE(pieces, 1) << "nothing spalled";
    EXPECT_LE(pieces, 40) << "crumbled";
}

}  // namespace

}  // namespace karst
