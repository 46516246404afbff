#include "karst/sim/watchdog.hpp"

#include "karst/core/parallel.hpp"

#include <fmt/format.h>

#include <cmath>

namespace karst {

WatchdogError::WatchdogError(std::string_view stage_, std::int64_t particle_id_, Real time_,
                             const std::string& what)
    : std::runtime_error(fmt::format("watchdog: {} in stage '{}' at particle {} (t = {:.6f} s)",
                                     what, stage_, particle_id_, time_)),
      stage(stage_),
      particle_id(particle_id_),
      time(time_) {}

WatchdogError::WatchdogError(std::string_view stage_, Real time_, const std::string& what)
    : std::runtime_error(
          fmt::format("watchdog: {} in stage '{}' (t = {:.6f} s)", what, stage_, time_)),
      stage(stage_),
      particle_id(-1),
      time(time_) {}

namespace {

/// Index of the first bad entry, or n: the smallest bad index, whatever the thread count.
template <class Bad>
Index first_bad(Index n, const Bad& bad) {
    const Real first =
        -parallel_max(n, -Real(n), [&](Index i) { return bad(i) ? -Real(i) : -Real(n); });
    return Index(first);
}

}  // namespace

void check_vectors(const std::vector<Vec3>& values, const std::vector<std::int64_t>& id,
                   Stage stage, Real time, const char* quantity, Real max_norm) {
    const Index n = Index(values.size());
    const Index i = first_bad(n, [&](Index k) {
        const Real s = values[k].squaredNorm();
        return !std::isfinite(s) || (max_norm > 0 && s > max_norm * max_norm);
    });
    if (i == n) return;
    const Real norm = values[i].norm();
    const std::string what = std::isfinite(norm)
                                 ? fmt::format("{} of magnitude {:.4g} exceeds the limit {:.4g}",
                                               quantity, norm, max_norm)
                                 : fmt::format("non-finite {}", quantity);
    throw WatchdogError(k_stage_names[size_t(stage)], id.empty() ? i : id[i], time, what);
}

void check_scalars(const std::vector<Real>& values, const std::vector<std::int64_t>& id,
                   Stage stage, Real time, const char* quantity) {
    const Index n = Index(values.size());
    const Index i = first_bad(n, [&](Index k) { return !std::isfinite(values[k]); });
    if (i == n) return;
    throw WatchdogError(k_stage_names[size_t(stage)], id.empty() ? i : id[i], time,
                        fmt::format("non-finite {}", quantity));
}

void check_structures(const StructureState& structures, Stage stage, Real time) {
    for (const Structure& s : structures.structures) {
        check_vectors(s.fields.u, s.node_id, stage, time, "displacement (Biot)");
        check_scalars(s.fields.p, s.node_id, stage, time, "pore pressure (Biot)");
    }
}

}  // namespace karst
