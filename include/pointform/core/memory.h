// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace pointform {

/// \brief How much memory this process may use, and where that figure comes from.
struct MemoryLimit
{
    /// Bytes; UINT64_MAX when nothing could be read.
    std::uint64_t bytes = UINT64_MAX;
    /// "cgroup v2 memory.max", "cgroup v1 memory.limit_in_bytes", "MemAvailable" or "unknown".
    std::string source = "unknown";
};

/// \brief Where memory_limit() reads from (the defaults are the live system; tests point these
/// at a fake tree).
struct MemoryLimitFiles
{
    std::filesystem::path proc_self_cgroup = "/proc/self/cgroup";
    std::filesystem::path cgroup_root = "/sys/fs/cgroup";
    std::filesystem::path meminfo = "/proc/meminfo";
};

/// \brief The memory limit that applies to this process: the smallest of the cgroup limits on
/// its cgroup and the cgroup's ancestors (v2 `memory.max`, read under `cgroup_root` and
/// `cgroup_root`/unified; v1 `memory.limit_in_bytes` under `cgroup_root`/memory) and the
/// system's MemAvailable from /proc/meminfo. Unreadable files are skipped; v1's "no limit"
/// (a value near 2⁶³) and v2's "max" count as unset.
[[nodiscard]] MemoryLimit memory_limit(const MemoryLimitFiles& files = {});

/// \brief memory_limit().bytes.
[[nodiscard]] std::uint64_t memory_limit_bytes();

/// \brief Whether work estimated to need `need_bytes` fits in 80% of `limit` (no limit, or no
/// estimate (NaN): it fits). The rule check_memory() refuses by.
[[nodiscard]] bool fits_in_memory(double need_bytes, const MemoryLimit& limit = memory_limit());

/// \brief Refuses, before anything is allocated, work estimated to need more than 80% of
/// memory_limit().
/// \param need_bytes  the estimate, in bytes (may be infinite)
/// \param what        what would need it, e.g. "marching cubes at a cell of 0.001"
/// \param advice      how to ask for less, e.g. "use a larger --cell"
/// \throw InvalidInput "<what> would need about N GiB, more than the M GiB this process may use
///        (<source>); <advice>"
void check_memory(double need_bytes, const std::string& what, const std::string& advice);

/// \brief Marks `bytes` from `begin` as an array whose pages are written sparsely (a pool sized for
/// the worst case, most of it never used): the kernel keeps its small pages there, so that
/// transparent huge pages (a system in `always` mode, or an executable asking for them for its
/// large blocks) do not make the whole array resident. Call before anything is written. Does
/// nothing where the system has no such advice.
void advise_sparse(void* begin, std::size_t bytes) noexcept;

/// \brief The opposite of advise_sparse(): asks for transparent huge pages (2 MiB) over the whole
/// huge pages within `bytes` from `begin`, an array about to be written densely (fewer page
/// faults). Allocates nothing, so an allocation function may call it. Does nothing where the
/// system has no such advice or grants no huge pages.
void advise_dense(void* begin, std::size_t bytes) noexcept;

/// \brief An allocator that default-initializes what a container constructs without a value:
/// numbers and other trivial types keep whatever the memory held, so that `resize(n)` of a large
/// array writes nothing. The loop that fills it then touches its pages first, in parallel where
/// it runs in parallel, instead of one thread zeroing them all beforehand (at 10M samples the
/// neighbour table alone was over a gigabyte of serial zeroing).
template <class T>
struct DefaultInitAllocator : std::allocator<T>
{
    using value_type = T;
    DefaultInitAllocator() noexcept = default;
    template <class U>
    DefaultInitAllocator(const DefaultInitAllocator<U>& /*other*/) noexcept
    {}
    template <class U>
    struct rebind
    {
        using other = DefaultInitAllocator<U>;
    };
    template <class U>
    void construct(U* p) noexcept(std::is_nothrow_default_constructible_v<U>)
    {
        ::new (static_cast<void*>(p)) U;
    }
    template <class U, class... Args>
    void construct(U* p, Args&&... args)
    {
        std::construct_at(p, std::forward<Args>(args)...);
    }
};

/// \brief A vector whose `resize(n)` leaves new numbers unset (DefaultInitAllocator): for arrays
/// that a loop fills right after.
template <class T>
using FilledLaterVector = std::vector<T, DefaultInitAllocator<T>>;

} // namespace pointform
