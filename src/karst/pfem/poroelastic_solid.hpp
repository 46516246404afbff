#pragma once
// One porous solid's structure side (method.md §5): its PFEM mesh on the rest positions, the
// Biot problem its scene entry describes, the fields u and p, and what a frame shows of them.
#include "karst/pfem/biot_setup.hpp"
#include "karst/porous/pore_flow.hpp"

#include <memory>

namespace karst {

class PoroelasticSolid {
public:
    /// Meshes the body and assembles its Biot problem (factorising the elasticity matrix).
    PoroelasticSolid(const Model& model, const PorousBody& body, PfemTimings& timings);

    /// One step over dt: the pore water moves (M15, with /poroelastic/pressure_source
    /// pore_water) and seeds the Biot pressure (M5), one Biot call (M22), then the porosity and
    /// permeability feedback (§5.4) into the mesh and the particles.
    BiotCallReport advance(Real dt, PfemTimings& timings);

    /// The solid's particles with saturation, porosity, absorbed_mass, pore_pressure (M5),
    /// pore_velocity (M17), fragment and permeability (6 components), for porous_NNNN.vtp.
    void append_particles_to(PointSet& points) const;

    /// Pore water held by the solid, kg.
    Real absorbed_water() const;

    /// Appends this solid's nodes (rest positions) and tets to `frame`, with the point arrays
    /// displacement, pore_pressure, porosity (M23), permeability (M24, 6 components),
    /// effective_stress (6), principal_stress (3) and crack_candidate (sigma'_1 / sigma_t, M25).
    void append_to(MeshFrame& frame) const;

    const TetMesh& mesh() const { return m_mesh; }
    const BiotFields& fields() const { return m_fields; }
    const BiotProblem& problem() const { return m_solver.problem(); }

private:
    void refresh_permeability();

    const PorousSolid& m_scene;
    bool m_feedback, m_pore_water;
    Real m_h;                   ///< SPH support radius, m
    Real m_rest_volume;         ///< V0 of every particle, m^3
    std::vector<Mat3> m_body_tensors;  ///< K0 per node (M12), m^2
    PoreWaterLaw m_law;
    PorousParticles m_particles;
    NeighbourLists m_pairs;
    std::unique_ptr<PoreFlow> m_flow;
    TetMesh m_mesh;
    BiotSolver m_solver;
    BiotFields m_fields;
    std::vector<Real> m_assembled_scale;  ///< per tet: the k/k0 H was assembled with
};

}  // namespace karst
