// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// Runs a computation at several thread counts for determinism tests, checking that the work
// really ran in parallel blocks (a comparison of two serial runs proves nothing).

#pragma once

#include "pointform/core/parallel.h"

#include <gtest/gtest.h>

#include <initializer_list>
#include <type_traits>
#include <vector>

namespace pointform::test {

/// \brief Runs `run()` at each of `counts` threads (default 1, 2 and 3) and returns its results in
/// that order; the default thread count is restored afterwards.
///
/// Checks through parallel_stats() that each run split at least `min_multi_block_loops` loops
/// into several blocks, that at one thread every block ran on one thread, and that above one
/// thread some loop had its blocks run by more than one thread.
template <class Run>
auto at_thread_counts(Run&& run, std::uint64_t min_multi_block_loops = 1,
                      std::initializer_list<int> counts = {1, 2, 3})
{
    std::vector<std::decay_t<decltype(run())>> results;
    for (const int threads : counts)
    {
        set_thread_count(threads);
        reset_parallel_stats();
        results.push_back(run());
        const ParallelStats stats = parallel_stats();
        EXPECT_GE(stats.multi_block_loops, min_multi_block_loops)
            << threads << " threads: too few loops split into blocks (" << stats.loops << " loops, "
            << stats.blocks << " blocks): the input is too small";
        if (threads == 1)
            EXPECT_EQ(stats.max_threads_per_loop, 1) << "blocks ran on several threads at -j 1";
        else
            EXPECT_GT(stats.max_threads_per_loop, 1)
                << threads << " threads: every loop ran on one thread";
    }
    set_thread_count(0);
    return results;
}

} // namespace pointform::test
