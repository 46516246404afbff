#pragma once
// The pore state of porous particles as the point set of porous_NNNN.vtp (issue 3 output).
#include "karst/io/point_arrays.hpp"
#include "karst/porous/pore_water.hpp"
#include "karst/sph/neighbour_grid.hpp"

#include <span>

namespace karst {

/// Points with saturation, porosity, absorbed_mass, pore_pressure (M5), pore_velocity (M17),
/// fragment and permeability (6 components). `pairs` lists porous neighbours within at least
/// the support radius `h`; M17's gradient uses the isotropic cubic kernel over neighbours of the
/// same fragment.
PointSet porous_points(const PorousParticles& particles, std::span<const PoreWaterLaw> laws,
                       const NeighbourLists& pairs, Real h);

}  // namespace karst
