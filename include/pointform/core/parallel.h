// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include <algorithm>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <iterator>
#include <vector>

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

/// \brief Runs `body(begin, end, out)` over fixed blocks of [0, n) in parallel, each block
/// appending to its own vector `out`, and concatenates those in block order, so the result does
/// not depend on the thread count.
template <typename T, typename Body>
[[nodiscard]] std::vector<T> parallel_collect(std::size_t n, std::size_t block, const Body& body)
{
    const std::size_t blocks = (n + block - 1) / block;
    std::vector<std::vector<T>> parts(blocks);
    parallel_blocks(blocks, 1, [&](std::size_t b0, std::size_t b1) {
        for (std::size_t b = b0; b < b1; ++b)
            body(b * block, std::min(n, (b + 1) * block), parts[b]);
    });
    std::size_t total = 0;
    for (const auto& part : parts)
        total += part.size();
    std::vector<T> out;
    out.reserve(total);
    for (auto& part : parts)
        out.insert(out.end(), part.begin(), part.end());
    return out;
}

/// \brief Sorts `items` by `less` in parallel: a power of two of pieces (about four per thread,
/// at least 65,536 items each) sorted at once, then merged in pairs, round by round, each
/// round's merges at once. For a strict total order (no two items equivalent, e.g. keys paired
/// with their index) the result is std::sort's, whatever the thread count. Needs one buffer of
/// items.size().
template <class T, class Less = std::less<>>
void parallel_sort(std::vector<T>& items, Less less = {})
{
    constexpr std::size_t min_piece = std::size_t{1} << 16;
    const std::size_t n = items.size();
    const auto wanted = static_cast<std::size_t>(4 * std::max(1, thread_count()));
    const std::size_t pieces = std::bit_floor(std::clamp<std::size_t>(n / min_piece, 1, wanted));
    if (pieces <= 1)
    {
        std::sort(items.begin(), items.end(), less);
        return;
    }
    const std::size_t piece = (n + pieces - 1) / pieces;
    const auto at = [&items](std::size_t i) {
        return items.begin() + static_cast<std::ptrdiff_t>(i);
    };
    parallel_blocks(pieces, 1, [&](std::size_t first, std::size_t last) {
        for (std::size_t p = first; p < last; ++p)
            std::sort(at(std::min(n, p * piece)), at(std::min(n, (p + 1) * piece)), less);
    });
    std::vector<T> buffer(n);
    for (std::size_t width = piece; width < n; width *= 2)
    {
        const std::size_t pairs = (n + 2 * width - 1) / (2 * width);
        parallel_blocks(pairs, 1, [&](std::size_t first, std::size_t last) {
            for (std::size_t q = first; q < last; ++q)
            {
                const std::size_t lo = q * 2 * width;
                const std::size_t mid = std::min(n, lo + width);
                const std::size_t hi = std::min(n, lo + 2 * width);
                std::merge(at(lo), at(mid), at(mid), at(hi),
                           buffer.begin() + static_cast<std::ptrdiff_t>(lo), less);
            }
        });
        items.swap(buffer);
    }
}

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
