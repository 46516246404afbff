#include "karst/core/parallel.hpp"

#include <tbb/global_control.h>
#include <tbb/info.h>

#include <algorithm>

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
    // A limit above the machine's cores allows threads that the default arena never makes.
    return static_cast<int>(std::min<size_t>(
        tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism),
        size_t(tbb::info::default_concurrency())));
}

}  // namespace karst
