#include "karst/core/parallel.hpp"

#include <tbb/global_control.h>

#include <memory>

namespace karst {

struct ThreadLimit::Impl {
    std::unique_ptr<tbb::global_control> control;
};

ThreadLimit::ThreadLimit(int threads) : m_impl(new Impl) {
    if (threads > 0)
        m_impl->control = std::make_unique<tbb::global_control>(
            tbb::global_control::max_allowed_parallelism, static_cast<size_t>(threads));
}

ThreadLimit::~ThreadLimit() {
    delete m_impl;
}

int ThreadLimit::active_threads() {
    return static_cast<int>(
        tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));
}

}  // namespace karst
