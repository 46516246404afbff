#pragma once
// The structure side of a coupled run (method.md §3 step 11, §5): every anchored, permeable
// fragment gets a PFEM mesh and a Biot problem. Between calls the fluid's forces on its
// particles are summed; every /poroelastic/time_step a Biot call takes their mean as nodal
// loads and the SPH pore pressure (M5) as p^n, its displacement moves the particles to X + u,
// and its strain and pressure feed porosity (M23), bulk volume and permeability (M24) back into
// the particles (§5.4).
#include "karst/pfem/biot_setup.hpp"
#include "karst/sim/state.hpp"

#include <memory>
#include <utility>

namespace karst {

class FragmentStructures {
public:
    /// Meshes every anchored fragment of a permeable solid and factorises its elasticity.
    FragmentStructures(const Model& model, const PorousState& porous);
    ~FragmentStructures();

    bool empty() const { return m_structures.empty(); }

    /// Adds this step's forces on the porous particles (fluid reactions and contacts), times dt.
    void add_loads(const PorousParticles& particles, const std::vector<Vec3>& force, Real dt);

    /// Every step: moves the particles toward X + u of the last call. Algorithm 2 once dt_B has
    /// passed since the last call: remeshes a fragment that has lost members or whose deformed
    /// mesh has a distorted element (§4.10), then one Biot call per fragment and the feedback.
    /// Returns true when some
    /// particle's volume or permeability moved by over 1 % since the pore-flow pairs were last
    /// built on them (the pairs cache both in their conductances and are then stale).
    bool advance(const Model& model, PorousState& porous);

    /// Time until the next call is due, s: the run lands a step on it, so that every call covers
    /// exactly dt_B and the flow matrix is factorised once.
    Real time_to_next_call(const Model& model) const { return model.scene.poroelastic.time_step - m_elapsed; }

    /// Appends every fragment's mesh and fields (nodes at their world rest positions X).
    void append_to(MeshFrame& frame) const;

    Index elements() const;
    const PfemTimings& timings() const { return m_timings; }

private:
    struct Structure;
    void build(const Model& model, const PorousState& porous, Structure& s);
    bool distorted(const Structure& s) const;
    /// Moves the particles the given fraction of the way from X + u^{n-1} to X + u^n.
    void follow_displacement(PorousParticles& p, Real fraction, Real dt_B) const;

    std::vector<std::unique_ptr<Structure>> m_structures;  // stable addresses: a solver refers to its mesh
    std::vector<Vec3> m_impulse;   ///< per particle id: sum of force dt since the last call, N s
    std::vector<Vec3> m_u;         ///< per particle id: last displacement (carried over a remesh), m
    std::vector<Vec3> m_rest_x;    ///< per particle id: rest position X (world = body frame when anchored), m
    std::vector<std::pair<Index, Index>> m_node_of;  ///< per particle id: (structure, node), or (-1, -1)
    std::vector<Mat3> m_rest_tensor;  ///< per particle id: K0 in the body frame, m^2
    std::vector<Real> m_paired_scale, m_paired_volume;  ///< per particle id: k/k0 and V of the last pair build
    Real m_elapsed = 0;            ///< time since the last call, s
    PfemTimings m_timings;
};

}  // namespace karst
