#include "karst/coupling/porous_neighbours.hpp"

namespace karst {

void update_porous_neighbours(const Model& model, State& state) {
    const std::vector<Vec3>& x = state.porous.particles.x;
    PorousScratch& s = state.porous_scratch;
    sort_into_cells(model.grid, x, s.cells);
    find_neighbours(model.grid, state.fluid.x, s.cells, false, state.scratch.fluid_porous);
    find_neighbours(model.grid, x, model.walls.cells, false, s.porous_wall);
    find_neighbours(model.grid, x, s.cells, true, s.porous_porous);
    find_neighbours(model.grid, x, state.scratch.cells, false, s.porous_fluid);
}

}  // namespace karst
