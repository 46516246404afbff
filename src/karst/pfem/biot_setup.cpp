#include "karst/pfem/biot_setup.hpp"

#include "karst/pfem/rigid_modes.hpp"

#include "karst/core/timer.hpp"
#include "karst/pfem/cracks.hpp"
#include "karst/pfem/face_links.hpp"
#include "karst/pfem/mesh_split.hpp"
#include "karst/pfem/porosity.hpp"

#include <algorithm>
#include <array>
#include <optional>

namespace karst {

namespace {

/// The scene's /poroelastic solver settings.
BiotOptions biot_options(const Model& model) {
    const PoroelasticSettings& pe = model.scene.poroelastic;
    BiotOptions options;
    options.splitting = pe.fixed_strain ? Splitting::FixedStrain : Splitting::FixedStress;
    options.max_iterations = pe.max_iterations, options.tolerance = pe.tolerance;
    if (!pe.anderson) options.anderson_depth = 0;
    options.polyhedral = pe.mfem_polyhedra;
    using Choice = PoroelasticSettings::LinearSolver;
    options.linear_solver = pe.linear_solver == Choice::Amg      ? LinearSolver::Amg
                            : pe.linear_solver == Choice::Direct ? LinearSolver::Direct
                                                                 : LinearSolver::Auto;
    return options;
}

/// Mean of a tet's nodal tensors.
Mat3 tet_mean(const Tet& t, const std::vector<Mat3>& nodal) {
    return 0.25 * (nodal[t[0]] + nodal[t[1]] + nodal[t[2]] + nodal[t[3]]);
}

}  // namespace

TetMesh mesh_points(const Model& model, const std::vector<Vec3>& x, PfemTimings& timings) {
    Stopwatch watch;
    const PoroelasticSettings& pe = model.scene.poroelastic;
    MeshOptions options;
    options.alpha = pe.alpha, options.join_delta = pe.join_delta,
    options.weighted = pe.weighted_alpha;
    const std::vector<Real> size(x.size(), model.dx);
    const std::vector<Real> weights(options.weighted ? x.size() : 0, alpha_shape_weight(model.dx));
    TetMesh mesh = build_tet_mesh(x, size, options, weights);
    timings.meshing += watch.seconds();
    return mesh;
}

BiotMaterial biot_material(const Model& model, const PorousMaterial& m) {
    BiotMaterial b;
    b.youngs_modulus = m.youngs_modulus, b.poisson_ratio = m.poisson_ratio,
    b.biot_coefficient = m.biot_coefficient;
    // 1/M = phi/K_f + (B - phi)/K_s (docs/method.md §5.3).
    b.storage = m.porosity / model.scene.poroelastic.fluid_bulk_modulus +
                (m.biot_coefficient - m.porosity) / b.grain_bulk_modulus();
    b.fluid_density = model.rho0;
    b.bulk_density = (1 - m.porosity) * m.solid_density + m.porosity * model.rho0;  // saturated
    return b;
}

namespace {

/// Whether node position x lies on the constraint's region: inside it or within 3/4 of a
/// spacing (the outer particle layer sits half a spacing inside the geometry, the next 1.5).
bool on_region(const Model& model, const Constraint& c, const Vec3& x) {
    return c.region.signed_distance(x) <= 0.75 * model.dx;
}

/// Nodes touching a static wall (within a spacing of its particle skin) are anchored, u = 0
/// (docs/method.md §5.3): a block resting on the ground is held by it.
bool touches_wall(const Model& model, const Vec3& x) {
    for (const Wall& w : model.scene.walls) {
        const Real d = w.shape.signed_distance(x);
        if (w.kind == Wall::Kind::Obstacle ? d <= model.dx : d >= -model.dx) return true;
    }
    return false;
}

/// The nodes a platen constraint moves: on its region and not held by a wall.
std::vector<Index> platen_nodes(const Model& model, const Constraint& c, const TetMesh& mesh) {
    std::vector<Index> nodes;
    for (Index a = 0; a < mesh.node_count(); ++a)
        if (on_region(model, c, mesh.nodes[a]) && !touches_wall(model, mesh.nodes[a]))
            nodes.push_back(a);
    return nodes;
}

int platen_axis(const Constraint& c) {
    return c.axes == 1 ? 0 : c.axes == 2 ? 1 : 2;
}

}  // namespace

std::vector<SupportLog> support_loads(const Model& model, const PorousSolid& solid,
                                      const TetMesh& mesh, const BiotFields& fields,
                                      const std::vector<Vec3>& support_force, Real time) {
    const Index n = mesh.node_count();
    const Index walls = Index(solid.constraints.size());
    // Per node and axis, the support that holds that component (-1: none).
    std::vector<std::array<Index, 3>> owner(n, {-1, -1, -1});
    for (Index k = 0; k < walls; ++k) {
        const Constraint& c = solid.constraints[k];
        if (c.kind == Constraint::Kind::Platen)
            for (Index a : platen_nodes(model, c, mesh)) owner[a][platen_axis(c)] = k;
        if (c.kind == Constraint::Kind::Fixed)
            for (Index a = 0; a < n; ++a)
                if (on_region(model, c, mesh.nodes[a]))
                    for (int d = 0; d < 3; ++d)
                        if (c.axes & (1 << d)) owner[a][d] = k;
    }
    for (Index a = 0; a < n; ++a)
        if (touches_wall(model, mesh.nodes[a])) owner[a] = {walls, walls, walls};
    std::vector<SupportLog> logs(walls + 1);
    const bool forces = support_force.size() == size_t(n);
    for (Index a = 0; a < n; ++a) {
        for (int d = 0; d < 3; ++d)
            if (owner[a][d] >= 0 && forces) logs[owner[a][d]].force[d] += support_force[a][d];
        for (int d = 0; d < 3; ++d) {
            const Index k = owner[a][d];
            if (k < 0 || (d > 0 && owner[a][0] == k) || (d > 1 && owner[a][1] == k)) continue;
            ++logs[k].nodes;  // once per node and support
            logs[k].displacement += fields.u[a];
        }
    }
    std::vector<SupportLog> out;
    for (Index k = 0; k <= walls; ++k) {
        SupportLog& l = logs[k];
        if (l.nodes > 0) l.displacement /= Real(l.nodes);
        if (k == walls) {
            if (l.nodes == 0) continue;
            l.constraint = -1, l.kind = "walls";
        } else {
            const Constraint& c = solid.constraints[k];
            if (c.kind != Constraint::Kind::Fixed && c.kind != Constraint::Kind::Platen) continue;
            l.constraint = k;
            l.kind = c.kind == Constraint::Kind::Fixed ? "fixed" : "platen";
            if (c.kind == Constraint::Kind::Platen)
                l.force[platen_axis(c)] = c.table.at(time) * c.force;
        }
        out.push_back(std::move(l));
    }
    return out;
}

BoundaryValues boundary_values(const Model& model, const PorousSolid& solid, const TetMesh& mesh,
                               Real time) {
    const Index n = mesh.node_count();
    BoundaryValues b{std::vector<Vec3>(n, Vec3::Zero()), std::vector<Vec3>(n, Vec3::Zero()),
                     std::vector<Real>(n, 0)};
    for (const Constraint& c : solid.constraints) {
        const Real factor = c.table.at(time);
        auto inside = [&](const Vec3& x) { return on_region(model, c, x); };
        if (c.kind == Constraint::Kind::Traction) {
            const auto loads = traction_loads(mesh, factor * c.traction, inside);
            for (Index a = 0; a < n; ++a) b.nodal_force[a] += loads[a];
            continue;
        }
        if (c.kind == Constraint::Kind::Platen) {
            // The total force, spread evenly: the tied unknown takes their sum.
            const std::vector<Index> nodes = platen_nodes(model, c, mesh);
            for (Index a : nodes)
                b.nodal_force[a][platen_axis(c)] += factor * c.force / Real(nodes.size());
            continue;
        }
        for (Index a = 0; a < n; ++a) {
            if (!inside(mesh.nodes[a])) continue;
            if (c.kind == Constraint::Kind::Drained) {
                b.drained_pressure[a] = factor * c.pressure;
                continue;
            }
            for (int k = 0; k < 3; ++k)
                if (c.axes & (1 << k)) b.prescribed_u[a][k] = factor * c.displacement[k];
        }
    }
    for (Index a = 0; a < n; ++a)
        if (touches_wall(model, mesh.nodes[a])) b.prescribed_u[a] = Vec3::Zero();
    return b;
}

std::vector<std::vector<Index>> unheld_pieces(const TetMesh& mesh,
                                              std::span<const std::uint8_t> fixed) {
    Index count = 0;
    const std::vector<Index> piece_of = tet_components(mesh.tet_count(), face_links(mesh), count);
    std::vector<std::pair<Index, Index>> member;  // (piece, node), once each after the sort
    for (Index e = 0; e < mesh.tet_count(); ++e)
        for (Index a : mesh.tets[e]) member.emplace_back(piece_of[e], a);
    std::sort(member.begin(), member.end());
    member.erase(std::unique(member.begin(), member.end()), member.end());
    std::vector<std::vector<Index>> unheld;
    for (size_t begin = 0, end = 0; begin < member.size(); begin = end) {
        std::vector<Index> piece;
        std::vector<Vec3> x;
        std::vector<std::uint8_t> axes;
        for (end = begin; end < member.size() && member[end].first == member[begin].first; ++end) {
            const Index a = member[end].second;
            piece.push_back(a), x.push_back(mesh.nodes[a]), axes.push_back(fixed[a]);
        }
        if (free_rigid_modes(x, axes).cols() > 0) unheld.push_back(std::move(piece));
    }
    return unheld;
}

std::vector<std::uint8_t> constrained_axes(const Model& model, const PorousSolid& solid,
                                           const TetMesh& mesh) {
    std::vector<std::uint8_t> axes(mesh.node_count(), 0);
    for (const Constraint& c : solid.constraints)
        if (c.kind == Constraint::Kind::Fixed)
            for (Index a = 0; a < mesh.node_count(); ++a)
                if (on_region(model, c, mesh.nodes[a])) axes[a] |= c.axes;
    return axes;
}

BiotProblem biot_problem(const Model& model, const PorousSolid& solid, const TetMesh& mesh,
                         const std::vector<Mat3>& node_tensors) {
    BiotProblem p;
    p.material = biot_material(model, solid.material);
    p.gravity = model.scene.gravity;
    p.mobility.resize(mesh.tet_count());
    for (Index e = 0; e < mesh.tet_count(); ++e)
        p.mobility[e] = tet_mean(mesh.tets[e], node_tensors) / solid.material.darcy_viscosity;
    const Index n = mesh.node_count();
    p.fixed = constrained_axes(model, solid, mesh), p.drained.assign(n, 0);
    for (const Constraint& c : solid.constraints)
        if (c.kind == Constraint::Kind::Drained)
            for (Index a = 0; a < n; ++a)
                if (on_region(model, c, mesh.nodes[a])) p.drained[a] = 1;
    for (Index a = 0; a < n; ++a)
        if (touches_wall(model, mesh.nodes[a])) p.fixed[a] = FixAll;
    for (const Constraint& c : solid.constraints) {
        if (c.kind != Constraint::Kind::Platen) continue;
        BiotProblem::Platen platen{{}, platen_axis(c)};
        for (Index a : platen_nodes(model, c, mesh))
            if (!(p.fixed[a] & c.axes)) platen.nodes.push_back(a);
        if (platen.nodes.size() > 1) p.platens.push_back(std::move(platen));
    }
    BoundaryValues values = boundary_values(model, solid, mesh, 0);
    p.nodal_force = std::move(values.nodal_force);
    p.prescribed_u = std::move(values.prescribed_u);
    p.drained_pressure = std::move(values.drained_pressure);
    // Without anchors, or anchored only at a point or along a line (a piece left by fracture or
    // an island left by dissolution), the rigid-mode spring keeps the elasticity invertible.
    p.unheld_pieces = unheld_pieces(mesh, p.fixed);
    p.free_body = !holds_rigid_modes(mesh.nodes, p.fixed) || !p.unheld_pieces.empty();
    return p;
}

BiotSolver make_biot_solver(const Model& model, const TetMesh& mesh, BiotProblem problem,
                            PfemTimings& timings, const BiotSplitOf* split_of) {
    BiotSolver solver(mesh, std::move(problem), biot_options(model), split_of);
    timings.assembly += solver.seconds_assembly();
    timings.factorisation += solver.seconds_elastic_factorisation();
    return solver;
}

NodalPoreState nodal_pore_state(const PorousMaterial& material, const BiotMaterial& biot,
                                const NodalStress& stress, const std::vector<Real>& pressure) {
    const size_t n = pressure.size();
    NodalPoreState s{std::vector<Real>(n), std::vector<Real>(n)};
    for (size_t a = 0; a < n; ++a) {
        s.porosity[a] = dynamic_porosity(material.porosity, stress.volumetric_strain[a],
                                         pressure[a], biot.grain_bulk_modulus());
        s.permeability_scale[a] =
            kozeny_carman_permeability(material.permeability, material.porosity, s.porosity[a]) /
            material.permeability;
    }
    return s;
}

void assemble_mobility(BiotSolver& solver, const TetMesh& mesh, const PorousMaterial& material,
                       const std::vector<Mat3>& node_tensors, const std::vector<Real>& tet_scale) {
    std::vector<Mat3> mobility(mesh.tet_count());
    for (Index e = 0; e < mesh.tet_count(); ++e)
        mobility[e] =
            (tet_scale[e] / material.darcy_viscosity) * tet_mean(mesh.tets[e], node_tensors);
    solver.set_mobility(std::move(mobility));
}

void refresh_mobility(BiotSolver& solver, const TetMesh& mesh, const PorousMaterial& material,
                      const std::vector<Mat3>& node_tensors, const std::vector<Real>& node_scale,
                      std::vector<Real>& assembled_scale) {
    std::vector<Real> tet_scale(mesh.tet_count());
    bool changed = false;
    for (Index e = 0; e < mesh.tet_count(); ++e) {
        const Tet& t = mesh.tets[e];
        tet_scale[e] =
            0.25 * (node_scale[t[0]] + node_scale[t[1]] + node_scale[t[2]] + node_scale[t[3]]);
        changed = changed || std::abs(tet_scale[e] / assembled_scale[e] - 1) > 0.01;
    }
    if (!changed) return;
    assemble_mobility(solver, mesh, material, node_tensors, tet_scale);
    assembled_scale = std::move(tet_scale);
}

void append_arrays(PointSet& into, const PointSet& local) {
    for (const PointArray& array : local.arrays) {
        auto it = std::find_if(into.arrays.begin(), into.arrays.end(),
                               [&](const PointArray& a) { return a.name == array.name; });
        if (it == into.arrays.end()) {
            into.arrays.push_back({array.name, array.components, array.integer, {}});
            it = std::prev(into.arrays.end());
        }
        it->values.insert(it->values.end(), array.values.begin(), array.values.end());
    }
}

void append_mesh_frame(MeshFrame& frame, const TetMesh& mesh, const BiotProblem& problem,
                       const BiotFields& fields, const BiotFields& carried,
                       const std::vector<Vec3>& support_force, const PorousMaterial& material,
                       const std::vector<Mat3>& node_tensors, bool feedback,
                       std::span<const Real> strength_scale) {
    const Index offset = Index(frame.nodes.x.size());
    const Index n = mesh.node_count();
    const NodalStress stress = nodal_stress(mesh, problem.material, carried);
    // The pores follow the strain of u alone: another stress only where a rest state adds to u.
    std::optional<NodalStress> own;
    if (carried.u != fields.u) own = nodal_stress(mesh, problem.material, fields);
    const NodalPoreState pore =
        nodal_pore_state(material, problem.material, own ? *own : stress, fields.p);
    std::vector<Real> crack(n);
    std::vector<Mat3> permeability(n);
    for (Index a = 0; a < n; ++a) {
        permeability[a] = (feedback ? pore.permeability_scale[a] : Real(1)) * node_tensors[a];
        crack[a] = stress.principal[a][0] / material.tensile_strength;
        if (material.compressive_strength)
            crack[a] = std::max(
                crack[a], mohr_coulomb_ratio(stress.principal[a], *material.compressive_strength,
                                             material.friction_angle));
        if (!strength_scale.empty()) crack[a] /= strength_scale[a];
    }
    PointSet local;
    local.add_vector("displacement", fields.u);
    local.add_scalar("pore_pressure", fields.p);
    local.add_scalar("porosity",
                     feedback ? pore.porosity : std::vector<Real>(n, material.porosity));
    local.add_symmetric_tensor("permeability", permeability);
    local.add_symmetric_tensor("effective_stress", stress.effective);
    local.add_vector("principal_stress", stress.principal);
    local.add_scalar("crack_candidate", crack);
    local.add_vector("support_force", support_force.size() == size_t(n)
                                          ? support_force
                                          : std::vector<Vec3>(n, Vec3::Zero()));
    append_arrays(frame.nodes, local);
    frame.nodes.x.insert(frame.nodes.x.end(), mesh.nodes.begin(), mesh.nodes.end());
    for (const Tet& t : mesh.tets)
        frame.tets.push_back({t[0] + offset, t[1] + offset, t[2] + offset, t[3] + offset});
}

}  // namespace karst
