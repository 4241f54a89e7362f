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

/// \brief What expect_parallel_run() asks of a run.
struct ParallelCheck
{
    /// Loops that split their range into several blocks, at least.
    std::uint64_t min_multi_block_loops = 1;
    /// Above one thread, some loop's blocks must have run on more than one thread. Whether they
    /// did depends on how the threads were scheduled, so only runs with many long blocks (where
    /// one thread cannot finish them all before the others start) ask it; the team's size,
    /// always checked, is fixed by the thread count.
    bool blocks_on_several_threads = false;
};

/// \brief Checks parallel_stats() since the last reset_parallel_stats() for a run at `threads`
/// threads: enough loops split into blocks; at one thread, every block on one thread; above
/// one, the teams of the split loops had `threads` threads (and, if asked, some loop had its
/// blocks run by more than one of them).
inline void expect_parallel_run(int threads, const ParallelCheck& check = {})
{
    const ParallelStats stats = parallel_stats();
    EXPECT_GE(stats.multi_block_loops, check.min_multi_block_loops)
        << threads << " threads: too few loops split into blocks (" << stats.loops << " loops, "
        << stats.blocks << " blocks): the input is too small";
    if (threads == 1)
    {
        EXPECT_EQ(stats.max_team_threads, 1) << "a team of several threads at -j 1";
        EXPECT_EQ(stats.max_threads_per_loop, 1) << "blocks ran on several threads at -j 1";
    }
    else
    {
        EXPECT_EQ(stats.max_team_threads, threads) << threads << " threads";
        if (check.blocks_on_several_threads)
        {
            EXPECT_GT(stats.max_threads_per_loop, 1)
                << threads << " threads: every loop ran on one thread";
        }
    }
}

/// \brief Runs `run()` at each of `counts` threads (default 1, 2 and 3) and returns its results in
/// that order, checking each run with expect_parallel_run(); the default thread count is
/// restored afterwards.
template <class Run>
auto at_thread_counts(Run&& run, const ParallelCheck& check = {},
                      std::initializer_list<int> counts = {1, 2, 3})
{
    std::vector<std::decay_t<decltype(run())>> results;
    for (const int threads : counts)
    {
        set_thread_count(threads);
        reset_parallel_stats();
        results.push_back(run());
        expect_parallel_run(threads, check);
    }
    set_thread_count(0);
    return results;
}

} // namespace pointform::test
