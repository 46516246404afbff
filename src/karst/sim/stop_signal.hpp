#pragma once
// SIGINT and SIGTERM ask a run to stop after its current step (issue 15), so that it ends with
// a consistent folder and its stats.json instead of dying mid-write. Only the command line
// installs the handlers; a library user's signals are left alone.
namespace karst {

/// Installs the SIGINT and SIGTERM handlers that record the signal.
void catch_stop_signals();
/// The signal that asked the run to stop, 0 if none.
int stop_signal();

}  // namespace karst
