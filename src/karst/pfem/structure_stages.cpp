#include "karst/pfem/structure_stages.hpp"

#include "karst/core/check.hpp"
#include "karst/core/parallel.hpp"
#include "karst/pfem/biot_setup.hpp"
#include "karst/pfem/face_links.hpp"
#include "karst/pfem/fracture_stage.hpp"
#include "karst/pfem/mesh_split.hpp"
#include "karst/scene/wall_crossing.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <limits>
#include <optional>

namespace karst {

namespace {

/// A fragment is remeshed once it has lost this fraction of its nodes (to dissolution or the
/// domain) [D]: the sheet remeshes at every topology event (§4.10), but an eroding rock loses a
/// few grains at most steps, and each remesh refactorises the elasticity. Until then the lost
/// nodes keep their stiffness and take no load.
constexpr Real k_remesh_lost_fraction = 0.01;

/// §4.10: a deformed element with a dihedral angle under this many degrees (or inverted) triggers
/// a remesh. Interior slivers that were under it at rest (tet_mesh.hpp) do not count.
constexpr Real k_distorted_dihedral_deg = 2;

}  // namespace

namespace {

/// Per node of structure s, the value of its particle id in the per-id array `by_id`.
std::vector<Vec3> node_values(const std::vector<Vec3>& by_id, const Structure& s) {
    std::vector<Vec3> values(s.node_id.size());
    for (size_t a = 0; a < s.node_id.size(); ++a) values[a] = by_id[s.node_id[a]];
    return values;
}

/// The weight of each node's particle, its solid and its pore water (N); a node whose particle
/// is gone weighs nothing.
std::vector<Vec3> node_weights(const Model& model, const State& state, const Structure& s,
                               const std::vector<Index>& index_of) {
    const PorousParticles& p = state.porous.particles;
    std::vector<Vec3> weight(s.node_id.size(), Vec3::Zero());
    for (size_t a = 0; a < s.node_id.size(); ++a)
        if (const Index i = index_of[s.node_id[a]]; i >= 0)
            weight[a] = (p.solid_mass[i] + p.absorbed_mass[i]) * model.scene.gravity;
    return weight;
}

}  // namespace

BiotFields fields_with_weight(const StructureState& st, const Structure& s) {
    BiotFields fields = s.fields;
    for (size_t a = 0; a < fields.u.size(); ++a) fields.u[a] += st.weight_u[s.node_id[a]];
    return fields;
}

BiotSolver& solver_of(const Model& model, State& state, size_t slot) {
    Structure& s = state.structures.structures[slot];
    if (BiotCache::Entry* e = state.biot_cache.find(slot, s.mesh_version)) return *e->solver;
    const PorousSolid& solid = model.scene.porous_solids[s.solid];
    BiotProblem problem = biot_problem(model, solid, s.mesh, s.node_tensors);
    // [D] Geostatic start in a coupled run: a fragment's rest state is its state at rest under
    // its own weight, so u, eps_v and p are measured from it. With gravity in the problem, a
    // resting block of E = 1 MPa soil consolidated under its own weight at t = 0, and its
    // porosity fell and its pore pressure rose before any water arrived. So gravity (body force
    // and gravity flux) leaves the problem; the weight comes back as the particles' weight
    // (solid and pore water) in each call's loads, held by the rest state's elastic forces
    // K u_rest: they cancel while nothing changes, and what is left is the weight of the water
    // absorbed since, of material dissolved, or the load a crack or a lost support no longer
    // carries. A poroelastic-only solid keeps gravity: consolidation under its weight is what
    // it shows.
    const bool coupled = !model.poroelastic_only();
    if (coupled) problem.gravity = Vec3::Zero();
    std::optional<BiotSplitOf> split_of;
    if (BiotCache::Entry* older =
            s.split_of_version >= 0 ? state.biot_cache.find(slot, s.split_of_version) : nullptr)
        split_of.emplace(BiotSplitOf{*older->solver, s.split_source});
    BiotSolver solver = make_biot_solver(model, s.mesh, std::move(problem),
                                         state.structures.timings, split_of ? &*split_of : nullptr);
    s.split_of_version = -1, s.split_source.clear();
    BiotCache::Entry& e = state.biot_cache.reset(slot);
    e.solver.emplace(std::move(solver));
    e.mesh_version = s.mesh_version;
    if (coupled) e.solver->set_rest_displacement(node_values(state.structures.weight_u, s));
    // The flow matrix the run was using: a new mesh starts from the problem's (scale 1); a solver
    // rebuilt for a mesh it had already (a resumed run) takes the scales it was assembled with.
    if (s.mobility_scale.size() != size_t(s.mesh.tet_count()))
        s.mobility_scale.assign(s.mesh.tet_count(), 1);
    else if (std::any_of(s.mobility_scale.begin(), s.mobility_scale.end(),
                         [](Real k) { return k != 1; }))
        assemble_mobility(*e.solver, s.mesh, solid.material, s.node_tensors, s.mobility_scale);
    refresh_mobility(*e.solver, s.mesh, solid.material, s.node_tensors, s.permeability_scale,
                     s.mobility_scale);
    if (s.flow_time_step > 0) e.solver->set_flow_time_step(s.flow_time_step);
    return *e.solver;
}

namespace {

/// Whether a crack has broken a face of the structure's mesh.
bool cracked(const StructureState& st, const Structure& s) {
    return std::any_of(s.node_id.begin(), s.node_id.end(),
                       [&](Index id) { return st.damage[id] > 0; });
}

/// Meshes structure `slot` on the rest positions of its fragment's present particles; u is
/// carried per particle id, p starts at the drained pressure where drained and 0 elsewhere.
/// With `new_rest_state` (a coupled run), the rest state is the new mesh standing under its
/// particles' weight; otherwise each particle keeps its own (weight_u).
void build(const Model& model, State& state, size_t slot, bool new_rest_state) {
    StructureState& st = state.structures;
    Structure& s = st.structures[slot];
    const PorousParticles& p = state.porous.particles;
    s.node_id.clear();
    for (Index i = 0; i < p.size(); ++i)
        if (p.fragment[i] == s.fragment) s.node_id.push_back(p.id[i]);
    // Nodes in the lexicographic order of their rest positions: the mesh (and every crack on it)
    // does not depend on the order of the particles.
    std::sort(s.node_id.begin(), s.node_id.end(), [&](Index a, Index b) {
        const Vec3 &xa = st.rest_x[a], &xb = st.rest_x[b];
        return std::lexicographical_compare(xa.begin(), xa.end(), xb.begin(), xb.end());
    });
    std::vector<Vec3> x;
    for (Index id : s.node_id) x.push_back(st.rest_x[id]);
    // A remesh of a cracked body keeps its cracks: the old mesh says which nodes were apart.
    std::vector<Index> old_node(s.node_id.size(), -1);
    std::vector<char> on_crack(s.node_id.size(), 0);
    for (size_t a = 0; a < s.node_id.size(); ++a) {
        const Index id = s.node_id[a];
        if (st.node_of[id].first == Index(slot)) old_node[a] = st.node_of[id].second;
        on_crack[a] = st.damage[id] > 0;
    }
    const TetMesh old_mesh = std::move(s.mesh);
    const std::vector<ElementLink> old_links = std::move(s.links);
    s.mesh = mesh_points(model, x, st.timings);
    if (cracked(st, s)) {
        keep_old_tets(s.mesh, old_mesh, old_node);
        drop_tets_across_cracks(s.mesh, old_mesh, old_links, old_node, on_crack);
    }
    s.mesh_version = st.next_mesh_version++;
    s.mobility_scale.clear(), s.flow_time_step = -1;  // a new mesh's solver starts afresh
    s.split_of_version = -1, s.split_source.clear();
    s.links = face_links(s.mesh);
    const Index n = s.mesh.node_count();
    s.node_tensors.resize(n), s.fields.u.resize(n), s.fields.p.assign(n, 0),
        s.permeability_scale.assign(n, 1);
    for (Index a = 0; a < n; ++a) {
        const Index id = s.node_id[a];
        st.node_of[id] = {Index(slot), a};
        s.node_tensors[a] = st.rest_tensor[id], s.fields.u[a] = st.u[id];
    }
    s.u_from = s.fields.u;
    s.distorted = false, s.grown = false;
    BiotSolver& solver = solver_of(model, state, slot);
    if (new_rest_state && !model.poroelastic_only()) {
        const std::vector<Vec3> u_rest = solver.drained_displacement(
            node_weights(model, state, s, index_by_id(state.porous.particles, st.u.size())));
        for (Index a = 0; a < n; ++a) st.weight_u[s.node_id[a]] = u_rest[a];
        solver.set_rest_displacement(u_rest);
    }
    const BiotProblem& problem = solver.problem();
    for (Index a = 0; a < n; ++a)
        if (problem.drained[a])
            s.fields.p[a] = problem.drained_pressure.empty() ? 0 : problem.drained_pressure[a];
    s.well_shaped.resize(s.mesh.tet_count());
    for (Index e = 0; e < s.mesh.tet_count(); ++e) {
        const Tet& t = s.mesh.tets[e];
        s.well_shaped[e] =
            min_dihedral_deg({x[t[0]], x[t[1]], x[t[2]], x[t[3]]}) >= k_distorted_dihedral_deg;
    }
}

bool distorted(const Structure& s) {
    std::vector<Vec3> x(s.mesh.node_count());
    for (Index a = 0; a < s.mesh.node_count(); ++a) x[a] = s.mesh.nodes[a] + s.fields.u[a];
    for (Index e = 0; e < s.mesh.tet_count(); ++e) {
        if (!s.well_shaped[e]) continue;
        const Tet& t = s.mesh.tets[e];
        if (signed_volume(x[t[0]], x[t[1]], x[t[2]], x[t[3]]) <= 0 ||
            min_dihedral_deg({x[t[0]], x[t[1]], x[t[2]], x[t[3]]}) < k_distorted_dihedral_deg)
            return true;
    }
    return false;
}

}  // namespace

void build_structures(const Model& model, State& state) {
    StructureState& st = state.structures;
    const PorousParticles& p = state.porous.particles;
    size_t ids = 0;
    for (Index i = 0; i < p.size(); ++i) ids = std::max<size_t>(ids, size_t(p.id[i]) + 1);
    st.grow_ids(ids);
    for (Index i = 0; i < p.size(); ++i) {
        const Index id = p.id[i];
        st.rest_tensor[id] = p.body_permeability[i], st.paired_volume[id] = p.volume[i],
        st.rest_volume[id] = p.volume[i], st.rest_x[id] = p.x[i];
    }
    if (model.coupled() && !model.scene.poroelastic.coupled_fragments) return;
    const std::vector<Fragment>& fragments = state.porous.fragments;
    for (size_t f = 0; f < fragments.size(); ++f) {
        if (!fragments[f].anchored || fragments[f].mass <= 0) continue;
        Index material = -1;  // the fragment's solid: its members share one material
        for (Index i = 0; i < p.size() && material < 0; ++i)
            if (p.fragment[i] == Index(f)) material = p.material[i];
        if (model.scene.porous_solids[material].material.porosity < k_min_porosity)
            continue;  // a rigid boundary
        Structure s;
        s.fragment = Index(f), s.solid = material;
        st.structures.push_back(std::move(s));
        build(model, state, st.structures.size() - 1, true);
    }
}

void add_structure_loads(State& state, Real dt) {
    StructureState& st = state.structures;
    if (st.empty()) return;
    const PorousParticles& p = state.porous.particles;
    const std::vector<Vec3>& force = state.porous_scratch.force;
    parallel_for(p.size(), [&](Index i) { st.impulse[p.id[i]] += dt * force[i]; });
    st.elapsed += dt;
}

void follow_structure_displacement(const Model& model, State& state) {
    const StructureState& st = state.structures;
    if (st.empty()) return;
    // [D] Spread over the interval after the call that gave u^n: set at once, a call's
    // displacement moved the fluid's boundary by up to 2 % of a spacing within one step. The
    // pore-flow pairs need no rebuild for it: their conductances hold the distances between
    // members, which change with the strain (feed_back_structures), not with the displacement.
    const Real dt_B = model.scene.poroelastic.time_step,
               fraction = std::min<Real>(1, st.elapsed / dt_B);
    PorousParticles& p = state.porous.particles;
    parallel_for(p.size(), [&](Index i) {
        const auto [slot, a] = st.node_of[p.id[i]];
        if (slot < 0) return;
        const Structure& s = st.structures[slot];
        const Vec3 change = s.fields.u[a] - s.u_from[a];
        p.x[i] = st.rest_x[p.id[i]] + s.u_from[a] + fraction * change;
        p.v[i] = fraction < 1 ? Vec3(change / dt_B) : Vec3::Zero();
        // [D] Biot has no contact with the walls: a displacement over a spacing (a very soft or
        // badly connected member) can carry a member through one. It stops at the wall instead.
        push_back_through_walls(model.scene.walls, model.dx, p.x[i], p.v[i]);
    });
}

bool biot_call_due(const Model& model, const State& state) {
    return !state.structures.empty() &&
           state.structures.elapsed >= model.scene.poroelastic.time_step * (1 - 1e-9);
}

Real time_to_next_biot_call(const Model& model, const State& state) {
    if (state.structures.empty()) return std::numeric_limits<Real>::infinity();
    return model.scene.poroelastic.time_step - state.structures.elapsed;
}

void remesh_structures(const Model& model, State& state) {
    StructureState& st = state.structures;
    const std::vector<Index> index_of = index_by_id(state.porous.particles, st.node_of.size());
    for (size_t slot = 0; slot < st.structures.size(); ++slot) {
        Structure& s = st.structures[slot];
        const Index n = s.mesh.node_count();
        Index lost = 0;
        for (Index a = 0; a < n; ++a) lost += index_of[s.node_id[a]] < 0;
        bool new_rest_state = false;
        if (lost > k_remesh_lost_fraction * n) {
            for (Index a = 0; a < n; ++a) st.u[s.node_id[a]] = s.fields.u[a];
        } else if (s.grown) {
            for (Index a = 0; a < n; ++a) st.u[s.node_id[a]] = s.fields.u[a];
        } else if (s.distorted && !cracked(st, s)) {
            // A cracked body keeps its mesh: a remesh keeps its old tets (build), and on the
            // deformed positions as a new rest state those are the distorted ones.
            new_rest_state = true;
            // [D] A distorted mesh is rebuilt on the deformed positions, which become the new
            // rest state (u = 0 there): small-strain Biot cannot carry a deformation that inverts
            // elements, so the stress it held is released, as in a soil that has flowed.
            // Where a wall stopped a member (follow_structure_displacement), the rest state is
            // where it stopped.
            for (Index a = 0; a < n; ++a) {
                const Index id = s.node_id[a], i = index_of[id];
                st.rest_x[id] =
                    i >= 0 ? state.porous.particles.x[i] : st.rest_x[id] + s.fields.u[a];
                st.u[id] = Vec3::Zero();
            }
        } else {
            continue;
        }
        const Index tets_before = s.mesh.tet_count();
        build(model, state, slot, new_rest_state);
        ++st.timings.remeshes;
        // A distorted body rebuilt on its deformed positions that no longer forms a single
        // tetrahedron was spread apart by a load the material could not carry: without
        // elements it would go on silently. (A body that lost nodes keeps its lattice rest
        // positions; a last flat layer of a dissolving block may rightly have no element.)
        const Structure& rebuilt = st.structures[slot];
        if (new_rest_state && tets_before > 0 && rebuilt.mesh.tet_count() == 0)
            throw NumericalFailure(fmt::format(
                "the remesh of a structure of {} nodes found no tetrahedra: its particles were "
                "spread apart by a load far beyond what the material carries",
                rebuilt.mesh.node_count()));
    }
}

void solve_structures(const Model& model, State& state, Real time, bool again) {
    StructureState& st = state.structures;
    const PorousParticles& p = state.porous.particles;
    const std::vector<Index> index_of = index_by_id(p, st.node_of.size());
    const Real dt = st.elapsed;
    const bool from_pore_water = model.scene.poroelastic.pressure_from_pore_water;
    for (size_t slot = 0; slot < st.structures.size(); ++slot) {
        Structure& s = st.structures[slot];
        BiotSolver& solver = solver_of(model, state, slot);
        const PoreWaterLaw& law = model.pore_laws[s.solid];
        const std::vector<char>& drained = solver.problem().drained;
        // In a coupled run, the weight against the rest state's K u_rest (solver_of).
        std::vector<Vec3> loads = model.poroelastic_only()
                                      ? std::vector<Vec3>(s.mesh.node_count(), Vec3::Zero())
                                      : node_weights(model, state, s, index_of);
        for (Index a = 0; a < s.mesh.node_count(); ++a) {
            const Index i = index_of[s.node_id[a]];
            if (i < 0) continue;
            loads[a] += st.impulse[s.node_id[a]] / dt;
            if (from_pore_water && !drained[a])
                s.fields.p[a] = law.pore_pressure(
                    law.saturation(p.absorbed_mass[i], p.porosity[i], p.volume[i]));
        }
        if (has_time_table(model.scene.porous_solids[s.solid])) {
            // Backward Euler: the boundary values at the end of the call's interval.
            const BoundaryValues b =
                boundary_values(model, model.scene.porous_solids[s.solid], s.mesh, time);
            solver.set_boundary_values(b.nodal_force, b.prescribed_u, b.drained_pressure);
            for (Index a = 0; a < s.mesh.node_count(); ++a)
                if (drained[a]) s.fields.p[a] = b.drained_pressure[a];
        }
        solver.set_extra_loads(loads);
        // Where the particles are now: X + u of the last call, or short of it when this call
        // comes early (again at once after a fracture).
        for (Index a = 0; a < s.mesh.node_count(); ++a) {
            const Index i = index_of[s.node_id[a]];
            s.u_from[a] = i >= 0 ? Vec3(p.x[i] - st.rest_x[s.node_id[a]]) : s.fields.u[a];
        }
        const BiotCallReport r = solver.advance(dt, s.fields);
        s.support_force = solver.support_forces(s.fields);
        s.flow_time_step = solver.flow_time_step();
        st.timings.factorisation += r.seconds_flow_factorisation,
            st.timings.iterations += r.seconds_iterations;
        ++(again ? st.timings.repeated_calls : st.timings.biot_calls);
        st.timings.biot_iterations += r.iterations;
        st.timings.unconverged_calls += !r.converged;
        s.distorted = distorted(s);
    }
}

Real largest_call_displacement(const State& state) {
    Real largest = 0;
    for (const Structure& s : state.structures.structures)
        for (size_t a = 0; a < s.fields.u.size(); ++a)
            largest = std::max(largest, (s.fields.u[a] - s.u_from[a]).norm());
    return largest;
}

void end_biot_call(State& state) {
    StructureState& st = state.structures;
    std::fill(st.impulse.begin(), st.impulse.end(), Vec3::Zero());
    st.elapsed = 0;
}

void release_split_solvers(State& state) {
    for (size_t slot = 0; slot < state.structures.structures.size(); ++slot) {
        const BiotCache::Entry* e =
            state.biot_cache.find(slot, state.structures.structures[slot].mesh_version);
        if (e && e->solver->elastic_split_unknowns() > 0) state.biot_cache.reset(slot);
    }
}

bool feed_back_structures(const Model& model, State& state) {
    if (!model.scene.poroelastic.permeability_feedback) return false;
    StructureState& st = state.structures;
    PorousParticles& p = state.porous.particles;
    const std::vector<Index> index_of = index_by_id(p, st.node_of.size());
    bool stale = false;
    for (size_t slot = 0; slot < st.structures.size(); ++slot) {
        Structure& s = st.structures[slot];
        BiotSolver& solver = solver_of(model, state, slot);
        const PorousMaterial& material = model.scene.porous_solids[s.solid].material;
        const NodalStress stress = nodal_stress(s.mesh, solver.problem().material, s.fields);
        const NodalPoreState pore =
            nodal_pore_state(material, solver.problem().material, stress, s.fields.p);
        const Mat3 R = state.porous.fragments[s.fragment].rotation_matrix();
        for (Index a = 0; a < s.mesh.node_count(); ++a) {
            const Index i = index_of[s.node_id[a]];
            if (i < 0) continue;
            p.porosity[i] = pore.porosity[a];
            p.volume[i] = st.rest_volume[s.node_id[a]] * (1 + stress.volumetric_strain[a]);
            p.body_permeability[i] = pore.permeability_scale[a] * s.node_tensors[a];
            p.permeability[i] = R * p.body_permeability[i] * R.transpose();
            const Index id = s.node_id[a];
            stale = stale ||
                    std::abs(pore.permeability_scale[a] / st.paired_scale[id] - 1) > 0.01 ||
                    std::abs(p.volume[i] / st.paired_volume[id] - 1) > 0.01;
        }
        s.permeability_scale = pore.permeability_scale;
        refresh_mobility(solver, s.mesh, material, s.node_tensors, s.permeability_scale,
                         s.mobility_scale);
    }
    if (stale)
        for (Index i = 0; i < p.size(); ++i)
            st.paired_scale[p.id[i]] =
                p.body_permeability[i].trace() / st.rest_tensor[p.id[i]].trace(),
            st.paired_volume[p.id[i]] = p.volume[i];
    return stale;
}

void append_structure_meshes(const Model& model, State& state, MeshFrame& frame) {
    const std::vector<Index> index_of =
        index_by_id(state.porous.particles, state.structures.node_of.size());
    for (size_t slot = 0; slot < state.structures.structures.size(); ++slot) {
        const Structure& s = state.structures.structures[slot];
        append_mesh_frame(frame, s.mesh, solver_of(model, state, slot).problem(), s.fields,
                          fields_with_weight(state.structures, s), s.support_force,
                          model.scene.porous_solids[s.solid].material, s.node_tensors,
                          model.scene.poroelastic.permeability_feedback,
                          strength_scale(model, state, s, index_of));
    }
}

std::vector<SupportLog> structure_supports(const Model& model, const State& state, Real time) {
    std::vector<SupportLog> rows;
    for (const Structure& s : state.structures.structures) {
        const PorousSolid& solid = model.scene.porous_solids[s.solid];
        for (SupportLog& l : support_loads(model, solid, s.mesh, s.fields, s.support_force, time)) {
            l.solid = s.solid;
            auto same = std::find_if(rows.begin(), rows.end(), [&](const SupportLog& r) {
                return r.solid == l.solid && r.constraint == l.constraint;
            });
            if (same == rows.end()) {
                rows.push_back(std::move(l));
                continue;
            }
            const Index nodes = same->nodes + l.nodes;
            if (nodes > 0)
                same->displacement =
                    (Real(same->nodes) * same->displacement + Real(l.nodes) * l.displacement) /
                    Real(nodes);
            if (l.kind != "platen") same->force += l.force;  // a platen's force is its own
            same->nodes = nodes;
        }
    }
    std::sort(rows.begin(), rows.end(), [](const SupportLog& a, const SupportLog& b) {
        return std::pair(a.solid, a.constraint < 0 ? Index(1) << 40 : a.constraint) <
               std::pair(b.solid, b.constraint < 0 ? Index(1) << 40 : b.constraint);
    });
    return rows;
}

MeshQuality structure_mesh_quality(const State& state) {
    MeshQuality q;
    for (const Structure& s : state.structures.structures) {
        const MeshQuality& m = s.mesh.quality;
        q.delaunay_cells += m.delaunay_cells, q.kept += m.kept, q.elements += m.elements;
        q.slivers_dropped += m.slivers_dropped, q.interior_slivers += m.interior_slivers,
            q.polyhedra += m.polyhedra;
        q.joined_polyhedra += m.joined_polyhedra, q.volume += m.volume;
    }
    return q;
}

}  // namespace karst
