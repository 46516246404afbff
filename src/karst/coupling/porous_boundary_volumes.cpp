#include "karst/coupling/porous_boundary_volumes.hpp"

#include "karst/core/parallel.hpp"

namespace karst {

void update_porous_boundary_volumes(const Model& model, State& state) {
    const std::vector<Vec3>& x = state.porous.particles.x;
    PorousScratch& s = state.porous_scratch;
    const CubicKernel& W = model.kernel;
    s.psi.resize(x.size());
    parallel_for(Index(x.size()), [&](Index k) {
        Real sum = W.w0();
        s.porous_porous.for_each(k,
                                 [&](Index l) { sum += W.w((x[k] - x[l]).norm()); });  // 0 beyond h
        s.porous_wall.for_each(k, [&](Index l) { sum += W.w((x[k] - model.walls.x[l]).norm()); });
        s.psi[k] = model.rho0 * std::min(model.lattice_volume, 1 / sum);
    });
}

}  // namespace karst
