#pragma once
// Internal invariant checks (style.md P8). User-facing input errors are SceneError, not these.
#include <fmt/core.h>
#include <stdexcept>
#include <string>

namespace karst {

/// An internal invariant broke: a bug in karst, not in the user's input.
struct InternalError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

/// A numerical method failed on what the input made of it (a singular stiffness matrix, a
/// solver that did not converge): not a bug. The step turns it into a WatchdogError naming the
/// stage and time, and the run ends on either loudly, with stats.json.
struct NumericalFailure : std::runtime_error {
    using std::runtime_error::runtime_error;
};

[[noreturn]] inline void fail_check(const char* expr, const char* file, int line,
                                    const std::string& what) {
    throw InternalError(fmt::format("{}:{}: check '{}' failed{}{}", file, line, expr,
                                    what.empty() ? "" : ": ", what));
}

}  // namespace karst

/// Always on and cheap.
#define KARST_CHECK(cond, ...)                                                                    \
    do {                                                                                          \
        if (!(cond)) ::karst::fail_check(#cond, __FILE__, __LINE__, fmt::format("" __VA_ARGS__)); \
    } while (false)

/// Debug builds only.
#ifdef NDEBUG
#define KARST_DCHECK(cond, ...) ((void)0)
#else
#define KARST_DCHECK(cond, ...) KARST_CHECK(cond, __VA_ARGS__)
#endif
