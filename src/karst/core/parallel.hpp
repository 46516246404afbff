#pragma once
// The one way karst runs loops in parallel (oneTBB). Kernels are lambdas over an index range, and
// every reduction is formed so that its result does not depend on the number of threads
// (style.md P5): each index writes only its own outputs, and sums go over fixed blocks in order.
#include "karst/core/types.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <vector>

namespace karst {

/// Grain of the parallel loops: large enough to hide scheduling cost for SPH-sized work.
inline constexpr Index k_parallel_grain = 256;

/// Calls body(i) for i in [0, n), in parallel, at least `grain` indices per task. body must write
/// only data owned by index i.
template <class Body>
void parallel_for(Index n, const Body& body, Index grain = k_parallel_grain) {
    tbb::parallel_for(tbb::blocked_range<Index>(0, n, grain),
                      [&](const tbb::blocked_range<Index>& r) {
                          for (Index i = r.begin(); i != r.end(); ++i) body(i);
                      });
}

/// Folds f(i) over [0, n) with `combine` in fixed blocks combined in block order: the same bits
/// on any thread count, for any combine (associative or, like floating-point +, not).
template <class T, class F, class Combine>
T deterministic_reduce(Index n, T identity, const F& f, const Combine& combine) {
    constexpr Index block = 4096;
    const Index blocks = (n + block - 1) / block;
    std::vector<T> partial(static_cast<size_t>(blocks), identity);
    // One task per block: the default grain would keep a few dozen blocks on one thread.
    parallel_for(
        blocks,
        [&](Index b) {
            T acc = identity;
            for (Index i = b * block, e = std::min(n, (b + 1) * block); i < e; ++i)
                acc = combine(acc, f(i));
            partial[b] = acc;
        },
        1);
    T acc = identity;
    for (const T& p : partial) acc = combine(acc, p);
    return acc;
}

/// Maximum of f(i) over [0, n), `init` when n == 0.
template <class F>
Real parallel_max(Index n, Real init, const F& f) {
    return deterministic_reduce(n, init, f, [](Real a, Real b) { return std::max(a, b); });
}

/// Sum of f(i) over [0, n), deterministic.
template <class T, class F>
T deterministic_sum(Index n, T zero, const F& f) {
    return deterministic_reduce(n, zero, f, [](const T& a, const T& b) { return T(a + b); });
}

/// Limits the threads karst uses for as long as it lives (0 = all cores).
class ThreadLimit {
public:
    explicit ThreadLimit(int threads);
    ~ThreadLimit();
    ThreadLimit(const ThreadLimit&) = delete;
    ThreadLimit& operator=(const ThreadLimit&) = delete;
    /// Threads actually available to karst's loops.
    static int active_threads();

private:
    struct Impl;
    Impl* m_impl;
};

}  // namespace karst
