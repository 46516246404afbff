#pragma once
// The structure side's physical state (docs/method.md §5), as plain data inside State: per anchored
// fragment of a permeable solid its PFEM mesh on the rest positions, the links between its
// elements, the Biot fields, and per porous particle id the rest position, displacement and the
// loads summed since the last Biot call. The solvers (factorisations, AMG hierarchies) are not
// state: BiotCache holds them, keyed by the mesh they were built on, and rebuilds them on demand.
#include "karst/pfem/biot.hpp"
#include "karst/pfem/tet_mesh.hpp"

#include <optional>
#include <utility>
#include <vector>

namespace karst {

/// Two elements sharing a face (docs/method.md §5.5, M27): fracture breaks links, and the unbroken
/// ones say which elements still hold together.
struct ElementLink {
    Index a = 0, b = 0;  ///< tets of the mesh, a < b
};

/// One anchored fragment's Biot problem.
struct Structure {
    Index fragment = 0;              ///< in PorousState::fragments
    Index solid = 0;                 ///< in scene.porous_solids (its material and constraints)
    std::int64_t mesh_version = 0;   ///< changes whenever the mesh is rebuilt (keys BiotCache)
    std::vector<Index> node_id;      ///< porous particle id of each node
    TetMesh mesh;                    ///< on the rest positions X (world frame: anchored)
    std::vector<ElementLink> links;  ///< face adjacencies of mesh.tets
    BiotFields fields;               ///< u, p of the last call, per node
    /// Per node: the force of its supports in the last call's equilibrium (N; empty before the
    /// first call on this mesh). BiotSolver::support_forces says what it holds.
    std::vector<Vec3> support_force;
    std::vector<Vec3> u_from;  ///< per node: u of the call before the last (the particles' start)
    std::vector<Mat3> node_tensors;        ///< K0 per node (body frame), m^2
    std::vector<Real> permeability_scale;  ///< per node: k/k0 of the last feedback (M24)
    /// Per tet: the k/k0 the Biot flow matrix is assembled with; it follows permeability_scale
    /// when a tet's mean moves by over 1 % (biot_setup.hpp). State, not cache: a solver rebuilt
    /// from it (after a resume) assembles the matrix the run was using.
    std::vector<Real> mobility_scale;
    Real flow_time_step = -1;  ///< the step the flow matrix was factorised for (none yet: -1), s
    std::vector<char> well_shaped;  ///< per tet: dihedral angles of at least 2 degrees at rest
    bool distorted = false;  ///< the last call left a distorted element: remesh before the next
    bool grown = false;      ///< a merged fragment's particles joined: remesh before the next call
    /// Set by fracture (not saved: a resumed run factorises afresh): the mesh this one split,
    /// and per node the node of that mesh it is or copies, so that its solver can reuse the
    /// older factor (BiotSplitOf).
    std::int64_t split_of_version = -1;
    std::vector<Index> split_source;
};

/// Seconds spent per PFEM phase and what the calls did, summed over structures and calls
/// (stats.json "phases" and "biot").
struct PfemTimings {
    Real meshing = 0, assembly = 0, factorisation = 0, iterations = 0;
    Index biot_calls = 0, biot_iterations = 0, remeshes = 0;
    Index repeated_calls = 0;     ///< calls repeated at once after a fracture (sim/step.cpp)
    Index unconverged_calls = 0;  ///< calls that ended at max_iterations above the tolerance
};

/// A crack disk made by fracture (docs/method.md §5.5), in world coordinates.
struct CrackRecord {
    Vec3 centre = Vec3::Zero(), normal = Vec3::UnitZ();  ///< m, unit
    Real radius = 0, area = 0;                           ///< m, m^2 (M26, before the clamp)
    Real time = 0;                                       ///< s
    Index links_broken = 0;
    /// The fracture round of its Biot call: 0 for the cracks of the call's own stress, k for
    /// the k-th solve repeated at once after cracks (sim/step.cpp).
    int round = 0;
};

/// What fracture did so far (stats.json "fracture"; its time is the step profile's "fracture").
struct FractureCounts {
    Index cracks = 0, links_broken = 0, nodes_split = 0, fragments_created = 0;
    Index merges = 0;  ///< fragments that joined another (§5.6)
};

struct StructureState {
    std::vector<Structure> structures;
    // Per porous particle id (PorousParticles::id); grow_ids() sizes them for new ids:
    std::vector<Vec3> impulse;  ///< sum of force dt since the last call, N s
    std::vector<Vec3> u;        ///< displacement carried over a remesh, m
    /// In a coupled run: the displacement of the rest state under the solid's own weight, which
    /// u is measured from (structure_stages.cpp), m. Zero in a poroelastic-only run.
    std::vector<Vec3> weight_u;
    std::vector<Vec3> rest_x;  ///< rest position X (world = body frame when anchored), m
    std::vector<std::pair<Index, Index>> node_of;  ///< (structure, node), or (-1, -1)
    std::vector<Mat3> rest_tensor;                 ///< K0 in the body frame, m^2
    std::vector<Real> rest_volume;                 ///< V0, the bulk volume at eps_v = 0, m^3
    std::vector<Real> paired_scale,
        paired_volume;          ///< k/k0 and V when the pore-flow pairs were built
    std::vector<Index> damage;  ///< links broken on faces through the particle (§5.6)
    Real elapsed = 0;           ///< time since the last call, s
    std::int64_t next_mesh_version = 0;
    PfemTimings timings;
    FractureCounts fracture;
    std::vector<CrackRecord> cracks;  ///< every crack so far, in the order made
    bool empty() const { return structures.empty(); }
    /// Sizes the per-id arrays for ids below `ids` (new entries empty: no node, no load).
    void grow_ids(size_t ids) {
        if (ids <= u.size()) return;
        impulse.resize(ids, Vec3::Zero()), u.resize(ids, Vec3::Zero()),
            weight_u.resize(ids, Vec3::Zero()), rest_x.resize(ids, Vec3::Zero()),
            node_of.resize(ids, {-1, -1});
        rest_tensor.resize(ids, Mat3::Zero()), rest_volume.resize(ids, 0),
            paired_scale.resize(ids, 1), paired_volume.resize(ids, 0), damage.resize(ids, 0);
    }
};

/// Solvers of the structures' meshes. Copying a State copies no solver (the copy rebuilds
/// them when it needs them), so a cache entry can always be dropped.
class BiotCache {
public:
    struct Entry {
        std::int64_t mesh_version = -1;
        std::optional<BiotSolver> solver;
    };
    BiotCache() = default;
    BiotCache(const BiotCache&) {}
    BiotCache& operator=(const BiotCache&) {
        m_entries.clear();
        return *this;
    }
    BiotCache(BiotCache&&) noexcept = default;
    BiotCache& operator=(BiotCache&&) noexcept = default;

    /// The entry of structure `slot`, or null when it was built on another mesh (or never).
    Entry* find(size_t slot, std::int64_t mesh_version) {
        if (slot >= m_entries.size() || m_entries[slot].mesh_version != mesh_version)
            return nullptr;
        return &m_entries[slot];
    }
    Entry& reset(size_t slot) {
        if (slot >= m_entries.size()) m_entries.resize(slot + 1);
        m_entries[slot] = Entry{};
        return m_entries[slot];
    }

private:
    std::vector<Entry> m_entries;
};

}  // namespace karst
