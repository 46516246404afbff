#pragma once
// The one-line progress display on stderr: rewritten in place on a terminal, printed as plain
// periodic lines otherwise (logs, CI).
#include "karst/core/timer.hpp"

#include <string>

namespace karst {

struct ProgressInfo {
    int frame = 0;
    double time = 0, end_time = 0;  ///< simulated, s
    double steps_per_second = 0;
    double mipps = 0;        ///< million particle-steps per second
    double eta_seconds = 0;  ///< wall-clock seconds left
    long long particles = 0;
    double absorbed_kg = -1;  ///< water soaked into porous solids so far; < 0: no porous solids
    long long removed = 0;    ///< fluid particles that left the domain so far
    long long fragments = 0;  ///< rigid fragments with mass (0: no porous solids)
};

class ProgressLine {
public:
    explicit ProgressLine(bool quiet);
    /// Shows `info` if enough wall time has passed since the last line (or `force`).
    void update(const ProgressInfo& info, bool force = false);
    /// Ends the line on a terminal.
    void finish();
    /// Prints a warning on a line of its own (even when quiet).
    void warn(const std::string& message);

private:
    bool m_quiet, m_tty, m_dirty = false;
    Stopwatch m_since_print;
    bool m_printed = false;
};

}  // namespace karst
