#include "karst/pfem/fracture_stage.hpp"

#include "karst/pfem/biot_setup.hpp"
#include "karst/pfem/cracks.hpp"
#include "karst/pfem/face_links.hpp"
#include "karst/pfem/mesh_split.hpp"
#include "karst/pfem/rigid_modes.hpp"
#include "karst/pfem/structure_stages.hpp"
#include "karst/rigid/fragment_motion.hpp"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <limits>

namespace karst {

namespace {

/// §5.6: copies sit this fraction of a spacing apart, so that a later Delaunay sees no
/// coincident points.
constexpr Real k_split_offset = 0.05;

/// [D] The smallest piece a crack may cut off, in tets: four lattice cells (a cell holds six).
/// Single tets chipped off by crossing crack disks became fragments of four particles that the
/// fluid blew out of the scene.
constexpr Index k_min_piece_tets = 24;

/// Appends a copy of particle i with id `id` (all attributes, then the id).
void append_copy(PorousParticles& p, Index i, Index id) {
    PorousParticles::for_each_attribute(
        [&](auto& attribute) {
            auto value = attribute[i];
            attribute.push_back(value);
        },
        p);
    p.id.back() = id;
}

/// The bedding normal at each node, from its tensor K0 (M12): the axis whose permeability is the
/// odd one out (the smallest when k along the layers exceeds k across, else the largest).
std::vector<Vec3> layer_normals(const std::vector<Mat3>& tensors, Real ratio) {
    std::vector<Vec3> normal(tensors.size(), Vec3::UnitZ());
    for (size_t a = 0; a < tensors.size(); ++a) {
        const Eigen::SelfAdjointEigenSolver<Mat3> eigen(tensors[a]);  // ascending
        normal[a] = eigen.eigenvectors().col(ratio >= 1 ? 0 : 2);
    }
    return normal;
}

/// Cracks structure `slot`; returns true when its mesh changed.
bool fracture_structure(const Model& model, State& state, size_t slot, Real time, int round) {
    StructureState& st = state.structures;
    PorousParticles& p = state.porous.particles;
    Structure& s = st.structures[slot];
    const PorousMaterial& material = model.scene.porous_solids[s.solid].material;
    const BiotProblem& problem = solver_of(model, state, slot).problem();
    const std::vector<Index> index_of = index_by_id(p, st.node_of.size());

    // The stress includes that of the rest state under the solid's weight: a crack or a loss of
    // support leaves it unbalanced, and a part the rest state held may then break off.
    NodalStress stress = nodal_stress(s.mesh, problem.material, fields_with_weight(st, s));
    // No crack starts at a node whose particle is gone, nor at an anchored node: the stress there
    // is the concentration of an idealised clamp, and a crack through the clamped layer would
    // leave both halves held.
    for (Index a = 0; a < s.mesh.node_count(); ++a)
        if (index_of[s.node_id[a]] < 0 || problem.fixed[a])
            stress.principal[a][0] = -std::numeric_limits<Real>::infinity();
    CrackSettings settings;
    settings.tensile_strength = material.tensile_strength;
    settings.fracture_energy = material.fracture_energy;
    settings.spacing = model.dx, settings.exclusion = model.h;
    settings.max_cracks = model.scene.fracture.max_cracks_per_call;
    settings.criterion = model.scene.fracture.criterion;
    settings.poisson_ratio = material.poisson_ratio;
    if (material.compressive_strength) {
        settings.compressive_strength = *material.compressive_strength;
        settings.friction_angle = material.friction_angle;
        const Vec3& g = model.scene.gravity;
        settings.down = g.norm() > 0 ? Vec3(g.normalized()) : Vec3::Zero();
    }
    settings.strength_scale = strength_scale(model, state, s, index_of);
    if (material.strength_across) {
        settings.strength_across = *material.strength_across;
        settings.layer_normal = layer_normals(s.node_tensors, material.layering_ratio);
    }
    // A crack whose disk cuts no unbroken link (the crack is already there) does not count.
    const std::vector<LinkGeometry> link_at = link_geometry(s.mesh, s.links);
    const auto cuts_something = [&](const Crack& c) {
        const std::vector<Index> cut = links_cut(link_at, std::span(&c, 1));
        return std::any_of(cut.begin(), cut.end(), [](Index k) { return k >= 0; });
    };
    std::vector<Crack> cracks = find_cracks(s.mesh, stress, s.node_id, settings, cuts_something);
    const std::vector<Index> cutter = links_cut(link_at, cracks);
    std::vector<Index> links_broken(cracks.size(), 0);
    std::vector<char> cut(cutter.size(), 0);
    for (size_t k = 0; k < cutter.size(); ++k) cut[k] = cutter[k] >= 0;
    // A small piece that a `fixed` constraint holds stays in the structure (the topology below):
    // it is no fragment, and sparing it left a body hanging from a stub by links no crack could
    // cut. One held only by a wall would fall free, so it is spared.
    const std::vector<std::uint8_t> constrained =
        constrained_axes(model, model.scene.porous_solids[s.solid], s.mesh);
    const auto stays_anchored = [&](std::span<const Index> tets) {
        std::vector<Vec3> held_x;
        std::vector<std::uint8_t> held_axes;
        std::vector<Index> nodes;
        for (Index e : tets)
            for (Index a : s.mesh.tets[e])
                if (constrained[a]) nodes.push_back(a);
        std::sort(nodes.begin(), nodes.end());
        nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
        for (Index a : nodes)
            held_x.push_back(s.mesh.nodes[a]), held_axes.push_back(constrained[a]);
        return holds_rigid_modes(held_x, held_axes);
    };
    spare_small_pieces(s.mesh.tet_count(), s.links, cut, k_min_piece_tets, stays_anchored);
    // §5.1.3's sliver volume, 1e-3 h_e^3 with h_e = dx.
    cut_sliver_bridges(s.mesh, s.links, cut, 1e-3 * std::pow(model.dx, 3));
    // Last, so that no cut above leaves a piece under the resolution.
    spare_small_pieces(s.mesh.tet_count(), s.links, cut, k_min_piece_tets, stays_anchored);
    for (size_t k = 0; k < cutter.size(); ++k)
        if (cut[k] && cutter[k] >= 0) ++links_broken[cutter[k]];
    const Index broken = Index(std::count(cut.begin(), cut.end(), 1));
    if (broken == 0) return false;

    // Record the cracks that cut something, and the damage of the particles on broken faces.
    for (size_t m = 0; m < cracks.size(); ++m) {
        const Crack& c = cracks[m];
        if (links_broken[m] == 0) continue;
        st.cracks.push_back({c.centre + s.fields.u[c.node], c.normal, c.radius, c.area, time,
                             links_broken[m], round});
        ++st.fracture.cracks;
    }
    st.fracture.links_broken += broken;
    for (size_t k = 0; k < cut.size(); ++k)
        if (cut[k])
            for (Index a : shared_nodes(s.mesh, s.links[k])) ++st.damage[s.node_id[a]];

    // M27: split the nodes, then carry the particles along.
    const MeshSplit split = split_mesh(s.mesh, s.links, cut, k_split_offset * model.dx);
    st.fracture.nodes_split += split.split_nodes;
    const Index n_old = s.mesh.node_count(), n_new = split.mesh.node_count();
    std::vector<Index> node_id(n_new);
    std::copy(s.node_id.begin(), s.node_id.end(), node_id.begin());
    for (Index k = n_old; k < n_new; ++k) node_id[k] = Index(state.next_id++);
    st.grow_ids(size_t(state.next_id));
    for (Index k = n_old; k < n_new; ++k) {
        const Index parent = s.node_id[split.source[k]], i = index_of[parent];
        if (i >= 0) append_copy(p, i, node_id[k]);
        st.damage[node_id[k]] = st.damage[parent],
        st.rest_tensor[node_id[k]] = st.rest_tensor[parent];
        st.paired_scale[node_id[k]] = st.paired_scale[parent];
        st.rest_volume[node_id[k]] = st.rest_volume[parent];
        st.paired_volume[node_id[k]] = st.paired_volume[parent];
        st.impulse[node_id[k]] = st.impulse[parent];
        st.weight_u[node_id[k]] = st.weight_u[parent];
    }
    const std::vector<Index> particle = index_by_id(p, st.node_of.size());
    // The mesh holds a node where it was before any split (below), rest_x where its particle
    // rests: a node split again keeps its earlier offsets.
    std::vector<Vec3> rest_before(n_old);
    for (Index a = 0; a < n_old; ++a) rest_before[a] = st.rest_x[s.node_id[a]];
    for (Index k = 0; k < n_new; ++k) {
        const Index id = node_id[k], a = split.source[k], i = particle[id];
        const Vec3 move = split.mesh.nodes[k] - s.mesh.nodes[a];
        const Real share = split.share[k];
        st.rest_x[id] = rest_before[a] + move, st.u[id] = s.fields.u[a];
        st.rest_volume[id] *= share, st.paired_volume[id] *= share, st.impulse[id] *= share;
        if (i < 0) continue;
        p.x[i] += move;
        p.volume[i] *= share, p.absorbed_mass[i] *= share, p.solid_mass[i] *= share;
    }

    // Topology: components held by a `fixed` constraint stay in the structure; every other
    // component becomes a free rigid fragment. A component is held when its fixed nodes hold all
    // six rigid modes (one anchored node is a hinge, and a hinged piece falls). [D] A wall only
    // pushes: with no constraint holding any component, the biggest one resting on a wall stays
    // (its clamp stands for the friction under a body), else the biggest; the pieces cut off it
    // rest on the wall by contact, so they can slide and topple.
    const auto held_components = [&](std::span<const std::uint8_t> fixed) {
        std::vector<std::vector<Vec3>> held_x(split.components);
        std::vector<std::vector<std::uint8_t>> held_axes(split.components);
        std::vector<char> seen(split.mesh.node_count(), 0);
        for (Index e = 0; e < split.mesh.tet_count(); ++e)
            for (Index k : split.mesh.tets[e])
                if (!seen[k] && fixed[split.source[k]])
                    seen[k] = 1, held_x[split.component[e]].push_back(split.mesh.nodes[k]),
                    held_axes[split.component[e]].push_back(fixed[split.source[k]]);
        std::vector<char> held(split.components, 0);
        for (Index c = 0; c < split.components; ++c)
            held[c] = holds_rigid_modes(held_x[c], held_axes[c]);
        return held;
    };
    std::vector<Index> tets_in(split.components, 0);
    for (Index e = 0; e < split.mesh.tet_count(); ++e) ++tets_in[split.component[e]];
    const auto biggest_of = [&](const std::vector<char>& among) {
        Index best = -1;
        for (Index c = 0; c < split.components; ++c)
            if (among[c] && (best < 0 || tets_in[c] > tets_in[best])) best = c;
        return best;
    };
    std::vector<char> anchored = held_components(constrained);
    if (biggest_of(anchored) < 0) {
        Index stays = biggest_of(held_components(problem.fixed));
        if (stays < 0) stays = biggest_of(std::vector<char>(split.components, 1));
        anchored[stays] = 1;
    }
    // A piece under the resolution that no cut of this call made stays too, as a piece the Biot
    // solve balances (biot_setup.hpp unheld_pieces): a remesh's drop of the tets across a crack
    // can leave a few tets beside it linked to nothing. Freed, each became a fragment of a few
    // grams that the fluid's pressure solve could not hold.
    for (Index c = 0; c < split.components; ++c)
        if (tets_in[c] < k_min_piece_tets) anchored[c] = 1;
    std::vector<char> keep(split.mesh.tet_count());
    for (Index e = 0; e < split.mesh.tet_count(); ++e) keep[e] = anchored[split.component[e]];

    std::vector<std::vector<Index>> members(split.components);
    std::vector<char> placed(n_new, 0);
    for (Index e = 0; e < split.mesh.tet_count(); ++e) {
        if (keep[e]) continue;
        for (Index k : split.mesh.tets[e])
            if (!placed[k] && particle[node_id[k]] >= 0)
                placed[k] = 1, members[split.component[e]].push_back(particle[node_id[k]]);
    }
    for (Index c = 0; c < split.components; ++c) {
        if (anchored[c] || members[c].empty()) continue;
        const Index f = Index(state.porous.fragments.size());
        // [D] The body's rigid field (M27) is zero: an anchored body does not move, its particles'
        // velocities only spread a quasi-static call's u over dt_B (sim/energy.cpp counts them
        // no kinetic energy). So a piece cut from it starts at rest; inheriting them gave an
        // arch's pieces more kinetic energy than its weight and elasticity had released.
        // [D] It starts in its undeformed shape X (a rigid body has no strain), moved by its
        // members' mass-weighted mean u, so its mass centre stays where it sagged to: on X alone
        // it rose by its sag, energy from nothing, and on X + u it kept a strained shape.
        Vec3 shift = Vec3::Zero();
        Real mass = 0;
        for (Index i : members[c]) {
            const Real m = p.solid_mass[i] + p.absorbed_mass[i];
            shift += m * (p.x[i] - st.rest_x[p.id[i]]), mass += m;
        }
        if (mass > 0) shift /= mass;
        for (Index i : members[c])
            p.fragment[i] = f, p.v[i] = Vec3::Zero(), p.x[i] = st.rest_x[p.id[i]] + shift;
        state.porous.fragments.push_back(free_fragment(p, members[c], model.dx));
        ++st.fracture.fragments_created;
    }

    // The structure keeps the anchored components, on their nodes (and the loose ones).
    std::vector<Index> node_of, tet_of;
    TetMesh mesh = sub_mesh(split.mesh, keep, true, node_of, tet_of);
    for (Index k = 0; k < n_new; ++k) st.node_of[node_id[k]] = {-1, -1};
    Structure next;
    next.fragment = s.fragment, next.solid = s.solid;
    next.mesh_version = st.next_mesh_version++;
    next.split_of_version = s.mesh_version;
    const Index n = mesh.node_count();
    next.split_source.resize(n);
    next.node_id.resize(n), next.fields.u.resize(n), next.fields.p.resize(n), next.u_from.resize(n);
    next.node_tensors.resize(n), next.permeability_scale.resize(n);
    for (Index a = 0; a < n; ++a) {
        const Index k = node_of[a], from = split.source[k];
        // [D] The mesh keeps each copy where its source was (the particles and rest_x take the
        // offset, for a later Delaunay): the elements keep their shapes, so a split leaves the
        // strain, stress and elastic energy of the carried u as they were, and the elasticity
        // is the old one with nodes duplicated, which the old factor solves (BiotSplitOf).
        next.split_source[a] = from;
        mesh.nodes[a] = s.mesh.nodes[from];
        next.node_id[a] = node_id[k];
        next.fields.u[a] = s.fields.u[from], next.fields.p[a] = s.fields.p[from];
        next.u_from[a] = s.u_from[from], next.node_tensors[a] = s.node_tensors[from];
        next.permeability_scale[a] = s.permeability_scale[from];
        st.node_of[node_id[k]] = {Index(slot), a};
    }
    std::vector<Index> new_tet(split.mesh.tet_count(), -1);
    for (size_t e = 0; e < tet_of.size(); ++e) new_tet[tet_of[e]] = Index(e);
    for (const ElementLink& l : split.links)
        if (new_tet[l.a] >= 0 && new_tet[l.b] >= 0)
            next.links.push_back(
                {std::min(new_tet[l.a], new_tet[l.b]), std::max(new_tet[l.a], new_tet[l.b])});
    next.well_shaped.resize(tet_of.size());
    for (size_t e = 0; e < tet_of.size(); ++e) next.well_shaped[e] = s.well_shaped[tet_of[e]];
    next.mesh = std::move(mesh);
    s = std::move(next);

    // The contact springs across what this call split take none of its offsets' load
    // (rigid/contact.hpp): neither between its pieces nor against the fragments around them.
    const std::vector<Vec3> after = contact_positions(state);
    std::vector<Vec3> before = after;
    std::vector<char> body(p.size(), 0), copy(p.size(), 0);
    for (Index k = 0; k < n_new; ++k)
        if (const Index i = particle[node_id[k]]; i >= 0)
            body[i] = 1, copy[i] = k >= n_old, before[i] = rest_before[split.source[k]];
    rest_after_split(state.porous.crack_contacts, p, state.porous.fragments,
                     {body, copy, before, after}, model.dx);
    return true;
}

}  // namespace

std::vector<Real> strength_scale(const Model& model, const State& state, const Structure& s,
                                 std::span<const Index> index_of) {
    const PorousMaterial& material = model.scene.porous_solids[s.solid].material;
    if (!material.tensile_strength_wet) return {};
    // [D] Water weakens rock and soil (wet sandstone keeps about half its strength; a soil loses
    // the cohesion its suction gave it): the strengths fall linearly with saturation to the wet
    // one at S = 1.
    const PorousParticles& p = state.porous.particles;
    const Real wet = *material.tensile_strength_wet / material.tensile_strength;
    const PoreWaterLaw& law = model.pore_laws[s.solid];
    std::vector<Real> scale(s.mesh.node_count(), 1);
    for (Index a = 0; a < s.mesh.node_count(); ++a)
        if (const Index i = index_of[s.node_id[a]]; i >= 0)
            scale[a] =
                1 + (wet - 1) * std::min<Real>(1, law.saturation(p.absorbed_mass[i], p.porosity[i],
                                                                 p.volume[i]));
    return scale;
}

bool fracture_structures(const Model& model, State& state, Real time, int round) {
    if (!model.scene.fracture.enabled) return false;
    bool changed = false;
    const size_t count = state.structures.structures.size();
    for (size_t slot = 0; slot < count; ++slot)
        changed = fracture_structure(model, state, slot, time, round) || changed;
    if (changed) refresh_fragment_mass(state, model.dx);
    return changed;
}

bool any_free_fragment(const State& state) {
    return std::any_of(state.porous.fragments.begin(), state.porous.fragments.end(),
                       [](const Fragment& f) { return !f.anchored && f.mass > 0; });
}

}  // namespace karst
