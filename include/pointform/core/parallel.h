// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>

namespace pointform {
class ProgressReporter;
}

namespace pointform {

/// \brief Number of threads that parallel loops use (OpenMP's team size).
[[nodiscard]] int thread_count();

/// \brief Sets the number of threads for later parallel loops; 0 restores the default (all
/// cores, or OMP_NUM_THREADS).
void set_thread_count(int threads);

/// \brief Runs `body(begin, end)` over consecutive blocks covering [0, n), in parallel.
///
/// Blocks are fixed by `n` and `block`, not by the thread count, so any body that writes only to
/// the slots of its own indices produces the same result whatever the number of threads.
/// \param n      number of items
/// \param block  items per block; 0 picks a default (4096)
/// \param body   called as body(begin, end) for each block; must not throw across threads:
///               exceptions are captured and the first one (lowest block) is rethrown.
/// \param progress  optional; updated as blocks complete, by one thread at a time (may throw
///               Cancelled, after which the remaining blocks are skipped).
void parallel_blocks(std::size_t n, std::size_t block,
                     const std::function<void(std::size_t, std::size_t)>& body,
                     ProgressReporter* progress = nullptr);

/// \brief What parallel_blocks has run since the process started or since the last
/// reset_parallel_stats(), counted by every call from every thread.
///
/// Always on and cheap (a few atomic updates per call and one per block), so tests and the CLI's
/// JSON report can show that work really was split into several blocks and run on several
/// threads, which a claim of thread-count independence needs.
struct ParallelStats
{
    std::uint64_t loops = 0;             ///< calls of parallel_blocks with n > 0
    std::uint64_t blocks = 0;            ///< blocks run (skipped ones after a failure not counted)
    std::uint64_t multi_block_loops = 0; ///< calls that split their range into 2 or more blocks
    /// Most threads in the team of one call: 1 when every call ran serially, else the thread
    /// count of the calls that split their range (fixed by the thread count, unlike the next).
    int max_team_threads = 0;
    /// Most distinct threads that actually ran blocks of one call (1 when every call ran
    /// serially; up to the team's size, as the threads happened to be scheduled).
    int max_threads_per_loop = 0;
};

/// \brief The statistics gathered since the last reset (a consistent snapshot only when no
/// parallel_blocks call is running).
[[nodiscard]] ParallelStats parallel_stats();

/// \brief Sets every figure of parallel_stats() back to zero.
void reset_parallel_stats();

} // namespace pointform
