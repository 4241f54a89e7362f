// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// The executable's operator new: malloc, as the default one, plus a request for transparent huge
// pages over every whole 2 MiB page of a large block (pointform::advise_dense()). The large arrays
// of a run (neighbour tables, the guide's moments, grids, level buffers) are written once page by
// page soon after they are made, so with 4 KiB pages a good share of a run is the kernel's page
// faults. Commands ask for it (ask_for_huge_pages()) where that pays: `normals` (1M samples of a
// clean sphere 1.12 -> 0.89 s, of a noisy one 2.85 -> 2.53 s; the same bytes and peak memory).
// Arrays written sparsely say so (advise_sparse(), as the kd-tree's node pool does: with huge
// pages all of it was resident, 40 MB more at 1M samples). `reconstruct` gained 0-2% (a 72k-sample
// scan, 1M-sample blobby and plate) and does not ask. Debian's kernels grant huge pages only where
// asked ("madvise" mode); where they are off the request does nothing. Only the executable asks:
// the library never replaces the allocation functions of the process it runs in (Python's, say).
// Blocks under large_block keep small pages, so the many small allocations never hold a huge page
// each. Builds with AddressSanitizer keep its own operator new, which checks every allocation
// against its deallocation.

#include "large_pages.h"

#include "pointform/core/memory.h"

#include <atomic>

namespace {
std::atomic<bool> huge_pages_asked{false};
} // namespace

void pointform::cli::ask_for_huge_pages()
{
    huge_pages_asked.store(true, std::memory_order_relaxed);
}

#if defined(__SANITIZE_ADDRESS__)
#define PF_KEEP_OPERATOR_NEW 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define PF_KEEP_OPERATOR_NEW 1
#endif
#endif

#if !defined(PF_KEEP_OPERATOR_NEW) && defined(__linux__)

#include <cstddef>
#include <cstdlib>
#include <new>

namespace {

constexpr std::size_t large_block = std::size_t{4} << 20U;

void* allocate(std::size_t size)
{
    for (;;)
    {
        if (void* block = std::malloc(size == 0 ? 1 : size))
        {
            if (size >= large_block && huge_pages_asked.load(std::memory_order_relaxed))
                pointform::advise_dense(block, size);
            return block;
        }
        // As the default operator new: the new-handler may free memory, else bad_alloc.
        const std::new_handler handler = std::get_new_handler();
        if (handler == nullptr)
            throw std::bad_alloc();
        handler();
    }
}

} // namespace

// The other forms (nothrow, aligned) and every operator delete stay the standard library's: its
// nothrow forms call these, and its operator delete frees what malloc gave.
void* operator new(std::size_t size)
{
    return allocate(size);
}

void* operator new[](std::size_t size)
{
    return allocate(size);
}

#endif
