#include "karst/pfem/fragment_structure.hpp"

#include "karst/core/parallel.hpp"

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

struct FragmentStructures::Structure {
    Index slot = 0;  ///< its place in m_structures
    Index fragment = 0;
    const PorousSolid* solid = nullptr;
    std::vector<Index> node_id;  ///< particle id of each node
    TetMesh mesh;
    std::optional<BiotSolver> solver;
    BiotFields fields;
    std::vector<Mat3> node_tensors;     ///< K0 per node
    std::vector<Real> assembled_scale;  ///< per tet, for refresh_mobility
    std::vector<char> well_shaped;      ///< per tet: dihedral angles of at least 2 degrees at rest
    bool distorted = false;             ///< the last call left a distorted element: remesh before the next
    std::vector<Vec3> u_from;           ///< per node: u of the call before the last (the motion's start)
};

FragmentStructures::FragmentStructures(const Model& model, const PorousState& porous) {
    const PorousParticles& p = porous.particles;
    Index ids = 0;
    for (Index i = 0; i < p.size(); ++i) ids = std::max(ids, p.id[i] + 1);
    m_impulse.assign(ids, Vec3::Zero()), m_u.assign(ids, Vec3::Zero()), m_rest_tensor.assign(ids, Mat3::Zero());
    m_rest_x.assign(ids, Vec3::Zero()), m_node_of.assign(ids, {-1, -1});
    m_paired_scale.assign(ids, 1), m_paired_volume.assign(ids, 0);
    for (Index i = 0; i < p.size(); ++i) {
        const Index id = p.id[i];
        m_rest_tensor[id] = p.body_permeability[i], m_paired_volume[id] = p.volume[i];
        m_rest_x[id] = p.x[i];
    }
    for (size_t f = 0; f < porous.fragments.size(); ++f) {
        if (!porous.fragments[f].anchored || porous.fragments[f].mass <= 0) continue;
        // The fragment's solid: its members share one material.
        Index material = -1;
        for (Index i = 0; i < p.size() && material < 0; ++i)
            if (p.fragment[i] == Index(f)) material = p.material[i];
        const PorousSolid& solid = model.scene.porous_solids[material];
        if (solid.material.porosity < k_min_porosity) continue;  // impermeable: no pore pressure, a rigid boundary
        auto s = std::make_unique<Structure>();
        s->slot = Index(m_structures.size()), s->fragment = Index(f), s->solid = &solid;
        build(model, porous, *s);
        m_structures.push_back(std::move(s));
    }
}

FragmentStructures::~FragmentStructures() = default;

void FragmentStructures::build(const Model& model, const PorousState& porous, Structure& s) {
    // An anchored fragment never moves or turns, so its rest frame is the world frame: the mesh
    // lives at the particles' world rest positions X, where the scene's regions and walls are.
    const PorousParticles& p = porous.particles;
    std::vector<Vec3> x;
    s.node_id.clear();
    for (Index i = 0; i < p.size(); ++i)
        if (p.fragment[i] == s.fragment) x.push_back(m_rest_x[p.id[i]]), s.node_id.push_back(p.id[i]);
    s.solver.reset();  // it refers to the old mesh
    s.mesh = mesh_points(model, x, m_timings);
    for (size_t a = 0; a < x.size(); ++a) m_node_of[s.node_id[a]] = {s.slot, Index(a)};
    s.node_tensors.resize(x.size());
    s.fields.u.resize(x.size()), s.fields.p.assign(x.size(), 0);
    for (size_t a = 0; a < x.size(); ++a) s.node_tensors[a] = m_rest_tensor[s.node_id[a]], s.fields.u[a] = m_u[s.node_id[a]];
    s.u_from = s.fields.u;
    // [D] Geostatic start: a coupled fragment's rest state is its state at rest under its own
    // weight, so gravity (body force and gravity flux) leaves the problem and u, eps_v and p are
    // the response to the fluid's loads and to the pore overpressure P^p (M5, zero up to S = 1).
    // With gravity in, a resting block of E = 1 MPa soil consolidated under its own weight at
    // t = 0, and its porosity fell and its pore pressure rose before any water arrived. Biot is
    // linear, so dropping a constant load only shifts the reference state.
    BiotProblem problem = biot_problem(model, *s.solid, s.mesh, s.node_tensors);
    problem.gravity = Vec3::Zero();
    s.solver.emplace(make_biot_solver(model, s.mesh, std::move(problem), m_timings));
    s.assembled_scale.assign(s.mesh.tet_count(), 1);
    s.well_shaped.resize(s.mesh.tet_count());
    for (Index e = 0; e < s.mesh.tet_count(); ++e) {
        const Tet& t = s.mesh.tets[e];
        s.well_shaped[e] = min_dihedral_deg({x[t[0]], x[t[1]], x[t[2]], x[t[3]]}) >= k_distorted_dihedral_deg;
    }
}

bool FragmentStructures::distorted(const Structure& s) const {
    std::vector<Vec3> x(s.mesh.node_count());
    for (Index a = 0; a < s.mesh.node_count(); ++a) x[a] = s.mesh.nodes[a] + s.fields.u[a];
    for (Index e = 0; e < s.mesh.tet_count(); ++e) {
        if (!s.well_shaped[e]) continue;
        const Tet& t = s.mesh.tets[e];
        if (signed_volume(x[t[0]], x[t[1]], x[t[2]], x[t[3]]) <= 0 || min_dihedral_deg({x[t[0]], x[t[1]], x[t[2]], x[t[3]]}) < k_distorted_dihedral_deg)
            return true;
    }
    return false;
}

void FragmentStructures::add_loads(const PorousParticles& particles, const std::vector<Vec3>& force, Real dt) {
    parallel_for(particles.size(), [&](Index i) { m_impulse[particles.id[i]] += dt * force[i]; });
    m_elapsed += dt;
}

void FragmentStructures::follow_displacement(PorousParticles& p, Real fraction, Real dt_B) const {
    parallel_for(p.size(), [&](Index i) {
        const auto [slot, a] = m_node_of[p.id[i]];
        if (slot < 0) return;
        const Structure& s = *m_structures[slot];
        const Vec3 change = s.fields.u[a] - s.u_from[a];
        p.x[i] = m_rest_x[p.id[i]] + s.u_from[a] + fraction * change;
        p.v[i] = fraction < 1 ? Vec3(change / dt_B) : Vec3::Zero();
    });
}

bool FragmentStructures::advance(const Model& model, PorousState& porous) {
    if (m_structures.empty()) return false;
    const Real dt = m_elapsed, dt_B = model.scene.poroelastic.time_step;
    PorousParticles& p = porous.particles;
    // The particles move from X + u^{n-1} to X + u^n over the interval after the call that gave
    // u^n, at the velocity of that change [D]: set at once, a call's displacement moved the fluid's
    // boundary by up to 2 % of a spacing within one step (cave_soak), and that run took 440
    // steps to 0.5 s against 374 with the motion spread out. The pairs need no rebuild for it:
    // their conductances hold the distances between members, which change with the strain
    // (caught by the volume test below), not with the displacement; rebuilding them whenever a
    // particle had moved 1 % of a spacing cost 0.24 s each, ten times in cave_soak's first 0.5 s,
    // and changed its absorbed water by 3e-5 kg.
    follow_displacement(p, std::min<Real>(1, dt / dt_B), dt_B);
    if (dt < dt_B * (1 - 1e-9)) return false;
    std::vector<Index> index_of(m_impulse.size(), -1);
    for (Index i = 0; i < p.size(); ++i) index_of[p.id[i]] = i;
    bool stale = false;
    const bool feedback = model.scene.poroelastic.permeability_feedback;
    const Real rest_volume = model.dx * model.dx * model.dx;
    for (auto& owned : m_structures) {
        Structure& s = *owned;
        const Index n = s.mesh.node_count();
        Index lost = 0;
        for (Index a = 0; a < n; ++a) lost += index_of[s.node_id[a]] < 0;
        if (lost > k_remesh_lost_fraction * n) {
            for (Index a = 0; a < n; ++a) m_u[s.node_id[a]] = s.fields.u[a];
            build(model, porous, s);
            ++m_timings.remeshes;
        } else if (s.distorted) {
            // [D] A distorted mesh is rebuilt on the deformed positions, which become the new
            // rest state (u = 0 there): small-strain Biot cannot carry a deformation that inverts
            // elements, so the stress it held is released, as in a soil that has flowed.
            for (Index a = 0; a < n; ++a) m_rest_x[s.node_id[a]] += s.fields.u[a], m_u[s.node_id[a]] = Vec3::Zero();
            build(model, porous, s);
            ++m_timings.remeshes;
        }
        // Loads: the mean force since the last call (§5.3); p^n <- P^p (M5) from the pore water,
        // or the Biot pressure carried from the last call (/poroelastic/pressure_source biot).
        const PoreWaterLaw& law = model.pore_laws[s.solid - model.scene.porous_solids.data()];
        const bool from_pore_water = model.scene.poroelastic.pressure_from_pore_water;
        std::vector<Vec3> loads(s.mesh.node_count(), Vec3::Zero());
        for (Index a = 0; a < s.mesh.node_count(); ++a) {
            const Index i = index_of[s.node_id[a]];
            if (i < 0) continue;
            loads[a] = m_impulse[s.node_id[a]] / dt;
            if (from_pore_water) s.fields.p[a] = law.pore_pressure(law.saturation(p.absorbed_mass[i], p.porosity[i], p.volume[i]));
        }
        s.solver->set_extra_loads(loads);
        s.u_from = s.fields.u;  // where the particles are now
        const BiotCallReport r = s.solver->advance(dt, s.fields);
        m_timings.factorisation += r.seconds_flow_factorisation, m_timings.iterations += r.seconds_iterations;
        ++m_timings.biot_calls, m_timings.biot_iterations += r.iterations;
        m_timings.all_converged = m_timings.all_converged && r.converged;
        s.distorted = distorted(s);
        if (!feedback) continue;
        // Feedback (§5.4): porosity, bulk volume V = V0 (1 + eps_v) and K = (k/k0) R K0 R^T.
        const NodalStress stress = nodal_stress(s.mesh, s.solver->problem().material, s.fields);
        const NodalPoreState pore = nodal_pore_state(s.solid->material, s.solver->problem().material, stress, s.fields.p);
        const Mat3 R = porous.fragments[s.fragment].rotation_matrix();
        for (Index a = 0; a < s.mesh.node_count(); ++a) {
            const Index i = index_of[s.node_id[a]];
            if (i < 0) continue;
            p.porosity[i] = pore.porosity[a];
            p.volume[i] = rest_volume * (1 + stress.volumetric_strain[a]);
            p.body_permeability[i] = pore.permeability_scale[a] * s.node_tensors[a];
            p.permeability[i] = R * p.body_permeability[i] * R.transpose();
            const Index id = s.node_id[a];
            stale = stale || std::abs(pore.permeability_scale[a] / m_paired_scale[id] - 1) > 0.01 ||
                    std::abs(p.volume[i] / m_paired_volume[id] - 1) > 0.01;
        }
        refresh_mobility(*s.solver, s.mesh, s.solid->material, s.node_tensors, pore.permeability_scale, s.assembled_scale);
    }
    std::fill(m_impulse.begin(), m_impulse.end(), Vec3::Zero());
    m_elapsed = 0;
    if (stale)
        for (Index i = 0; i < p.size(); ++i)
            m_paired_scale[p.id[i]] = p.body_permeability[i].trace() / m_rest_tensor[p.id[i]].trace(), m_paired_volume[p.id[i]] = p.volume[i];
    return stale;
}

void FragmentStructures::append_to(MeshFrame& frame) const {
    for (const auto& s : m_structures)
        append_mesh_frame(frame, s->mesh, s->solver->problem(), s->fields, s->solid->material, s->node_tensors);
}

Index FragmentStructures::elements() const {
    Index n = 0;
    for (const auto& s : m_structures) n += s->mesh.tet_count();
    return n;
}

}  // namespace karst
