// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include <cstddef>
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

} // namespace pointform
