#pragma once
// The output folder of a run: per-frame fluid and mesh files, the static boundary, run.pvd,
// mesh.case, log.csv and stats.json. Each file is written atomically; run.pvd and log.csv are
// rewritten after every frame, so the folder is complete and consistent whenever a run stops.
#include "karst/io/output_folder.hpp"
#include "karst/io/point_arrays.hpp"
#include "karst/scene/scene.hpp"
#include "karst/sim/model.hpp"
#include "karst/sim/state.hpp"
#include "karst/surface/surface_mesh.hpp"

#include <nlohmann/json.hpp>

#include <array>
#include <cstdint>
#include <filesystem>
#include <vector>

namespace karst {

/// What one support of a porous solid's Biot problem carries at a frame (a row of supports.csv):
/// a `fixed` or `platen` constraint, or the static walls that anchor the solid.
struct SupportLog {
    Index solid = 0;                   ///< in scene.porous_solids
    Index constraint = -1;             ///< in its constraints; -1: the static walls
    std::string kind{};                ///< fixed, platen or walls
    Index nodes = 0;                   ///< mesh nodes it holds
    Vec3 force = Vec3::Zero();         ///< on the solid, N (a platen: its applied force)
    Vec3 displacement = Vec3::Zero();  ///< mean displacement of its nodes, m
};

/// One row of log.csv.
struct FrameLog {
    Real time = 0;              ///< s
    Real dt = 0;                ///< last step, s
    Index steps = 0;            ///< steps so far
    Index particles = 0;        ///< fluid particles now
    Real density_error = 0;     ///< largest pressure-solve residual since the last frame (fraction)
    Real mipps = 0;             ///< million particle-steps per second since the last frame
    Real kinetic_energy = 0;    ///< fluid + porous particles, J (sim/energy.hpp)
    Real potential_energy = 0;  ///< -sum m g.x, J
    Real contact_energy = 0;    ///< the fragments' contact springs, J
    Index removed = 0;          ///< fluid particles that left the domain so far
    Real speed_p99 = 0;         ///< 99th percentile of the fluid particles' speed, m/s
    Real max_speed = 0;         ///< fastest fluid particle, m/s
    std::vector<SupportLog>
        supports{};  ///< supports.csv rows of this frame (solids' Biot problems)
};

/// The PFEM meshes of a frame, as one tetrahedral grid with its point arrays.
struct MeshFrame {
    PointSet nodes;
    std::vector<std::array<Index, 4>> tets;
};

/// Crack disks as polygons (docs/method.md §5.5), their values on every vertex.
struct CrackFrame {
    PointSet vertices;
    std::vector<std::vector<Index>> polygons;
};

/// Every crack made so far as a 16-gon in its plane: normal, radius, area (M26) and time.
CrackFrame crack_frame(const std::vector<CrackRecord>& cracks);

/// What a frame holds; absent parts are not written.
struct FrameParts {
    const FluidParticles* fluid = nullptr;
    const MeshFrame* mesh = nullptr;
    const PointSet* porous = nullptr;    ///< porous particles with their pore state
    const CrackFrame* cracks = nullptr;  ///< written once some crack exists
    const SurfaceMesh* fluid_surface = nullptr;
    const SurfaceMesh* porous_surface = nullptr;
    const std::string* level_set = nullptr;  ///< the fluid level set, .vdb bytes
    Real pscale = 0;                         ///< fluid particle radius in the PLY points, m
};

/// The frames written so far: what run.pvd and log.csv list (a checkpoint keeps it).
struct FrameHistory {
    struct Written {
        bool fluid = false, mesh = false, porous = false, cracks = false;
        bool fluid_surface = false, porous_surface = false;
        /// The frames whose files this frame's mesh reads: its geometry, then each array (a
        /// file is written only when its bytes changed).
        std::vector<int> mesh_files;
    };
    std::vector<FrameLog> log;
    std::vector<Written> written;  ///< which parts each frame has
    bool has_boundary = false;
    std::vector<std::uint64_t> mesh_hashes;  ///< FNV-1a of the newest of each of those files
};

class FrameWriter {
public:
    /// Claims `dir` (io/output_folder.hpp: the files of an earlier run there are removed; a
    /// folder karst did not write is refused unless `overwrite`).
    FrameWriter(std::filesystem::path dir, const OutputSettings& settings, bool overwrite);
    /// Continues the run that wrote `dir` after its frames in `history` (a resumed run): the
    /// frame files it wrote after them are removed, the rest is kept.
    FrameWriter(std::filesystem::path dir, const OutputSettings& settings, FrameHistory history);
    void write_boundary(const WallParticles& walls);
    /// fluid_NNNN.vtp/.ply, the mesh (mesh_NNNN.geo and mesh_<array>_NNNN.ens, each only when
    /// it changed), porous_NNNN.vtp, cracks_NNNN.vtp,
    /// fluid_surface_NNNN.ply/.vtp, porous_surface_NNNN.ply/.vtp and fluid_level_set_NNNN.vdb as
    /// present, then run.pvd, mesh.case and log.csv anew.
    void write_frame(const FrameParts& parts, const FrameLog& log);
    void write_stats(const nlohmann::json& stats);
    int frames() const { return int(m_history.log.size()); }
    const FrameHistory& history() const { return m_history; }
    OutputFolder& folder() { return m_folder; }
    const std::filesystem::path& dir() const { return m_folder.dir(); }

private:
    /// The mesh's files of frame `frame` at `time` that changed, and mesh.case; returns the
    /// frames whose files it reads.
    std::vector<int> write_mesh(const MeshFrame& mesh, int frame, Real time);
    /// <stem>.ply and <stem>.vtp of a surface.
    void write_surface(const std::string& stem, const SurfaceMesh& mesh);
    OutputFolder m_folder;
    OutputSettings m_settings;
    FrameHistory m_history;
};

}  // namespace karst
