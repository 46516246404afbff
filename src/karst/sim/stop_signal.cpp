#include "karst/sim/stop_signal.hpp"

#include <csignal>

namespace karst {

namespace {

volatile std::sig_atomic_t g_signal = 0;

extern "C" void record_signal(int signal) {
    g_signal = signal;
}

}  // namespace

void catch_stop_signals() {
    std::signal(SIGINT, record_signal);
    std::signal(SIGTERM, record_signal);
}

int stop_signal() {
    return g_signal;
}

}  // namespace karst
