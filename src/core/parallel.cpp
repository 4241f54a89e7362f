// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/core/parallel.h"

#include "pointform/core/progress.h"

#include <omp.h>

#include <algorithm>
#include <atomic>
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

} // namespace

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
    std::vector<std::exception_ptr> errors(blocks);
    std::atomic<std::size_t> done{0};
    std::atomic<bool> stop{false};
    std::mutex reporting;

    const auto run_block = [&](std::size_t b) {
        if (stop.load(std::memory_order_relaxed))
            return;
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
            run_block(b);
    }
    else
    {
        const auto count = static_cast<std::ptrdiff_t>(blocks);
#pragma omp parallel for schedule(dynamic, 1)
        for (std::ptrdiff_t b = 0; b < count; ++b)
            run_block(static_cast<std::size_t>(b));
    }
    for (const auto& e : errors)
        if (e)
            std::rethrow_exception(e);
}

} // namespace pointform
