#include "karst/sim/checkpoint.hpp"

#include "karst/core/fnv1a.hpp"
#include "karst/io/binary_archive.hpp"
#include "karst/scene/scene_error.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <fstream>
#include <sstream>

namespace karst {

// What a checkpoint holds, type by type (io/binary_archive.hpp): one list serves writing and
// reading. A field added to State and left out here makes the resume test fail.

template <class Ar>
void fields(Ar& ar, FluidParticles& f) {
    FluidParticles::for_each_attribute([&](auto& a) { ar(a); }, f);
}

template <class Ar>
void fields(Ar& ar, PorousParticles& p) {
    PorousParticles::for_each_attribute([&](auto& a) { ar(a); }, p);
}

template <class Ar>
void fields(Ar& ar, Fragment& f) {
    ar(f.centre, f.rotation, f.velocity, f.angular_momentum, f.mass, f.body_inertia, f.anchored);
}

template <class Ar>
void fields(Ar& ar, CrackContact& c) {
    ar(c.lo, c.hi, c.rest);
}

template <class Ar>
void fields(Ar& ar, PorousState& s) {
    ar(s.particles, s.fragments, s.absorbed, s.dissolved, s.fluid_deleted, s.removed,
       s.pore_substeps, s.crack_contacts);
}

template <class Ar>
void fields(Ar& ar, PorePairs& p) {
    ar(p.start, p.other, p.conductance, p.weight, p.row_sum);
}

template <class Ar>
void fields(Ar& ar, MeshQuality& q) {
    ar(q.delaunay_cells, q.kept, q.elements, q.slivers_dropped, q.interior_slivers, q.polyhedra,
       q.joined_polyhedra, q.min_dihedral_deg, q.volume);
}

template <class Ar>
void fields(Ar& ar, TetMesh& m) {
    ar(m.nodes, m.tets, m.tet_polyhedron, m.boundary, m.quality);
}

template <class Ar>
void fields(Ar& ar, ElementLink& l) {
    ar(l.a, l.b);
}

template <class Ar>
void fields(Ar& ar, BiotFields& f) {
    ar(f.u, f.p);
}

template <class Ar>
void fields(Ar& ar, Structure& s) {
    ar(s.fragment, s.solid, s.mesh_version, s.node_id, s.mesh, s.links, s.fields, s.support_force,
       s.u_from, s.node_tensors, s.permeability_scale, s.mobility_scale, s.flow_time_step,
       s.well_shaped, s.distorted, s.grown);
}

template <class Ar>
void fields(Ar& ar, PfemTimings& t) {
    ar(t.meshing, t.assembly, t.factorisation, t.iterations, t.biot_calls, t.biot_iterations,
       t.remeshes, t.repeated_calls, t.unconverged_calls);
}

template <class Ar>
void fields(Ar& ar, CrackRecord& c) {
    ar(c.centre, c.normal, c.radius, c.area, c.time, c.links_broken, c.round);
}

template <class Ar>
void fields(Ar& ar, FractureCounts& f) {
    ar(f.cracks, f.links_broken, f.nodes_split, f.fragments_created, f.merges);
}

template <class Ar>
void fields(Ar& ar, StructureState& s) {
    ar(s.structures, s.impulse, s.u, s.weight_u, s.rest_x, s.node_of, s.rest_tensor, s.rest_volume,
       s.paired_scale, s.paired_volume, s.damage, s.elapsed, s.next_mesh_version, s.timings,
       s.fracture, s.cracks);
}

template <class Ar>
void fields(Ar& ar, State& s) {
    ar(s.fluid, s.porous, s.porous_scratch.fragment_pairs, s.porous_scratch.pairs_stale,
       s.structures, s.time, s.steps, s.dt, s.a_max, s.dt_solver_limit, s.removed, s.pushed_back,
       s.next_id);
}

template <class Ar>
void fields(Ar& ar, SupportLog& l) {
    ar(l.solid, l.constraint, l.kind, l.nodes, l.force, l.displacement);
}

template <class Ar>
void fields(Ar& ar, FrameLog& l) {
    ar(l.time, l.dt, l.steps, l.particles, l.density_error, l.mipps, l.kinetic_energy,
       l.potential_energy, l.contact_energy, l.removed, l.speed_p99, l.max_speed, l.supports);
}

template <class Ar>
void fields(Ar& ar, FrameHistory::Written& w) {
    ar(w.fluid, w.mesh, w.porous, w.cracks, w.fluid_surface, w.porous_surface, w.mesh_files);
}

template <class Ar>
void fields(Ar& ar, FrameHistory& h) {
    ar(h.log, h.written, h.has_boundary, h.mesh_hashes);
}

template <class Ar>
void fields(Ar& ar, MassTotals& m) {
    ar(m.water, m.solute, m.absorbed, m.grains);
}

template <class Ar>
void fields(Ar& ar, StepProfile& p) {
    ar(p.seconds);
}

template <class Ar>
void fields(Ar& ar, RunRecord& r) {
    ar(r.next_frame, r.max_density_error, r.frame_density_error, r.frames_over_tolerance,
       r.particle_steps, r.frame_particle_steps, r.frame_step_seconds, r.wall_seconds,
       r.energy_warned, r.removed_warned, r.biot_warned, r.porous_removed_warned, r.initial,
       r.energy, r.profile, r.frames);
}

namespace {

constexpr char k_magic[] = "karst checkpoint";

}  // namespace

std::string checkpoint_bytes(const CheckpointKey& key, const State& state,
                             const RunRecord& record) {
    ArchiveWriter body;
    body(state, record);
    ArchiveWriter file;
    file(std::string(k_magic), k_checkpoint_format, std::string(KARST_VERSION), key.scene, key.fps,
         body.bytes(), fnv1a(body.bytes()));
    return file.bytes();
}

void read_checkpoint(const std::filesystem::path& path, const CheckpointKey& key, State& state,
                     RunRecord& record) {
    auto refuse = [&](const std::string& expected, const std::string& found) {
        return SceneError("--resume", expected, fmt::format("{} in '{}'", found, path.string()));
    };
    std::ifstream in(path, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    if (!in) throw refuse("a readable checkpoint file", "an unreadable file");
    const std::string bytes = ss.str();
    ArchiveWriter magic;
    magic(std::string(k_magic));
    if (!bytes.starts_with(magic.bytes()))
        throw refuse("a karst checkpoint", "another kind of file");
    try {
        ArchiveReader file(std::string_view(bytes).substr(magic.bytes().size()));
        std::string version, body;
        std::uint32_t format = 0;
        CheckpointKey found;
        std::uint64_t sum = 0;
        file(format, version);
        if (format != k_checkpoint_format || version != KARST_VERSION)
            throw refuse(fmt::format("a checkpoint of karst {} (layout {})", KARST_VERSION,
                                     k_checkpoint_format),
                         fmt::format("one of karst {} (layout {})", version, format));
        file(found.scene, found.fps);
        if (found.scene != key.scene)
            throw refuse("a checkpoint of this scene (only /time/end may differ)",
                         "one of another scene");
        if (found.fps != key.fps)
            throw refuse(fmt::format("a checkpoint written at {:g} frames per second", key.fps),
                         fmt::format("one at {:g}", found.fps));
        file(body, sum);
        if (sum != fnv1a(body) || file.left() != 0)
            throw refuse("an intact checkpoint", "a damaged one (checksum)");
        ArchiveReader reader(body);
        reader(state, record);
        if (reader.left() != 0) throw ArchiveError("bytes left over after the record");
    } catch (const ArchiveError& e) {
        throw refuse("an intact checkpoint", fmt::format("a damaged one ({})", e.what()));
    }
}

std::string checkpoint_name(Index steps) {
    return fmt::format("checkpoint_{:012d}.kcp", steps);
}

std::vector<std::string> checkpoint_names(const std::filesystem::path& dir) {
    std::vector<std::string> names;
    std::error_code ec;
    for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
        const std::string name = entry.path().filename().string();
        if (name.starts_with("checkpoint_") && name.ends_with(".kcp")) names.push_back(name);
    }
    std::sort(names.begin(), names.end());
    return names;
}

}  // namespace karst
