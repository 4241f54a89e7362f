// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/core/parallel.h"

#include "pointform/core/progress.h"

#include <omp.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cstdint>
#include <exception>
#include <mutex>
#include <vector>

namespace pointform {
namespace {

int default_threads()
{
    static const int threads = omp_get_max_threads();
    return threads;
}

std::atomic<std::uint64_t> stat_loops{0};
std::atomic<std::uint64_t> stat_blocks{0};
std::atomic<std::uint64_t> stat_multi_block_loops{0};
std::atomic<int> stat_max_team{0};
std::atomic<int> stat_max_threads{0};

void record_max(std::atomic<int>& max, int value)
{
    int seen = max.load(std::memory_order_relaxed);
    while (seen < value && !max.compare_exchange_weak(seen, value, std::memory_order_relaxed))
    {
        // seen now holds the current maximum
    }
}

} // namespace

ParallelStats parallel_stats()
{
    ParallelStats stats;
    stats.loops = stat_loops.load(std::memory_order_relaxed);
    stats.blocks = stat_blocks.load(std::memory_order_relaxed);
    stats.multi_block_loops = stat_multi_block_loops.load(std::memory_order_relaxed);
    stats.max_team_threads = stat_max_team.load(std::memory_order_relaxed);
    stats.max_threads_per_loop = stat_max_threads.load(std::memory_order_relaxed);
    return stats;
}

void reset_parallel_stats()
{
    stat_loops.store(0, std::memory_order_relaxed);
    stat_blocks.store(0, std::memory_order_relaxed);
    stat_multi_block_loops.store(0, std::memory_order_relaxed);
    stat_max_team.store(0, std::memory_order_relaxed);
    stat_max_threads.store(0, std::memory_order_relaxed);
}

int thread_count()
{
    return omp_get_max_threads();
}

void set_thread_count(int threads)
{
    const int base = default_threads(); // remember the default before the first change
    omp_set_num_threads(threads > 0 ? threads : base);
}

void parallel_blocks(std::size_t n, std::size_t block,
                     const std::function<void(std::size_t, std::size_t)>& body,
                     ProgressReporter* progress)
{
    if (n == 0)
        return;
    if (block == 0)
        block = 4096;
    const std::size_t blocks = (n + block - 1) / block;
    stat_loops.fetch_add(1, std::memory_order_relaxed);
    if (blocks > 1)
        stat_multi_block_loops.fetch_add(1, std::memory_order_relaxed);
    std::vector<std::exception_ptr> errors(blocks);
    std::atomic<std::size_t> done{0};
    std::atomic<bool> stop{false};
    std::mutex reporting;

    // Bit t set: the team's thread t ran a block (threads past 63 share the last bit, so the
    // count saturates at 64).
    std::atomic<std::uint64_t> ran_on{0};
    std::atomic<int> team{1};

    // in_team: run by the team of the parallel region below (not serially here, where the
    // caller may itself be a thread of some other team).
    const auto run_block = [&](std::size_t b, bool in_team) {
        if (stop.load(std::memory_order_relaxed))
            return;
        const int t = in_team ? std::min(omp_get_thread_num(), 63) : 0;
        const std::uint64_t bit = std::uint64_t{1} << t;
        if ((ran_on.load(std::memory_order_relaxed) & bit) == 0)
        {
            ran_on.fetch_or(bit, std::memory_order_relaxed);
            if (in_team)
                record_max(team, omp_get_num_threads());
        }
        try
        {
            body(b * block, std::min(n, (b + 1) * block));
        }
        catch (...)
        {
            errors[b] = std::current_exception();
            stop = true;
        }
        const std::size_t finished = done.fetch_add(1) + 1;
        // Whichever thread finds the reporter free reports; the others never wait for it.
        if (progress != nullptr && reporting.try_lock())
        {
            try
            {
                progress->update(static_cast<double>(finished), static_cast<double>(blocks));
            }
            catch (...)
            {
                if (!errors[b])
                    errors[b] = std::current_exception();
                stop = true;
            }
            reporting.unlock();
        }
    };

    if (blocks == 1 || thread_count() == 1)
    {
        for (std::size_t b = 0; b < blocks; ++b)
            run_block(b, false);
    }
    else
    {
        // Each thread of the team first runs the blocks of its own index (t, t + T, ... below
        // the number of threads asked for), then takes the rest one at a time as it frees up.
        // Dynamic scheduling alone let one thread take every block of a short loop before the
        // other woke (a 30-block loop on a busy machine), so that a run at -j 2 could not show
        // that a second thread ran; now every thread of the team runs at least one block of a
        // loop with as many blocks. Which thread runs a block never changes a result.
        const std::size_t first = std::min(blocks, static_cast<std::size_t>(thread_count()));
        std::atomic<std::size_t> next{first};
#pragma omp parallel
        {
            const auto t = static_cast<std::size_t>(omp_get_thread_num());
            const auto team_size = static_cast<std::size_t>(omp_get_num_threads());
            for (std::size_t b = t; b < first; b += team_size)
                run_block(b, true);
            for (std::size_t b = next.fetch_add(1); b < blocks; b = next.fetch_add(1))
                run_block(b, true);
        }
    }
    stat_blocks.fetch_add(done.load(), std::memory_order_relaxed);
    record_max(stat_max_team, team.load(std::memory_order_relaxed));
    record_max(stat_max_threads, std::popcount(ran_on.load(std::memory_order_relaxed)));
    for (const auto& e : errors)
        if (e)
            std::rethrow_exception(e);
}

} // namespace pointform
