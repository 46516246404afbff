#pragma once
// The immutable model (style.md P3): everything the scene fixes for the whole run, including the
// static wall particles, their Akinci volumes and their cell-sorted layout. Built once from a
// Scene; all geometry checks that refuse a scene happen here, before simulating.
#include "karst/core/types.hpp"
#include "karst/porous/dissolution.hpp"
#include "karst/porous/pore_water.hpp"
#include "karst/scene/scene.hpp"
#include "karst/sph/kernels.hpp"
#include "karst/sph/neighbour_grid.hpp"

#include <vector>

namespace karst {

/// Static boundary particles (Akinci 2012), stored in cell order of `grid`.
struct WallParticles {
    std::vector<Vec3> x;    ///< (n), m
    std::vector<Real> psi;  ///< (n), Psi_k = rho0 V_b,k, kg/m^3 * m^3 = kg
    CellRanges cells;       ///< particle ranges per grid cell
    Index size() const { return Index(x.size()); }
};

/// The particles of one porous solid at rest (docs/method.md §2). The PFEM mesh is built on rest_x.
struct PorousBody {
    Index solid = 0;                      ///< index into scene.porous_solids
    std::vector<Vec3> rest_x;             ///< (n), m
    std::vector<Mat3> body_permeability;  ///< (n) K0 (M12 / M28), m^2
};

struct Model {
    Scene scene;
    Real dx = 0;             ///< particle spacing, m
    Real h = 0;              ///< support radius 2 dx, m
    Real rho0 = 1000;        ///< kg/m^3
    Real particle_mass = 0;  ///< m_f0 = rho0 dx^3, kg
    Real lattice_volume =
        0;  ///< dx^3 / (dx^3 sum_lattice W): a boundary lattice site's volume, m^3
    CubicKernel kernel{1.0};
    /// |sum grad W|^2 + sum |grad W|^2 on a full lattice neighbourhood (1/m^8): the prototype
    /// particle of M8, fixed by the lattice, so delta(dt) is closed-form.
    Real pcisph_prototype_sum = 0;
    Aabb domain;
    UniformGrid grid;
    WallParticles walls;
    std::vector<Vec3> initial_x;              ///< fluid particles at t = 0, m
    std::vector<Vec3> initial_v;              ///< m/s
    std::vector<Real> initial_concentration;  ///< C = m_sol / m
    std::vector<PorousBody> porous;
    /// Per material (= per scene solid): the pore-water law and when it dissolves.
    std::vector<PoreWaterLaw> pore_laws;
    std::vector<DissolutionThreshold> dissolution;
    UniformGrid porous_grid;  ///< cell = the longest porous kernel reach (M13), at least h
    /// Porous solids run coupled with the fluid as rigid fragments; else they are poroelastic-only.
    bool coupled() const { return !porous.empty() && (!initial_x.empty() || any_free_solid()); }
    /// Porous solids alone, all anchored, no fluid: the Biot solver runs by itself.
    bool poroelastic_only() const { return !porous.empty() && !coupled(); }
    bool any_free_solid() const {
        for (const PorousSolid& s : scene.porous_solids)
            if (!s.anchored) return true;
        return false;
    }

    /// M8: delta = rho0^2 / (2 dt^2 m^2 (|sum grad W|^2 + sum |grad W|^2)), in Pa per kg/m^3.
    Real pcisph_delta(Real dt) const {
        return rho0 * rho0 / (2 * dt * dt * particle_mass * particle_mass * pcisph_prototype_sum);
    }
};

/// Most particles a scene may have (fluid + porous + walls).
inline constexpr double k_max_particles = 50e6;
/// Peak memory of a run per particle, rounded up from the peak resident size of the default
/// scene (15,000 fluid and 29,680 wall particles: 48 MB over the 13 MB of an empty run) and of
/// cave_soak (meshed porous particles: the PFEM mesh, its links
/// and the Biot factorisation dominate); the scene is refused when its estimate exceeds the
/// memory available.
inline constexpr double k_bytes_per_sph_particle = 2e3;
/// A wall particle holds its position and volume and sits in the cell lists, no neighbour list.
inline constexpr double k_bytes_per_wall_particle = 500;
inline constexpr double k_bytes_per_porous_particle = 40e3;

/// Samples the scene and checks its geometry; throws SceneError for empty or overlapping
/// geometry, a domain not holding the particles, or more than k_max_particles particles.
Model build_model(const Scene& scene);

}  // namespace karst
