#include "karst/sim/progress.hpp"

#include <fmt/format.h>

#include <cstdio>
#include <unistd.h>

namespace karst {

ProgressLine::ProgressLine(bool quiet) : m_quiet(quiet), m_tty(isatty(fileno(stderr)) != 0) {}

void ProgressLine::update(const ProgressInfo& p, bool force) {
    if (m_quiet) return;
    const double every = m_tty ? 0.2 : 10.0;  // seconds between refreshes / plain lines
    if (!force && m_printed && m_since_print.seconds() < every) return;
    m_since_print.restart();
    m_printed = true;
    const int eta = int(p.eta_seconds + 0.5);
    const std::string absorbed =
        p.absorbed_kg >= 0 ? fmt::format("  absorbed {:.4g} kg", p.absorbed_kg) : "";
    const std::string removed =
        p.removed > 0 ? fmt::format(" ({} left the domain)", p.removed) : "";
    const std::string fragments =
        p.fragments > 0 ? fmt::format("  {} fragment{}", p.fragments, p.fragments > 1 ? "s" : "")
                        : "";
    const std::string line = fmt::format(
        "frame {:4d}  t {:8.4f}/{:.4g} s  {:7.1f} steps/s  {:6.3f} MIPPS  {} particles{}{}{}  "
        "ETA {:d}:{:02d}:{:02d}",
        p.frame, p.time, p.end_time, p.steps_per_second, p.mipps, p.particles, removed, absorbed,
        fragments, eta / 3600, eta / 60 % 60, eta % 60);
    if (m_tty) {
        fmt::print(stderr, "\r{}\x1b[K", line);
        m_dirty = true;
    } else {
        fmt::print(stderr, "{}\n", line);
    }
    std::fflush(stderr);
}

void ProgressLine::warn(const std::string& message) {
    finish();
    fmt::print(stderr, "warning: {}\n", message);
    std::fflush(stderr);
}

void ProgressLine::finish() {
    if (m_dirty) fmt::print(stderr, "\n");
    m_dirty = false;
}

}  // namespace karst
