#include "karst/pfem/poroelastic_solid.hpp"

#include "karst/core/timer.hpp"
#include "karst/pfem/nodal_stress.hpp"
#include "karst/porous/permeability.hpp"
#include "karst/porous/porous_points.hpp"
#include "karst/sim/porous_materials.hpp"
#include "karst/sph/kernels.hpp"

namespace karst {

PoroelasticSolid::PoroelasticSolid(const Model& model, const PorousBody& body, PfemTimings& timings)
    : m_scene(model.scene.porous_solids[body.solid]),
      m_feedback(model.scene.poroelastic.permeability_feedback),
      m_pore_water(model.scene.poroelastic.pressure_from_pore_water),
      m_h(model.h),
      m_rest_volume(model.dx * model.dx * model.dx),
      m_body_tensors(body.body_permeability),
      m_law(pore_water_law(m_scene.material, model.rho0, model.scene.gravity)),
      m_mesh(mesh_points(model, body.rest_x, timings)),
      m_solver(make_biot_solver(model, m_mesh, biot_problem(model, m_scene, m_mesh, m_body_tensors), timings)),
      m_fields{std::vector<Vec3>(m_mesh.node_count(), Vec3::Zero()), std::vector<Real>(m_mesh.node_count(), 0)} {
    for (Index a = 0; a < m_mesh.node_count(); ++a)
        if (m_solver.problem().drained[a]) m_fields.p[a] = m_solver.problem().drained_pressure[a];
    m_assembled_scale.assign(m_mesh.tet_count(), 1);

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

void PoroelasticSolid::refresh_permeability() {
    // Feedback (method.md §5.4): M23 porosity and M24 permeability at the nodes give the
    // mobility of the next call; the particles follow (M12 with R = I): their porosity sets S,
    // their tensor the flow.
    const NodalStress stress = nodal_stress(m_mesh, m_solver.problem().material, m_fields);
    const NodalPoreState pore = nodal_pore_state(m_scene.material, m_solver.problem().material, stress, m_fields.p);
    for (Index a = 0; a < m_mesh.node_count(); ++a) {
        m_particles.porosity[a] = pore.porosity[a];
        m_particles.volume[a] = m_rest_volume * (1 + stress.volumetric_strain[a]);  // V = V0 (1 + eps_v)
        m_particles.permeability[a] = pore.permeability_scale[a] * m_body_tensors[a];
    }
    refresh_mobility(m_solver, m_mesh, m_scene.material, m_body_tensors, pore.permeability_scale, m_assembled_scale);
}

void PoroelasticSolid::append_to(MeshFrame& frame) const {
    append_mesh_frame(frame, m_mesh, m_solver.problem(), m_fields, m_scene.material, m_body_tensors);
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
