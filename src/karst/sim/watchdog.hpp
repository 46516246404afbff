#pragma once
// The per-stage health check (style.md P8): the first NaN, infinity or runaway speed stops the
// run, naming the stage, the particle and the time.
#include "karst/core/types.hpp"
#include "karst/pfem/structure_state.hpp"
#include "karst/sim/step_profile.hpp"

#include <stdexcept>
#include <string>
#include <vector>

namespace karst {

struct WatchdogError : std::runtime_error {
    WatchdogError(std::string_view stage, std::int64_t particle_id, Real time,
                  const std::string& what);
    /// A failure of a stage as a whole (no one particle to blame): particle_id is -1.
    WatchdogError(std::string_view stage, Real time, const std::string& what);
    std::string stage;
    std::int64_t particle_id;
    Real time;
};

/// Throws WatchdogError if any entry of `values` is not finite (or, when max_norm > 0, longer
/// than max_norm), naming `quantity`, the stage and the particle's id (its index when `id` is
/// empty, as for porous particles).
void check_vectors(const std::vector<Vec3>& values, const std::vector<std::int64_t>& id,
                   Stage stage, Real time, const char* quantity, Real max_norm = 0);
void check_scalars(const std::vector<Real>& values, const std::vector<std::int64_t>& id,
                   Stage stage, Real time, const char* quantity);
/// The Biot fields of every structure: a non-finite displacement or pore pressure names the
/// node's porous particle id.
void check_structures(const StructureState& structures, Stage stage, Real time);

}  // namespace karst
