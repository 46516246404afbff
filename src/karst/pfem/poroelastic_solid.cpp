#include "karst/pfem/poroelastic_solid.hpp"

#include "karst/core/timer.hpp"
#include "karst/pfem/nodal_stress.hpp"
#include "karst/pfem/porosity.hpp"
#include "karst/porous/permeability.hpp"
#include "karst/porous/porous_points.hpp"
#include "karst/sim/porous_materials.hpp"
#include "karst/sph/kernels.hpp"


namespace karst {

namespace {

TetMesh mesh_body(const Model& model, const PorousBody& body, PfemTimings& timings) {
    Stopwatch watch;
    const PoroelasticSettings& pe = model.scene.poroelastic;
    MeshOptions options;
    options.alpha = pe.alpha, options.join_delta = pe.join_delta, options.weighted = pe.weighted_alpha;
    const std::vector<Real> size(body.rest_x.size(), model.dx);
    // Weighted variant (method.md §5.1): w = (omega_S S + omega_m m/m_bar) (dx/2)^2 with a
    // saturated, uniform-mass solid until the pore state arrives (issue 3): S = 1, m = m_bar.
    const std::vector<Real> weights(options.weighted ? body.rest_x.size() : 0, (1.0 + 0.2) * 0.25 * model.dx * model.dx);
    TetMesh mesh = build_tet_mesh(body.rest_x, size, options, weights);
    timings.meshing += watch.seconds();
    return mesh;
}

/// Mean of a tet's nodal tensors.
Mat3 tet_mean(const Tet& t, const std::vector<Mat3>& nodal) { return 0.25 * (nodal[t[0]] + nodal[t[1]] + nodal[t[2]] + nodal[t[3]]); }

BiotMaterial biot_material(const Model& model, const PorousMaterial& m) {
    BiotMaterial b;
    b.youngs_modulus = m.youngs_modulus, b.poisson_ratio = m.poisson_ratio, b.biot_coefficient = m.biot_coefficient;
    // 1/M = phi/K_f + (B - phi)/K_s (method.md §5.3).
    b.storage = m.porosity / model.scene.poroelastic.fluid_bulk_modulus + (m.biot_coefficient - m.porosity) / b.grain_bulk_modulus();
    b.fluid_density = model.rho0;
    b.bulk_density = (1 - m.porosity) * m.solid_density + m.porosity * model.rho0;  // saturated
    return b;
}

BiotProblem biot_problem(const Model& model, const PorousSolid& solid, const TetMesh& mesh, const std::vector<Mat3>& body_tensors) {
    BiotProblem p;
    p.material = biot_material(model, solid.material);
    p.gravity = model.scene.gravity;
    p.mobility.resize(mesh.tet_count());
    for (Index e = 0; e < mesh.tet_count(); ++e) p.mobility[e] = tet_mean(mesh.tets[e], body_tensors) / solid.material.darcy_viscosity;
    const Index n = mesh.node_count();
    p.fixed.assign(n, 0), p.drained.assign(n, 0), p.drained_pressure.assign(n, 0), p.nodal_force.assign(n, Vec3::Zero());
    // A node is on a region when inside it or within 3/4 of a spacing: the outer particle layer
    // sits half a spacing inside the geometry, the next one 1.5 spacings.
    const Real reach = 0.75 * model.dx;
    for (const Constraint& c : solid.constraints) {
        auto inside = [&](const Vec3& x) { return c.region.signed_distance(x) <= reach; };
        if (c.kind == Constraint::Kind::Traction) {
            const auto loads = traction_loads(mesh, c.traction, inside);
            for (Index a = 0; a < n; ++a) p.nodal_force[a] += loads[a];
            continue;
        }
        for (Index a = 0; a < n; ++a) {
            if (!inside(mesh.nodes[a])) continue;
            if (c.kind == Constraint::Kind::Fixed) p.fixed[a] |= c.axes;
            else p.drained[a] = 1, p.drained_pressure[a] = c.pressure;
        }
    }
    // Nodes touching a static wall (within a spacing of its particle skin) are anchored, u = 0
    // (method.md §5.3): a block resting on the ground is held by it.
    for (const Wall& w : model.scene.walls)
        for (Index a = 0; a < n; ++a) {
            const Real d = w.shape.signed_distance(mesh.nodes[a]);
            if (w.kind == Wall::Kind::Obstacle ? d <= model.dx : d >= -model.dx) p.fixed[a] = FixAll;
        }
    p.free_body = std::all_of(p.fixed.begin(), p.fixed.end(), [](std::uint8_t f) { return f == 0; });
    return p;
}

/// Appends the arrays of `local` to those of `into` (by name), creating them for the first solid.
void append_arrays(PointSet& into, const PointSet& local) {
    for (const PointArray& array : local.arrays) {
        auto it = std::find_if(into.arrays.begin(), into.arrays.end(), [&](const PointArray& a) { return a.name == array.name; });
        if (it == into.arrays.end()) {
            into.arrays.push_back({array.name, array.components, array.integer, {}});
            it = std::prev(into.arrays.end());
        }
        it->values.insert(it->values.end(), array.values.begin(), array.values.end());
    }
}

BiotSolver make_solver(const Model& model, const PorousBody& body, const TetMesh& mesh, const std::vector<Mat3>& body_tensors,
                       PfemTimings& timings) {
    const PoroelasticSettings& pe = model.scene.poroelastic;
    BiotOptions options;
    options.splitting = pe.fixed_strain ? Splitting::FixedStrain : Splitting::FixedStress;
    options.max_iterations = pe.max_iterations, options.tolerance = pe.tolerance;
    options.polyhedral = pe.mfem_polyhedra;
    options.linear_solver = pe.amg ? LinearSolver::Amg : LinearSolver::Direct;
    BiotSolver solver(mesh, biot_problem(model, model.scene.porous_solids[body.solid], mesh, body_tensors), options);
    timings.assembly += solver.seconds_assembly();
    timings.factorisation += solver.seconds_elastic_factorisation();
    return solver;
}

}  // namespace

PoroelasticSolid::PoroelasticSolid(const Model& model, const PorousBody& body, PfemTimings& timings)
    : m_scene(model.scene.porous_solids[body.solid]),
      m_feedback(model.scene.poroelastic.permeability_feedback),
      m_pore_water(model.scene.poroelastic.pressure_from_pore_water),
      m_h(model.h),
      m_body_tensors(body.body_permeability),
      m_law(pore_water_law(m_scene.material, model.rho0, model.scene.gravity)),
      m_mesh(mesh_body(model, body, timings)),
      m_solver(make_solver(model, body, m_mesh, m_body_tensors, timings)),
      m_fields{std::vector<Vec3>(m_mesh.node_count(), Vec3::Zero()), std::vector<Real>(m_mesh.node_count(), 0)} {
    for (Index a = 0; a < m_mesh.node_count(); ++a)
        if (m_solver.problem().drained[a]) m_fields.p[a] = m_solver.problem().drained_pressure[a];
    m_assembled_k.assign(m_mesh.tet_count(), m_scene.material.permeability);

    // The pore water on the particles (method.md §2, §4.7): the mesh nodes are the particles.
    m_particles = porous_particles_at_rest(model, body, body.solid);
    m_particles.material.clear();  // one material: m_law
    const PorousParticles& p = m_particles;
    Real reach = model.h;
    for (const Mat3& K : m_body_tensors) reach = std::max(reach, kernel_reach(K, model.h));
    Aabb box;
    for (const Vec3& x : p.x) box.extend(x);
    const UniformGrid grid(box.padded(reach), reach);
    CellRanges cells;
    sort_into_cells(grid, p.x, cells);
    find_neighbours(grid, p.x, cells, true, m_pairs);
    m_flow = std::make_unique<PoreFlow>(std::vector{m_law}, model.h, model.dx,
                                        model.scene.paper_eq20 ? PairFlux::PaperEq20 : PairFlux::Darcy);
}

BiotCallReport PoroelasticSolid::advance(Real dt, PfemTimings& timings) {
    if (m_pore_water) {
        Stopwatch watch;
        m_flow->advance(m_particles, m_pairs, dt);
        timings.pore_flow += watch.seconds();
        // p^n <- P^p (M5) from the pore water at every node; the Biot p is kept for output only.
        for (Index a = 0; a < m_mesh.node_count(); ++a)
            if (!m_solver.problem().drained[a])
                m_fields.p[a] = m_law.pore_pressure(m_law.saturation(m_particles.absorbed_mass[a], m_particles.porosity[a], m_particles.volume[a]));
    }
    const BiotCallReport r = m_solver.advance(dt, m_fields);
    timings.factorisation += r.seconds_flow_factorisation;
    timings.iterations += r.seconds_iterations;
    ++timings.biot_calls;
    timings.biot_iterations += r.iterations;
    timings.all_converged = timings.all_converged && r.converged;
    if (m_feedback) refresh_permeability();
    return r;
}

Real PoroelasticSolid::porosity_at(const NodalStress& stress, Index a) const {
    return dynamic_porosity(m_scene.material.porosity, stress.volumetric_strain[a], m_fields.p[a],
                            m_solver.problem().material.grain_bulk_modulus());
}

void PoroelasticSolid::refresh_permeability() {
    // Feedback (method.md §5.4): M23 porosity and M24 permeability at the nodes, averaged over
    // each tet's nodes, give the mobility of the next call. H is reassembled (and the flow matrix
    // refactorised) only when some tet's permeability moved by over 1 % since the last assembly.
    const NodalStress stress = nodal_stress(m_mesh, m_solver.problem().material, m_fields);
    const PorousMaterial& mat = m_scene.material;
    std::vector<Real> k(m_mesh.node_count());
    for (Index a = 0; a < m_mesh.node_count(); ++a) {
        const Real phi = porosity_at(stress, a);
        k[a] = kozeny_carman_permeability(mat.permeability, mat.porosity, phi);
        // The particles follow (M12 with R = I): their porosity sets S, their tensor the flow.
        m_particles.porosity[a] = phi;
        m_particles.permeability[a] = (k[a] / mat.permeability) * m_body_tensors[a];
    }
    std::vector<Real> tet_k(m_mesh.tet_count());
    bool changed = false;
    for (Index e = 0; e < m_mesh.tet_count(); ++e) {
        const Tet& t = m_mesh.tets[e];
        tet_k[e] = 0.25 * (k[t[0]] + k[t[1]] + k[t[2]] + k[t[3]]);
        changed = changed || std::abs(tet_k[e] / m_assembled_k[e] - 1) > 0.01;
    }
    if (!changed) return;
    std::vector<Mat3> mobility(m_mesh.tet_count());
    for (Index e = 0; e < m_mesh.tet_count(); ++e)
        mobility[e] = (tet_k[e] / (mat.permeability * mat.darcy_viscosity)) * tet_mean(m_mesh.tets[e], m_body_tensors);
    m_solver.set_mobility(std::move(mobility));
    m_assembled_k = std::move(tet_k);
}

void PoroelasticSolid::append_to(MeshFrame& frame) const {
    const Index offset = Index(frame.nodes.x.size());
    const Index n = m_mesh.node_count();
    const NodalStress stress = nodal_stress(m_mesh, m_solver.problem().material, m_fields);
    const PorousMaterial& mat = m_scene.material;
    std::vector<Real> porosity(n), crack(n);
    std::vector<Mat3> permeability(n);
    for (Index a = 0; a < n; ++a) {
        porosity[a] = porosity_at(stress, a);
        permeability[a] = (kozeny_carman_permeability(mat.permeability, mat.porosity, porosity[a]) / mat.permeability) * m_body_tensors[a];
        crack[a] = stress.principal[a][0] / mat.tensile_strength;
    }
    PointSet local;
    local.add_vector("displacement", m_fields.u);
    local.add_scalar("pore_pressure", m_fields.p);
    local.add_scalar("porosity", porosity);
    local.add_symmetric_tensor("permeability", permeability);
    local.add_symmetric_tensor("effective_stress", stress.effective);
    local.add_vector("principal_stress", stress.principal);
    local.add_scalar("crack_candidate", crack);
    append_arrays(frame.nodes, local);
    frame.nodes.x.insert(frame.nodes.x.end(), m_mesh.nodes.begin(), m_mesh.nodes.end());
    for (const Tet& t : m_mesh.tets) frame.tets.push_back({t[0] + offset, t[1] + offset, t[2] + offset, t[3] + offset});
}

Real PoroelasticSolid::absorbed_water() const {
    Real sum = 0;
    for (Real m : m_particles.absorbed_mass) sum += m;
    return sum;
}

void PoroelasticSolid::append_particles_to(PointSet& points) const {
    append_arrays(points, porous_points(m_particles, {&m_law, 1}, m_pairs, m_h));
    points.x.insert(points.x.end(), m_particles.x.begin(), m_particles.x.end());
}

}  // namespace karst
