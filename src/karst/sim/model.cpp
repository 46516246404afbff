#include "karst/sim/model.hpp"

#include "karst/core/parallel.hpp"
#include "karst/pfem/alpha_shape_weight.hpp"
#include "karst/porous/permeability.hpp"
#include "karst/scene/scene_error.hpp"
#include "karst/sim/porous_materials.hpp"
#include "karst/sph/integrate.hpp"
#include "karst/sph/neighbour_grid.hpp"

#include <fmt/format.h>

#include <fmt/ostream.h>

#include <unistd.h>

#include <algorithm>
#include <fstream>
#include <limits>
#include <numeric>
#include <unordered_map>
#include <unordered_set>

namespace karst {

namespace {

constexpr Real inf = std::numeric_limits<Real>::infinity();
constexpr std::int64_t k_max_lattice_index = std::int64_t(1) << 20;  ///< 21 bits per axis

/// Packs a lattice index into one key (21 bits per axis, offset so negatives fit).
std::uint64_t lattice_key(const LatticeIndex& i) {
    constexpr std::int64_t off = k_max_lattice_index;
    return std::uint64_t(i[0] + off) | std::uint64_t(i[1] + off) << 21 |
           std::uint64_t(i[2] + off) << 42;
}

/// Signed-distance band that a wall's particles fill (method: Akinci 2012 boundary skin).
std::pair<Real, Real> wall_band(const Wall& w, Real dx) {
    const Real t = w.layers * dx;
    return w.kind == Wall::Kind::Container ? std::pair{Real(0), t} : std::pair{-t, Real(0)};
}

/// Every sampled shape lies within k_max_lattice_index spacings of the origin, so lattice
/// indices neither overflow nor collide in lattice_key, and counting them stays finite.
void check_lattice_extent(const Shape& shape, Real dx, Real reach, const std::string& path) {
    const Aabb box = shape.bounds().padded(reach);
    const double limit = double(k_max_lattice_index - 2) * dx;
    for (int d = 0; d < 3; ++d)
        if (!(std::abs(box.min[d]) < limit && std::abs(box.max[d]) < limit))
            throw SceneError(
                path,
                fmt::format("a shape within {:g} m of the origin on each axis "
                            "({} spacings of {:g} m)",
                            limit, k_max_lattice_index - 2, dx),
                fmt::format("one reaching {:g} m on axis {}",
                            std::abs(box.min[d]) > std::abs(box.max[d]) ? box.min[d] : box.max[d],
                            "xyz"[d]));
}

/// Bytes this process may still take: MemAvailable of /proc/meminfo, else the physical memory.
double available_memory_bytes() {
    std::ifstream meminfo("/proc/meminfo");
    std::string key;
    double kib = 0;
    while (meminfo >> key >> kib)
        if (key == "MemAvailable:") return kib * 1024;
    return double(sysconf(_SC_PHYS_PAGES)) * double(sysconf(_SC_PAGE_SIZE));
}

/// The neighbour grid covers the domain: the scene's, or the box around every shape (walls with
/// their layers) grown by 4 h, which holds the box build_model makes around the particles. Checked
/// before any sampling, whose cost grows with a shape's box: a union of two spheres 300 m apart
/// sampled for an hour. h = 2 dx as in build_model.
void check_domain_grid(const Scene& s, Real h) {
    if (s.domain) {
        (void)UniformGrid(*s.domain, h);  // refuses at /domain
        return;
    }
    Aabb box;
    for (const FluidBlock& b : s.fluid_blocks) box.extend(b.shape.bounds());
    for (const PorousSolid& p : s.porous_solids) box.extend(p.shape.bounds());
    for (const Wall& w : s.walls)
        box.extend(w.shape.bounds().padded(w.layers * s.particle_spacing));
    box = box.padded(4 * h);
    const double cells = grid_cell_count(box, h);
    if (!(cells <= k_max_grid_cells)) {
        const Vec3 size = box.max - box.min;
        throw SceneError(
            "/particle_spacing",
            fmt::format("shapes within a box of at most {:g} cells of h = 2 x spacing (the "
                        "neighbour grid; or set /domain)",
                        k_max_grid_cells),
            fmt::format("{} m, with shapes spanning {:.3g} x {:.3g} x {:.3g} m: {:.3g} cells",
                        s.particle_spacing, size[0], size[1], size[2], cells));
    }
}

/// Particles and the memory a run of them needs, estimated before anything is allocated, so a
/// scene too large for the machine is refused instead of dying of bad_alloc mid-run.
void check_particle_budget(const Scene& s) {
    const Real dx = s.particle_spacing;
    for (const FluidBlock& b : s.fluid_blocks)
        check_lattice_extent(b.shape, dx, 0, b.path + "/shape");
    for (const PorousSolid& p : s.porous_solids)
        check_lattice_extent(p.shape, dx, 0, p.path + "/shape");
    for (const Wall& w : s.walls)
        check_lattice_extent(w.shape, dx, w.layers * dx, w.path + "/shape");
    check_domain_grid(s, 2 * dx);
    double fluid = 0, porous = 0, walls = 0;
    // Each loop stops once the cap is passed: a scene of thousands of blocks is refused at once.
    for (const FluidBlock& b : s.fluid_blocks) {
        if (fluid > k_max_particles) break;
        fluid += estimate_lattice_count(b.shape, dx, -inf, 0, k_max_particles - fluid);
    }
    for (const PorousSolid& p : s.porous_solids) {
        if (fluid + porous > k_max_particles) break;
        porous += estimate_lattice_count(p.shape, dx, -inf, 0, k_max_particles - fluid - porous);
    }
    for (const Wall& w : s.walls) {
        if (fluid + porous + walls > k_max_particles) break;
        const auto [lo, hi] = wall_band(w, dx);
        walls +=
            estimate_lattice_count(w.shape, dx, lo, hi, k_max_particles - fluid - porous - walls);
    }
    const double total = fluid + porous + walls;
    if (total > k_max_particles)
        throw SceneError(
            "/particle_spacing",
            fmt::format("a spacing giving at most {:g} million particles", k_max_particles / 1e6),
            fmt::format("{} m, which gives about {:.3g} million", dx, total / 1e6));
    const double need = k_bytes_per_sph_particle * fluid + k_bytes_per_wall_particle * walls +
                        k_bytes_per_porous_particle * porous;
    const double have = available_memory_bytes();
    if (need > have)
        throw SceneError(
            "/particle_spacing",
            fmt::format("a spacing whose particles fit in the {:.3g} GB of memory available",
                        have / 1e9),
            fmt::format("{} m: about {:.3g} million particles needing about {:.3g} GB", dx,
                        total / 1e6, need / 1e9));
}

/// A constraint or wet region that selects none of its solid's particles is a mistake (a fixed
/// region that missed its block lets it fly away): refused. Constraints select the nodes within
/// 3/4 dx of their region (pfem/biot_setup.cpp), wet regions the particles inside.
void check_regions_select_particles(const Model& m) {
    for (const PorousBody& body : m.porous) {
        const PorousSolid& solid = m.scene.porous_solids[body.solid];
        auto selects = [&](const Shape& region, Real reach) {
            return std::any_of(body.rest_x.begin(), body.rest_x.end(),
                               [&](const Vec3& x) { return region.signed_distance(x) <= reach; });
        };
        const std::string found = fmt::format(
            "a region that selects none of the solid's {} particles", body.rest_x.size());
        for (const Constraint& c : solid.constraints)
            if (!selects(c.region, 0.75 * m.dx))
                throw SceneError(c.path + "/region",
                                 "a region reaching the solid (within 0.75 spacings)", found);
        for (size_t w = 0; w < solid.wet_regions.size(); ++w)
            if (!selects(solid.wet_regions[w].region, 0))
                throw SceneError(fmt::format("{}/wet_regions/{}/region", solid.path, w),
                                 "a region holding some of the solid's particles", found);
    }
}

/// A run of more steps than this is a scene error (a step of 1e-300 s), not a long run.
constexpr Real k_max_steps = 1e8;
/// Frames one run may write (each is a set of files).
constexpr Real k_max_frames = 1e5;

void check_step_counts(const Scene& s) {
    const Real end = s.time.end;
    auto check = [&](Real step, const char* path) {
        if (end / step > k_max_steps)
            throw SceneError(path,
                             fmt::format("a step of at least end / {:g} = {:.3g} s", k_max_steps,
                                         end / k_max_steps),
                             fmt::format("{:.3g} s", step));
    };
    if (s.time.fixed_dt) check(*s.time.fixed_dt, "/time/fixed_dt");
    if (end * s.output.fps > k_max_frames)
        throw SceneError(
            "/output/fps",
            fmt::format("at most {:g} frames over the {:g} s run", k_max_frames, end),
            fmt::format("{:g} per second, {:.3g} frames", s.output.fps, end * s.output.fps));
    if (!s.porous_solids.empty()) check(s.poroelastic.time_step, "/poroelastic/time_step");
}

/// A viscosity the explicit step cannot carry (sph/integrate.hpp, viscous_step_limit) is refused
/// before simulating: a fixed step above its bound, or a bound below dt_min.
void check_viscous_step(const Scene& s) {
    const Real limit = viscous_step_limit(s.fluid, s.particle_spacing);
    const Real artificial = artificial_kinematic_viscosity(s.fluid, s.particle_spacing);
    const std::string found = fmt::format(
        "nu = {:g} m^2/s and alpha_v = {:g}, c_s = {:g} m/s (whose share of nu_eff is "
        "{:.3g} m^2/s): a bound of {:.3g} s",
        s.fluid.viscosity, s.fluid.artificial_viscosity, s.fluid.sound_speed, artificial, limit);
    // Against the step the run takes: a fixed step longer than the run is cut to its end.
    if (s.time.fixed_dt && std::min(*s.time.fixed_dt, s.time.end) > limit)
        throw SceneError("/time/fixed_dt",
                         fmt::format("a step within the stable step {:g} dx^2 / nu_eff of the "
                                     "viscosity ({})",
                                     k_viscous_step, found),
                         fmt::format("{:.3g} s", *s.time.fixed_dt));
    if (!s.time.fixed_dt && limit < s.time.dt_min)
        throw SceneError(
            s.fluid.viscosity >= artificial ? "/fluid/viscosity" : "/fluid/artificial_viscosity",
            fmt::format("a viscosity whose stable step, {:g} dx^2 / nu_eff, is at "
                        "least /time/dt_min = {:.3g} s (or a coarser spacing)",
                        k_viscous_step, s.time.dt_min),
            found);
}

/// Fluid blocks and porous solids on the scene lattice; no lattice site may be taken twice.
void sample_fluid_and_solids(const Scene& s, Model& m) {
    const Real dx = s.particle_spacing;
    std::unordered_map<std::uint64_t, const std::string*> owner;  // lattice key -> owner path
    auto sample = [&](const Shape& shape, const std::string& path, const auto& take) {
        const auto points = sample_lattice(shape, dx, -inf, 0);
        if (points.empty())
            throw SceneError(
                path + "/shape",
                fmt::format("a shape holding at least one particle at spacing {} m", dx),
                "an empty shape");
        for (const LatticeIndex& p : points) {
            const auto [it, fresh] = owner.emplace(lattice_key(p), &path);
            if (!fresh)
                throw SceneError(path + "/shape",
                                 "fluid blocks and porous solids that do not overlap",
                                 fmt::format("an overlap with {} near {}", *it->second,
                                             fmt::streamed(lattice_point(p, dx).transpose())));
            take(lattice_point(p, dx));
        }
    };
    for (const FluidBlock& block : s.fluid_blocks)
        sample(block.shape, block.path, [&](const Vec3& x) {
            m.initial_x.push_back(x), m.initial_v.push_back(block.velocity),
                m.initial_concentration.push_back(block.concentration);
        });
    // Porous solids sit on the exact lattice: jitter would give the mesh interior slivers
    // (pfem/box_nodes.hpp says why).
    for (size_t i = 0; i < s.porous_solids.size(); ++i) {
        PorousBody body;
        body.solid = Index(i);
        sample(s.porous_solids[i].shape, s.porous_solids[i].path,
               [&](const Vec3& x) { body.rest_x.push_back(x); });
        m.porous.push_back(std::move(body));
    }
}

void sample_walls(const Scene& s, Model& m, std::vector<int>& layers) {
    const Real dx = s.particle_spacing;
    std::unordered_set<std::uint64_t> taken;  // walls may touch or overlap each other: merge points
    for (const Wall& w : s.walls) {
        const auto [lo, hi] = wall_band(w, dx);
        const auto points = sample_lattice(w.shape, dx, lo, hi);
        if (points.empty())
            throw SceneError(
                w.path + "/shape",
                fmt::format("a shape holding at least one particle at spacing {} m", dx),
                "an empty shape");
        for (const LatticeIndex& p : points)
            if (taken.insert(lattice_key(p)).second)
                m.walls.x.push_back(lattice_point(p, dx)), layers.push_back(w.layers);
    }
    // Porous solids must not overlap an obstacle or stick out of a container.
    for (const Wall& w : s.walls)
        for (const PorousBody& body : m.porous)
            for (const Vec3& x : body.rest_x) {
                const Real d = w.shape.signed_distance(x);
                if (w.kind == Wall::Kind::Container ? d > 0 : d <= 0)
                    throw SceneError(
                        s.porous_solids[body.solid].path + "/shape",
                        w.kind == Wall::Kind::Container
                            ? fmt::format("a solid inside the container {}", w.path)
                            : fmt::format("a solid not overlapping the obstacle {}", w.path),
                        fmt::format("a particle at {}", fmt::streamed(x.transpose())));
            }
    // Fluid must not start inside an obstacle, nor outside a container's cavity.
    for (const Wall& w : s.walls) {
        for (size_t i = 0; i < m.initial_x.size(); ++i) {
            const Real d = w.shape.signed_distance(m.initial_x[i]);
            const bool bad = w.kind == Wall::Kind::Container ? d > 0 : d <= 0;
            if (bad)
                throw SceneError(
                    w.path + "/shape",
                    w.kind == Wall::Kind::Container ? "a container holding all fluid"
                                                    : "an obstacle not overlapping fluid",
                    fmt::format("fluid at {}", fmt::streamed(m.initial_x[i].transpose())));
        }
    }
}

/// M8 prototype: a particle with a full lattice neighbourhood.
Real prototype_sum(const CubicKernel& kernel, Real dx) {
    Vec3 sum_grad = Vec3::Zero();
    Real sum_sq = 0;
    for (int k = -2; k <= 2; ++k)
        for (int j = -2; j <= 2; ++j)
            for (int i = -2; i <= 2; ++i) {
                const Vec3 g = kernel.gradient(Vec3(i, j, k) * dx);
                sum_grad += g;
                sum_sq += g.squaredNorm();
            }
    return sum_grad.squaredNorm() + sum_sq;
}

/// Calibration of Akinci volumes [D]. A wall of `layers` lattice layers under a resting fluid
/// lattice: V_b = 1 / sum_l W_kl exceeds dx^3 (the wall sees fewer neighbours than the fluid it
/// stands for), so the first fluid layer starts over-dense (6 % for one layer at h = 2 dx, 15 %
/// in corners), and PCISPH spends its first steps in a violent correction. The factor
/// gamma = (rho0 - fluid part) / (wall part) on a flat prototype wall makes that layer exactly
/// rho0.
Real akinci_calibration(const CubicKernel& W, Real dx, Real rho0, Real mass, int layers) {
    const int reach = 3;  // lattice offsets beyond the support (h = 2 dx) contribute nothing
    // Wall particles at z = -(l + 1/2) dx, l < layers; fluid at z = (k + 1/2) dx, k >= 0.
    auto wall_volume = [&](int layer) {
        Real sum = 0;
        for (int l = 0; l < layers; ++l)
            for (int j = -reach; j <= reach; ++j)
                for (int i = -reach; i <= reach; ++i)
                    sum += W.w((Vec3(i, j, l - layer) * dx).norm());
        return 1 / sum;
    };
    Real fluid = 0, wall = 0;
    for (int j = -reach; j <= reach; ++j)
        for (int i = -reach; i <= reach; ++i) {
            for (int k = 0; k <= reach; ++k) fluid += mass * W.w((Vec3(i, j, k) * dx).norm());
            for (int l = 0; l < layers; ++l)
                wall += rho0 * wall_volume(l) * W.w((Vec3(i, j, l + 1) * dx).norm());
        }
    return (rho0 - fluid) / wall;
}

/// The volume of one lattice particle as the fluid's density sum sees it: dx^3 / N with
/// N = dx^3 sum_lattice W, so that rho0 V_lattice sum_lattice W = rho0 exactly.
Real lattice_volume(const CubicKernel& W, Real dx) {
    Real sum = 0;
    for (int k = -2; k <= 2; ++k)
        for (int j = -2; j <= 2; ++j)
            for (int i = -2; i <= 2; ++i) sum += W.w((Vec3(i, j, k) * dx).norm());
    return 1 / sum;
}

/// Boundary weights Psi_k = rho0 V_k (docs/method.md §4.1) of static walls.
/// [D] Walls of two or more layers are lattice sites, like the fluid, and fill the kernel's
/// support beyond the surface, so V_k = the lattice volume makes a resting fluid lattice exactly
/// rho0 beside flat walls, edges and corners alike; it is capped by the Akinci volume
/// V_b,k = 1 / sum_l W_kl (walls l, k included) where walls crowd closer than the lattice
/// (overlapping walls). The Akinci volume alone, scaled to make a flat wall exact, left
/// vertical edges 0.7 % and bottom corners 1.8 % under-dense: those particles then sat at p = 0,
/// were pushed into the corner by their neighbours and shot out again, and a resting 0.4 x 0.4 x
/// 0.2 m tank at nu = 1e-4 reached 6 m/s within 0.6 s. A one-layer wall cannot fill the support,
/// so it keeps the Akinci volume scaled by gamma (akinci_calibration).
void compute_wall_volumes(Model& m, const std::vector<int>& layers) {
    WallParticles& w = m.walls;
    sort_into_cells(m.grid, w.x, w.cells);
    w.x = w.cells.sorted_x;  // store walls in cell order, so cell ranges index x directly
    std::vector<int> sorted_layers(w.x.size());
    for (size_t s = 0; s < w.x.size(); ++s) sorted_layers[s] = layers[w.cells.order[s]];
    const Real gamma_thin = akinci_calibration(m.kernel, m.dx, m.rho0, m.particle_mass, 1);
    std::iota(w.cells.order.begin(), w.cells.order.end(), 0u);
    NeighbourLists lists;
    find_neighbours(m.grid, w.x, w.cells, true, lists);
    w.psi.resize(w.x.size());
    parallel_for(w.size(), [&](Index k) {
        Real sum = m.kernel.w0();
        lists.for_each(k, [&](Index l) { sum += m.kernel.w((w.x[k] - w.x[l]).norm()); });
        w.psi[k] = m.rho0 *
                   (sorted_layers[k] == 1 ? gamma_thin / sum : std::min(m.lattice_volume, 1 / sum));
    });
}

/// Per-material laws, K0 per particle and the pore-flow grid.
void set_up_porous_materials(Model& m) {
    Real reach = m.h;
    for (PorousBody& body : m.porous) {
        const PorousSolid& solid = m.scene.porous_solids[body.solid];
        body.body_permeability = body_permeabilities(solid.material, body.rest_x, m.h);
        for (const Mat3& K : body.body_permeability) reach = std::max(reach, kernel_reach(K, m.h));
    }
    for (const PorousSolid& solid : m.scene.porous_solids) {
        m.pore_laws.push_back(pore_water_law(solid.material, m.rho0, m.scene.gravity));
        m.dissolution.push_back({solid.material.dissolution_saturation,
                                 solid.material.dissolution_porosity,
                                 solid.material.solid_density});
    }
    m.porous_grid = UniformGrid(m.domain, reach);
}

/// Whether some cube of the lattice holds four particles of `points` off one plane, so that the
/// Delaunay mesh of the solid has a tetrahedron no larger than a lattice cell's (its
/// circumsphere, the cell's, holds no other lattice point). A sheet one particle thick, a line,
/// and a rod along a diagonal, whose particles touch only at corners, have none.
bool holds_a_lattice_cell_tetrahedron(const std::vector<Vec3>& points, Real dx) {
    const auto index = [&](const Vec3& x) {
        return LatticeIndex{std::llround(x[0] / dx - 0.5), std::llround(x[1] / dx - 0.5),
                            std::llround(x[2] / dx - 0.5)};
    };
    struct Hash {
        size_t operator()(const LatticeIndex& i) const {
            return std::hash<std::int64_t>()(i[0] * 73856093 ^ i[1] * 19349663 ^ i[2] * 83492791);
        }
    };
    std::unordered_set<LatticeIndex, Hash> occupied;
    for (const Vec3& x : points) {
        const LatticeIndex p = index(x);
        occupied.insert(p);
        for (int corner = 0; corner < 8; ++corner) {
            // The cube whose corner `corner` is p; its occupied vertices.
            const LatticeIndex base{p[0] - (corner & 1), p[1] - (corner >> 1 & 1),
                                    p[2] - (corner >> 2 & 1)};
            std::vector<Vec3> in;  // cube-local coordinates
            for (int v = 0; v < 8; ++v)
                if (occupied.count(
                        {base[0] + (v & 1), base[1] + (v >> 1 & 1), base[2] + (v >> 2 & 1)}))
                    in.push_back(Vec3(v & 1, v >> 1 & 1, v >> 2 & 1));
            for (size_t a = 1; a < in.size(); ++a)
                for (size_t b = a + 1; b < in.size(); ++b)
                    for (size_t c = b + 1; c < in.size(); ++c)
                        if ((in[a] - in[0]).cross(in[b] - in[0]).dot(in[c] - in[0]) != 0)
                            return true;
        }
    }
    return false;
}

/// A solid that gets a Biot problem must mesh into tetrahedra: an alpha that keeps a lattice
/// cell's, and a lattice cell with four of its particles off one plane.
void check_meshable(const Model& m, const PorousBody& body) {
    // A lattice cell's tetrahedra have radius^2 3/4 dx^2 (less the weight when weighted);
    // M19 keeps a tetrahedron below alpha dx.
    const PoroelasticSettings& pe = m.scene.poroelastic;
    const Real cell_radius2 =
        0.75 - (pe.weighted_alpha ? alpha_shape_weight(m.dx) / (m.dx * m.dx) : 0.0);
    if (pe.alpha * pe.alpha <= cell_radius2)
        throw SceneError("/poroelastic/alpha",
                         fmt::format("an alpha above {:.3g} (the {}radius of a lattice cell's "
                                     "tetrahedra over dx): below it no tetrahedron is kept",
                                     std::sqrt(cell_radius2), pe.weighted_alpha ? "ortho" : ""),
                         fmt::format("{:g}", pe.alpha));
    if (holds_a_lattice_cell_tetrahedron(body.rest_x, m.dx)) return;
    Aabb box;
    for (const Vec3& x : body.rest_x) box.extend(x);
    const PorousSolid& s = m.scene.porous_solids[body.solid];
    throw SceneError(
        s.path + "/shape",
        "a solid at least two particles thick along every axis, with four particles off one plane "
        "in some lattice cell (its Biot problem needs tetrahedra)",
        fmt::format("{} particles spanning {:.3g} x {:.3g} x {:.3g} m", body.rest_x.size(),
                    (box.max - box.min)[0], (box.max - box.min)[1], (box.max - box.min)[2]));
}

/// The Biot problems a scene can pose (docs/method.md §5): a poroelastic-only solid needs pores,
/// and in a coupled scene only anchored fragments of permeable solids get one, so constraints on
/// any other solid would be silently ignored.
void check_biot_setup(const Model& m) {
    const Scene& scene = m.scene;
    for (const PorousBody& body : m.porous) {
        const PorousSolid& s = scene.porous_solids[body.solid];
        const bool biot = m.poroelastic_only() ||
                          (scene.poroelastic.coupled_fragments && s.anchored &&
                           !s.constraints.empty() && s.material.porosity >= k_min_porosity);
        if (biot) check_meshable(m, body);
    }
    for (const PorousSolid& s : scene.porous_solids) {
        if (m.poroelastic_only()) {
            if (s.material.porosity < k_min_porosity)
                throw SceneError(s.path + "/material/porosity",
                                 "a porosity of at least 1e-4 in a poroelastic-only scene (an "
                                 "impermeable solid has no pore pressure)",
                                 fmt::format("{}", s.material.porosity));
            continue;
        }
        if (s.constraints.empty()) continue;
        const char* why = !scene.poroelastic.coupled_fragments
                              ? "/poroelastic/coupled_fragments is none"
                          : !s.anchored ? "the solid is free (free fragments move rigidly)"
                          : s.material.porosity < k_min_porosity
                              ? "the solid is impermeable (porosity below 1e-4)"
                              : nullptr;
        if (why)
            throw SceneError(
                s.path + "/constraints",
                fmt::format(
                    "no Biot constraints here: {}, so no Biot problem is solved for this solid",
                    why),
                fmt::format("{} constraints", s.constraints.size()));
    }
}

}  // namespace

Model build_model(const Scene& scene) {
    Model m;
    m.scene = scene;
    m.dx = scene.particle_spacing;
    m.h = 2 * m.dx;
    m.rho0 = scene.fluid.rest_density;
    m.particle_mass = m.rho0 * m.dx * m.dx * m.dx;
    m.kernel = CubicKernel(m.h);
    m.pcisph_prototype_sum = prototype_sum(m.kernel, m.dx);
    m.lattice_volume = lattice_volume(m.kernel, m.dx);

    if (scene.fluid_blocks.empty() && scene.walls.empty() && scene.porous_solids.empty())
        throw SceneError("/fluid_blocks", "at least one fluid block, porous solid or wall",
                         "an empty scene");
    check_step_counts(scene);
    check_particle_budget(scene);
    sample_fluid_and_solids(scene, m);
    // Fluid appears later only by dissolution, which needs fluid to start with.
    if (!m.initial_x.empty()) check_viscous_step(scene);
    std::vector<int> wall_layers;  // per wall particle
    sample_walls(scene, m, wall_layers);

    Aabb all;
    for (const Vec3& x : m.initial_x) all.extend(x);
    for (const Vec3& x : m.walls.x) all.extend(x);
    for (const PorousBody& body : m.porous)
        for (const Vec3& x : body.rest_x) all.extend(x);
    m.domain = scene.domain ? *scene.domain : all.padded(4 * m.h);
    std::vector<const std::vector<Vec3>*> sets{&m.initial_x, &m.walls.x};
    for (const PorousBody& body : m.porous) sets.push_back(&body.rest_x);
    for (const auto* set : sets)
        for (const Vec3& x : *set)
            if (!m.domain.contains(x))
                throw SceneError(
                    "/domain", "a box holding every particle",
                    fmt::format("a particle outside it at {}", fmt::streamed(x.transpose())));
    m.grid = UniformGrid(m.domain, m.h);
    compute_wall_volumes(m, wall_layers);
    check_regions_select_particles(m);
    set_up_porous_materials(m);
    check_biot_setup(m);
    return m;
}

}  // namespace karst
