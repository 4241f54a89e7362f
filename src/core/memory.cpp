// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/core/memory.h"

#include "pointform/core/error.h"

#if defined(__linux__)
#include <sys/mman.h>
#include <unistd.h>
#endif

#include <cstdint>
#include <cstdio>
#include <fstream>
#include <optional>
#include <sstream>
#include <vector>

namespace pointform {
namespace {

/// v1 reports "no limit" as a page-rounded 2⁶³ − 1; anything this large is no limit.
constexpr std::uint64_t unlimited_threshold = std::uint64_t{1} << 60;

/// The first line of `path` as an unsigned number; nullopt if missing, "max" or malformed.
std::optional<std::uint64_t> read_number(const std::filesystem::path& path)
{
    std::ifstream in(path);
    std::string text;
    if (!in || !(in >> text) || text.empty() || text == "max")
    {
        return std::nullopt;
    }
    std::uint64_t value = 0;
    for (const char c : text)
    {
        if (c < '0' || c > '9' || value > (UINT64_MAX - 9) / 10)
        {
            return std::nullopt;
        }
        value = 10 * value + static_cast<std::uint64_t>(c - '0');
    }
    return value;
}

/// `relative` ("/a/b") and its ancestors ("/a", "/"), each as a path below `mount`.
std::vector<std::filesystem::path> with_ancestors(const std::filesystem::path& mount,
                                                  const std::string& relative)
{
    std::vector<std::filesystem::path> out;
    std::string path = relative;
    for (;;)
    {
        while (path.size() > 1 && path.back() == '/')
        {
            path.pop_back();
        }
        out.push_back(path.empty() || path == "/" ? mount : mount / path.substr(1));
        const std::size_t slash = path.rfind('/');
        if (path.empty() || path == "/" || slash == std::string::npos)
        {
            break;
        }
        path = slash == 0 ? "/" : path.substr(0, slash);
    }
    return out;
}

void take(MemoryLimit& limit, std::optional<std::uint64_t> bytes, const char* source)
{
    if (bytes && *bytes < unlimited_threshold && *bytes < limit.bytes)
    {
        limit.bytes = *bytes;
        limit.source = source;
    }
}

} // namespace

MemoryLimit memory_limit(const MemoryLimitFiles& files)
{
    MemoryLimit limit;
    // /proc/self/cgroup lines: "hierarchy-id:controllers:path"; v2 is "0::path".
    std::ifstream cgroups(files.proc_self_cgroup);
    std::string line;
    while (std::getline(cgroups, line))
    {
        const std::size_t first = line.find(':');
        const std::size_t second = first == std::string::npos ? first : line.find(':', first + 1);
        if (second == std::string::npos)
        {
            continue;
        }
        const std::string controllers = line.substr(first + 1, second - first - 1);
        const std::string path = line.substr(second + 1);
        if (path.empty() || path.front() != '/')
        {
            continue;
        }
        if (line.compare(0, first, "0") == 0 && controllers.empty())
        {
            for (const auto& mount : {files.cgroup_root, files.cgroup_root / "unified"})
            {
                for (const auto& dir : with_ancestors(mount, path))
                {
                    take(limit, read_number(dir / "memory.max"), "cgroup v2 memory.max");
                }
            }
        }
        else
        {
            std::stringstream list(controllers);
            std::string controller;
            while (std::getline(list, controller, ','))
            {
                if (controller != "memory")
                {
                    continue;
                }
                for (const auto& dir : with_ancestors(files.cgroup_root / "memory", path))
                {
                    take(limit, read_number(dir / "memory.limit_in_bytes"),
                         "cgroup v1 memory.limit_in_bytes");
                }
            }
        }
    }
    std::ifstream meminfo(files.meminfo);
    while (std::getline(meminfo, line))
    {
        std::istringstream fields(line);
        std::string key;
        std::uint64_t kib = 0;
        if (fields >> key >> kib && key == "MemAvailable:")
        {
            take(limit, kib * 1024, "MemAvailable");
            break;
        }
    }
    return limit;
}

std::uint64_t memory_limit_bytes()
{
    return memory_limit().bytes;
}

bool fits_in_memory(double need_bytes, const MemoryLimit& limit)
{
    return limit.bytes == UINT64_MAX ||
           !(need_bytes > 0.8 * static_cast<double>(limit.bytes)); // NaN: no estimate
}

void check_memory(double need_bytes, const std::string& what, const std::string& advice)
{
    const MemoryLimit limit = memory_limit();
    if (fits_in_memory(need_bytes, limit))
    {
        return;
    }
    const auto have = static_cast<double>(limit.bytes);
    constexpr double gib = 1024.0 * 1024.0 * 1024.0;
    char text[160];
    std::snprintf(text, sizeof text, " would need about %.3g GiB, more than the %.3g GiB",
                  need_bytes / gib, have / gib);
    throw InvalidInput(what + text + " this process may use (" + limit.source + "); " + advice);
}

namespace {

/// madvise(advice) over the whole pages of `alignment` bytes within [begin, begin + bytes).
void advise_whole_pages([[maybe_unused]] void* begin, [[maybe_unused]] std::size_t bytes,
                        [[maybe_unused]] std::uintptr_t alignment, [[maybe_unused]] int advice)
{
#if defined(__linux__)
    if (begin == nullptr || alignment == 0)
        return;
    const auto start = reinterpret_cast<std::uintptr_t>(begin);
    const std::uintptr_t first = (start + alignment - 1) & ~(alignment - 1);
    const std::uintptr_t last = (start + bytes) & ~(alignment - 1);
    if (last > first)
        (void)madvise(reinterpret_cast<void*>(first), last - first, advice);
#endif
}

} // namespace

void advise_sparse(void* begin, std::size_t bytes) noexcept
{
#if defined(__linux__) && defined(MADV_NOHUGEPAGE)
    const long page_size = sysconf(_SC_PAGESIZE);
    if (page_size > 0)
        advise_whole_pages(begin, bytes, static_cast<std::uintptr_t>(page_size), MADV_NOHUGEPAGE);
#else
    (void)begin;
    (void)bytes;
#endif
}

void advise_dense(void* begin, std::size_t bytes) noexcept
{
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    advise_whole_pages(begin, bytes, std::uintptr_t{2} << 20U, MADV_HUGEPAGE);
#else
    (void)begin;
    (void)bytes;
#endif
}

} // namespace pointform
