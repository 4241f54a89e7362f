// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/core/memory.h"

#include "pointform/core/error.h"

#include "support/test_support.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <vector>

namespace pointform {
namespace {

using test::write_file;

/// A fake /proc and /sys/fs/cgroup under a temporary directory.
struct FakeSystem
{
    test::TempDir dir;
    MemoryLimitFiles files{
        .proc_self_cgroup = dir / "cgroup", .cgroup_root = dir / "sys", .meminfo = dir / "meminfo"};

    void file(const std::filesystem::path& relative, const std::string& content) const
    {
        std::filesystem::create_directories((dir.path() / relative).parent_path());
        write_file(dir.path() / relative, content);
    }
};

TEST(MemoryLimit, TakesTheSmallestOfTheCgroupV2LimitsAndMemAvailable)
{
    FakeSystem fake;
    fake.file("cgroup", "0::/user.slice/job\n");
    fake.file("meminfo", "MemTotal:       8000000 kB\nMemAvailable:   4000000 kB\n");
    fake.file("sys/user.slice/job/memory.max", "max\n");
    fake.file("sys/user.slice/memory.max", "1073741824\n"); // a parent's limit applies too
    MemoryLimit limit = memory_limit(fake.files);
    EXPECT_EQ(limit.bytes, 1073741824U);
    EXPECT_EQ(limit.source, "cgroup v2 memory.max");

    // Without a cgroup limit, MemAvailable.
    fake.file("sys/user.slice/memory.max", "max\n");
    limit = memory_limit(fake.files);
    EXPECT_EQ(limit.bytes, 4000000ULL * 1024U);
    EXPECT_EQ(limit.source, "MemAvailable");
}

TEST(MemoryLimit, ReadsCgroupV1AndIgnoresItsNoLimitValue)
{
    FakeSystem fake;
    fake.file("cgroup", "5:cpu,cpuacct:/\n4:memory:/docker/abc\n0::/\n");
    fake.file("meminfo", "MemAvailable:   4000000 kB\n");
    fake.file("sys/memory/memory.limit_in_bytes", "9223372036854771712\n");
    fake.file("sys/memory/docker/abc/memory.limit_in_bytes", "536870912\n");
    MemoryLimit limit = memory_limit(fake.files);
    EXPECT_EQ(limit.bytes, 536870912U);
    EXPECT_EQ(limit.source, "cgroup v1 memory.limit_in_bytes");

    fake.file("sys/memory/docker/abc/memory.limit_in_bytes", "9223372036854771712\n");
    limit = memory_limit(fake.files);
    EXPECT_EQ(limit.source, "MemAvailable");
}

TEST(MemoryLimit, UnreadableFilesLeaveItUnknown)
{
    FakeSystem fake;
    const MemoryLimit limit = memory_limit(fake.files);
    EXPECT_EQ(limit.bytes, UINT64_MAX);
    EXPECT_EQ(limit.source, "unknown");
}

TEST(MemoryLimit, TheLiveSystemHasALimitAndCheckMemoryRefusesBeyondIt)
{
    const MemoryLimit limit = memory_limit();
    ASSERT_LT(limit.bytes, UINT64_MAX) << "neither a cgroup limit nor /proc/meminfo was readable";
    EXPECT_NO_THROW(check_memory(1024.0, "a kibibyte", "-"));
    EXPECT_THROW(check_memory(static_cast<double>(limit.bytes), "all of it", "ask for less"),
                 InvalidInput);
    try
    {
        check_memory(1e30, "a lot", "ask for less");
    }
    catch (const InvalidInput& e)
    {
        const std::string what = e.what();
        EXPECT_NE(what.find("a lot would need about"), std::string::npos) << what;
        EXPECT_NE(what.find(limit.source), std::string::npos) << what;
        EXPECT_NE(what.find("ask for less"), std::string::npos) << what;
    }
}

// An array advised sparse or dense keeps what is written to it, and nothing (no array, no whole
// page) is no error.
TEST(AdviseSparse, KeepsTheContentsAndTakesAnyRange)
{
    for (const auto advise : {&advise_sparse, &advise_dense})
    {
        std::vector<std::uint32_t> pool(std::size_t{3} << 20U);
        advise(pool.data(), pool.size() * sizeof(std::uint32_t));
        for (std::size_t i = 0; i < pool.size(); i += 4099)
            pool[i] = static_cast<std::uint32_t>(i);
        for (std::size_t i = 0; i < pool.size(); ++i)
            ASSERT_EQ(pool[i], i % 4099 == 0 ? i : 0U) << i;
        advise(nullptr, 0);
        advise(pool.data() + 1, 16);
        EXPECT_EQ(pool[4099], 4099U);
    }
}

} // namespace
} // namespace pointform
