#include "karst/io/frame_writer.hpp"

#include "karst/core/fnv1a.hpp"
#include "karst/io/ensight_writer.hpp"
#include "karst/io/ply_writer.hpp"
#include "karst/io/vtk_writer.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace karst {

namespace fs = std::filesystem;

FrameWriter::FrameWriter(fs::path dir, const OutputSettings& settings, bool overwrite)
    : m_folder(std::move(dir), overwrite), m_settings(settings) {}

FrameWriter::FrameWriter(fs::path dir, const OutputSettings& settings, FrameHistory history)
    : m_folder(std::move(dir), OutputFolder::Resume{}),
      m_settings(settings),
      m_history(std::move(history)) {
    // Frame files are <part>_NNNN.<ext>; those numbered past the history are the killed run's.
    const int kept = frames();
    m_folder.remove_if([kept](const std::string& name) {
        const size_t underscore = name.rfind('_'), dot = name.rfind('.');
        if (underscore == std::string::npos || dot == std::string::npos || dot < underscore + 2)
            return false;
        const std::string digits = name.substr(underscore + 1, dot - underscore - 1);
        if (!std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; }))
            return false;
        const std::string ext = name.substr(dot);
        return (ext == ".vtp" || ext == ".ply" || ext == ".vdb" || ext == ".geo" ||
                ext == ".ens") &&
               std::stoll(digits) >= kept;
    });
}

void FrameWriter::write_boundary(const WallParticles& walls) {
    if (!m_settings.walls || walls.size() == 0) return;
    PointSet points{walls.x, {}};
    points.add_scalar("psi", walls.psi);
    m_folder.write("boundary.vtp", vtp_bytes(points, m_settings.compress));
    m_history.has_boundary = true;
}

void FrameWriter::write_frame(const FrameParts& parts, const FrameLog& log) {
    const int frame = frames();
    const bool fluid_part = parts.fluid && (m_settings.vtp || m_settings.ply);
    const bool mesh = parts.mesh && !parts.mesh->nodes.x.empty() && m_settings.mesh;
    const bool porous = parts.porous && m_settings.porous;
    const bool cracks = parts.cracks && !parts.cracks->polygons.empty() && m_settings.cracks;
    if (fluid_part) {
        const FluidParticles& fluid = *parts.fluid;
        PointSet points{fluid.x, {}};
        points.add_vector("velocity", fluid.v);
        points.add_scalar("density", fluid.rho);
        // The fluid's pressure: the density solve's plus, with DFSPH, the divergence solve's.
        std::vector<Real> pressure(fluid.size());
        for (Index i = 0; i < fluid.size(); ++i) pressure[i] = fluid.pressure(i);
        points.add_scalar("pressure", pressure);
        std::vector<Real> water(fluid.size());  // absorption drains it, dissolution brings grains
        for (Index i = 0; i < fluid.size(); ++i) water[i] = fluid.water(i);
        points.add_scalar("water", water);
        std::vector<Real> concentration(fluid.size());
        for (Index i = 0; i < fluid.size(); ++i) concentration[i] = fluid.solute[i] / fluid.mass[i];
        points.add_scalar("concentration", concentration);
        points.add_integer("id", fluid.id);
        if (parts.pscale > 0)
            points.add_scalar("pscale", std::vector<Real>(fluid.size(), parts.pscale));
        if (m_settings.vtp)
            m_folder.write(fmt::format("fluid_{:04d}.vtp", frame),
                           vtp_bytes(points, m_settings.compress));
        if (m_settings.ply)
            m_folder.write(fmt::format("fluid_{:04d}.ply", frame), ply_bytes(points));
    }
    std::vector<int> mesh_files;
    if (mesh) mesh_files = write_mesh(*parts.mesh, frame, log.time);
    m_history.log.push_back(log);
    if (porous)
        m_folder.write(fmt::format("porous_{:04d}.vtp", frame),
                       vtp_bytes(*parts.porous, m_settings.compress));
    if (cracks)
        m_folder.write(fmt::format("cracks_{:04d}.vtp", frame),
                       vtp_polygons_bytes(parts.cracks->vertices, parts.cracks->polygons,
                                          m_settings.compress));
    const bool fluid_surface = parts.fluid_surface && m_settings.fluid_surface;
    const bool porous_surface = parts.porous_surface && m_settings.porous_surface;
    if (fluid_surface)
        write_surface(fmt::format("fluid_surface_{:04d}", frame), *parts.fluid_surface);
    if (porous_surface)
        write_surface(fmt::format("porous_surface_{:04d}", frame), *parts.porous_surface);
    if (parts.level_set && m_settings.level_set)
        m_folder.write(fmt::format("fluid_level_set_{:04d}.vdb", frame), *parts.level_set);
    m_history.written.push_back({fluid_part && m_settings.vtp, mesh, porous, cracks, fluid_surface,
                                 porous_surface, std::move(mesh_files)});
    const std::vector<FrameLog>& rows = m_history.log;
    const std::vector<FrameHistory::Written>& written = m_history.written;
    const bool boundary = m_history.has_boundary;

    if (boundary || m_settings.vtp || m_settings.porous || m_settings.cracks ||
        m_settings.fluid_surface || m_settings.porous_surface) {
        // Parts: 0 fluid, 1 boundary, 3 porous particles, 4 cracks, 5 fluid surface, 6 porous
        // surface (2, the mesh, is in mesh.case).
        std::vector<PvdEntry> entries;
        for (int f = 0; f < frames(); ++f) {
            if (written[f].fluid)
                entries.push_back({rows[f].time, 0, fmt::format("fluid_{:04d}.vtp", f)});
            if (boundary) entries.push_back({rows[f].time, 1, "boundary.vtp"});
            if (written[f].porous)
                entries.push_back({rows[f].time, 3, fmt::format("porous_{:04d}.vtp", f)});
            if (written[f].cracks)
                entries.push_back({rows[f].time, 4, fmt::format("cracks_{:04d}.vtp", f)});
            if (written[f].fluid_surface)
                entries.push_back({rows[f].time, 5, fmt::format("fluid_surface_{:04d}.vtp", f)});
            if (written[f].porous_surface)
                entries.push_back({rows[f].time, 6, fmt::format("porous_surface_{:04d}.vtp", f)});
        }
        m_folder.write("run.pvd", pvd_bytes(entries));
    }
    std::string csv =
        "frame,time,dt,steps,particles,removed,density_error,mipps,speed_p99,max_speed,kinetic_"
        "energy,potential_energy,contact_energy,total_energy\n";
    for (int f = 0; f < frames(); ++f) {
        const FrameLog& r = rows[f];
        csv += fmt::format(
            "{},{:.9g},{:.6g},{},{},{},{:.6g},{:.6g},{:.6g},{:.6g},{:.9g},{:.9g},{:.9g},{:.9g}\n",
            f, r.time, r.dt, r.steps, r.particles, r.removed, r.density_error, r.mipps, r.speed_p99,
            r.max_speed, r.kinetic_energy, r.potential_energy, r.contact_energy,
            r.kinetic_energy + r.potential_energy + r.contact_energy);
    }
    m_folder.write("log.csv", csv);
    if (std::any_of(rows.begin(), rows.end(),
                    [](const FrameLog& r) { return !r.supports.empty(); })) {
        std::string supports =
            "frame,time,solid,constraint,kind,nodes,force_x,force_y,force_z,displacement_x,"
            "displacement_y,displacement_z\n";
        for (int f = 0; f < frames(); ++f)
            for (const SupportLog& l : rows[f].supports)
                supports += fmt::format(
                    "{},{:.9g},{},{},{},{},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g}\n", f,
                    rows[f].time, l.solid, l.constraint, l.kind, l.nodes, l.force[0], l.force[1],
                    l.force[2], l.displacement[0], l.displacement[1], l.displacement[2]);
        m_folder.write("supports.csv", supports);
    }
}

std::vector<int> FrameWriter::write_mesh(const MeshFrame& mesh, int frame, Real time) {
    // File 0 is the geometry (rest positions and tetrahedra: it changes only when a mesh is
    // rebuilt, split or merged), file k the k-th array. Each is written when its bytes differ
    // from its newest file's, which the frame otherwise reads again.
    std::vector<std::string> names{ensight_file("mesh", "", frame)};
    std::vector<std::string> bytes{ensight_geometry_bytes(mesh.nodes, mesh.tets)};
    for (const PointArray& array : mesh.nodes.arrays) {
        names.push_back(ensight_file("mesh", array.name, frame));
        bytes.push_back(ensight_variable_bytes(mesh.nodes, array));
    }
    const std::vector<int>* previous = nullptr;
    for (const FrameHistory::Written& w : m_history.written)
        if (w.mesh) previous = &w.mesh_files;
    std::vector<std::uint64_t>& hashes = m_history.mesh_hashes;
    const bool same_layout = previous && previous->size() == bytes.size();
    if (!same_layout) hashes.assign(bytes.size(), 0);
    std::vector<int> files(bytes.size());
    for (size_t k = 0; k < bytes.size(); ++k) {
        const std::uint64_t hash = fnv1a(bytes[k]);
        if (same_layout && hash == hashes[k]) {
            files[k] = (*previous)[k];
            continue;
        }
        m_folder.write(names[k], bytes[k]);
        hashes[k] = hash, files[k] = frame;
    }
    std::vector<EnsightStep> steps;
    for (int f = 0; f < frames(); ++f)
        if (m_history.written[f].mesh && m_history.written[f].mesh_files.size() == files.size())
            steps.push_back({m_history.log[f].time, m_history.written[f].mesh_files});
    steps.push_back({time, files});
    m_folder.write("mesh.case", ensight_case_bytes("mesh", mesh.nodes, steps));
    return files;
}

CrackFrame crack_frame(const std::vector<CrackRecord>& cracks) {
    constexpr int k_sides = 16;
    CrackFrame frame;
    std::vector<Vec3> normal;
    std::vector<Real> radius, area, time, round;
    for (const CrackRecord& c : cracks) {
        // Two unit vectors spanning the crack plane.
        const Vec3 a = c.normal.unitOrthogonal(), b = c.normal.cross(a);
        std::vector<Index> polygon;
        for (int k = 0; k < k_sides; ++k) {
            const Real angle = 2 * std::numbers::pi * k / k_sides;
            polygon.push_back(Index(frame.vertices.x.size()));
            frame.vertices.x.push_back(c.centre +
                                       c.radius * (std::cos(angle) * a + std::sin(angle) * b));
            normal.push_back(c.normal), radius.push_back(c.radius), area.push_back(c.area),
                time.push_back(c.time), round.push_back(c.round);
        }
        frame.polygons.push_back(std::move(polygon));
    }
    frame.vertices.add_vector("normal", normal);
    frame.vertices.add_scalar("radius", radius);
    frame.vertices.add_scalar("area", area);
    frame.vertices.add_scalar("time", time);
    frame.vertices.add_scalar("round", round);
    return frame;
}

void FrameWriter::write_surface(const std::string& stem, const SurfaceMesh& mesh) {
    m_folder.write(stem + ".ply", ply_bytes(mesh));
    // VTK gets the colour as a float RGB array in [0, 1] (ParaView: untick Map Scalars).
    PointSet vertices = mesh.vertices;
    if (!mesh.colour.empty()) {
        std::vector<Vec3> colour(mesh.colour.size());
        for (size_t v = 0; v < colour.size(); ++v)
            colour[v] = Vec3(mesh.colour[v][0], mesh.colour[v][1], mesh.colour[v][2]) / 255;
        vertices.add_vector("colour", colour);
    }
    std::vector<std::vector<Index>> polygons(mesh.triangles.size());
    for (size_t f = 0; f < polygons.size(); ++f)
        polygons[f].assign(mesh.triangles[f].begin(), mesh.triangles[f].end());
    m_folder.write(stem + ".vtp", vtp_polygons_bytes(vertices, polygons, m_settings.compress));
}

void FrameWriter::write_stats(const nlohmann::json& stats) {
    m_folder.write("stats.json", stats.dump(2) + "\n");
}

}  // namespace karst
