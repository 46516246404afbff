#pragma once
// Wall-clock stopwatch for stage profiles and progress.
#include <chrono>

namespace karst {

class Stopwatch {
public:
    Stopwatch() : m_start(Clock::now()) {}
    /// Seconds since construction or the last restart().
    double seconds() const { return std::chrono::duration<double>(Clock::now() - m_start).count(); }
    void restart() { m_start = Clock::now(); }

private:
    using Clock = std::chrono::steady_clock;
    Clock::time_point m_start;
};

}  // namespace karst
