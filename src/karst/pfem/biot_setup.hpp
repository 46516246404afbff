#pragma once
// From a scene's porous solid to its Biot problem (docs/method.md §5.1-5.5): the mesh of a point
// set, the Biot material and boundary conditions, the solver options, the porosity and permeability
// feedback at the nodes, and the mesh frame arrays.
#include "karst/io/frame_writer.hpp"
#include "karst/pfem/alpha_shape_weight.hpp"
#include "karst/pfem/biot.hpp"
#include "karst/pfem/nodal_stress.hpp"
#include "karst/pfem/structure_state.hpp"
#include "karst/sim/model.hpp"

#include <algorithm>
#include <span>

namespace karst {

/// §5.1 mesh of the points x (rest positions, spacing dx) with the scene's alpha, delta and
/// weighted-alpha settings.
TetMesh mesh_points(const Model& model, const std::vector<Vec3>& x, PfemTimings& timings);

/// The saturated Biot material of a porous material (docs/method.md §5.3).
BiotMaterial biot_material(const Model& model, const PorousMaterial& material);

/// The values of the scene's constraints at `time` (their tables' factors) on `mesh`: nodal
/// forces of the tractions, prescribed displacements (on the fixed axes) and drained pressures.
struct BoundaryValues {
    std::vector<Vec3> nodal_force, prescribed_u;
    std::vector<Real> drained_pressure;
};
BoundaryValues boundary_values(const Model& model, const PorousSolid& solid, const TetMesh& mesh,
                               Real time);

/// What each support of `solid` carries on `mesh` (io/frame_writer.hpp SupportLog): every `fixed`
/// and `platen` constraint in scene order, then the static walls where some node touches one.
/// Each held component of a node belongs to the support whose value boundary_values gives it (a
/// wall over any constraint, a later constraint over an earlier), so the forces of all supports
/// add up to the total support force. A fixed support's force sums its components; a platen's is
/// its applied force at `time`, since its nodes move freely along its axis. Solid indices are
/// left 0.
std::vector<SupportLog> support_loads(const Model& model, const PorousSolid& solid,
                                      const TetMesh& mesh, const BiotFields& fields,
                                      const std::vector<Vec3>& support_force, Real time);

/// Whether some constraint of the solid changes in time.
inline bool has_time_table(const PorousSolid& solid) {
    return std::any_of(solid.constraints.begin(), solid.constraints.end(),
                       [](const Constraint& c) { return !c.table.rows.empty(); });
}

/// The nodes of each piece of `mesh` (tets joined by faces) that some rigid motion leaves
/// untouched by its `fixed` nodes (pfem/rigid_modes.hpp: free_rigid_modes).
std::vector<std::vector<Index>> unheld_pieces(const TetMesh& mesh,
                                              std::span<const std::uint8_t> fixed);

/// The axes each node of `mesh` is held on by the solid's `fixed` constraints (FixX | FixY |
/// FixZ bits), not counting the walls' anchors.
std::vector<std::uint8_t> constrained_axes(const Model& model, const PorousSolid& solid,
                                           const TetMesh& mesh);

/// The Biot problem of `solid` on `mesh`, whose nodes are world positions: mobility from the
/// nodal tensors K0, the scene's constraints (fixed, drained, traction) at t = 0, and anchors
/// where a node lies within a spacing of a static wall.
BiotProblem biot_problem(const Model& model, const PorousSolid& solid, const TetMesh& mesh,
                         const std::vector<Mat3>& node_tensors);

/// Builds the solver with the scene's /poroelastic settings (through the factor of the solver
/// it splits, where given: BiotSolver) and adds its assembly and factorisation times.
BiotSolver make_biot_solver(const Model& model, const TetMesh& mesh, BiotProblem problem,
                            PfemTimings& timings, const BiotSplitOf* split_of = nullptr);

/// Porosity (M23) and permeability scale k/k0 (M24) at every node, from the nodal strain and
/// the Biot pressure.
struct NodalPoreState {
    std::vector<Real> porosity, permeability_scale;
};
NodalPoreState nodal_pore_state(const PorousMaterial& material, const BiotMaterial& biot,
                                const NodalStress& stress, const std::vector<Real>& pressure);

/// H from each tet's permeability scale k/k0 (M24): mobility scale K0 / eta per tet.
void assemble_mobility(BiotSolver& solver, const TetMesh& mesh, const PorousMaterial& material,
                       const std::vector<Mat3>& node_tensors, const std::vector<Real>& tet_scale);

/// M24 into the Biot flow: each tet's permeability scale is the mean of its nodes'. H is
/// reassembled (and the flow matrix refactorised) only when some tet's scale moved by over 1 %
/// since the last assembly, whose scales `assembled_scale` keeps (all 1 at first).
void refresh_mobility(BiotSolver& solver, const TetMesh& mesh, const PorousMaterial& material,
                      const std::vector<Mat3>& node_tensors, const std::vector<Real>& node_scale,
                      std::vector<Real>& assembled_scale);

/// Appends the mesh (nodes at `mesh.nodes`, tets) to `frame`, with the point arrays
/// displacement, pore_pressure, porosity and permeability (6 components) as the pores use them
/// (the call's M23 and M24 with `feedback`, else the rest values phi0 and K0), effective_stress
/// (6), principal_stress (3), crack_candidate (sigma'_1 / sigma_t, M25, or the Mohr-Coulomb
/// ratio where that is larger and the material has a compressive strength, both over the
/// strengths times `strength_scale` where given: the water's weakening) and support_force (3,
/// zero where `support_force` does not cover the mesh: no call on it yet). The stresses are
/// those of `carried` (the fields with u from the unloaded mesh, fields_with_weight), the rest
/// those of `fields`.
void append_mesh_frame(MeshFrame& frame, const TetMesh& mesh, const BiotProblem& problem,
                       const BiotFields& fields, const BiotFields& carried,
                       const std::vector<Vec3>& support_force, const PorousMaterial& material,
                       const std::vector<Mat3>& node_tensors, bool feedback,
                       std::span<const Real> strength_scale);

/// Appends the arrays of `local` to those of `into` (by name), creating them for the first solid.
void append_arrays(PointSet& into, const PointSet& local);

}  // namespace karst
