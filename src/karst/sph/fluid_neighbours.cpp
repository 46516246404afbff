#include "karst/sph/fluid_neighbours.hpp"

namespace karst {

void update_fluid_neighbours(const Model& model, State& state) {
    if (state.steps % model.scene.sort_interval == 0)
        permute_attributes(state.fluid, morton_order(model.grid, state.fluid.x));
    FluidScratch& s = state.scratch;
    sort_into_cells(model.grid, state.fluid.x, s.cells);
    find_neighbours(model.grid, state.fluid.x, s.cells, true, s.fluid_fluid);
    find_neighbours(model.grid, state.fluid.x, model.walls.cells, false, s.fluid_wall);
    // No porous neighbours until coupling/porous_neighbours.cpp lists them (scenes without porous
    // solids never do).
    s.fluid_porous.count.assign(state.fluid.size(), 0);
}

}  // namespace karst
