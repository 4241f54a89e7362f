// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/core/error.h"
#include "pointform/core/json_depth.h"
#include "pointform/core/parallel.h"
#include "pointform/core/progress.h"
#include "pointform/core/types.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <numeric>
#include <random>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

namespace pointform {
namespace {

TEST(ParallelBlocks, CoversEveryIndexOnceWhateverTheThreadCount)
{
    for (const int threads : {1, 2, 3})
    {
        set_thread_count(threads);
        std::vector<int> hits(100003, 0);
        parallel_blocks(hits.size(), 1000, [&](std::size_t begin, std::size_t end) {
            for (std::size_t i = begin; i < end; ++i)
                ++hits[i];
        });
        EXPECT_EQ(std::accumulate(hits.begin(), hits.end(), 0), 100003) << threads;
        EXPECT_EQ(*std::min_element(hits.begin(), hits.end()), 1) << threads;
    }
    set_thread_count(0);
    parallel_blocks(0, 10, [](std::size_t, std::size_t) { FAIL() << "called on empty range"; });
}

TEST(ParallelBlocks, StatsCountLoopsBlocksAndThreads)
{
    const auto busy = [](std::size_t begin, std::size_t end) {
        // Long enough per block that the other threads of the team join in.
        const auto until = std::chrono::steady_clock::now() + std::chrono::microseconds(200);
        while (std::chrono::steady_clock::now() < until)
        {}
        (void)begin;
        (void)end;
    };
    set_thread_count(1);
    reset_parallel_stats();
    parallel_blocks(10000, 100, busy);
    parallel_blocks(50, 100, busy); // one block
    parallel_blocks(0, 100, busy);  // nothing: not a loop
    ParallelStats stats = parallel_stats();
    EXPECT_EQ(stats.loops, 2U);
    EXPECT_EQ(stats.blocks, 101U);
    EXPECT_EQ(stats.multi_block_loops, 1U);
    EXPECT_EQ(stats.max_team_threads, 1);
    EXPECT_EQ(stats.max_threads_per_loop, 1);

    for (const int threads : {2, 3})
    {
        set_thread_count(threads);
        reset_parallel_stats();
        parallel_blocks(10000, 100, busy);
        stats = parallel_stats();
        EXPECT_EQ(stats.loops, 1U);
        EXPECT_EQ(stats.blocks, 100U);
        EXPECT_EQ(stats.multi_block_loops, 1U);
        EXPECT_EQ(stats.max_team_threads, threads);
        EXPECT_GT(stats.max_threads_per_loop, 1) << threads;
        EXPECT_LE(stats.max_threads_per_loop, threads);
    }

    // Blocks skipped after a failure are not counted.
    set_thread_count(1);
    reset_parallel_stats();
    EXPECT_THROW(parallel_blocks(1000, 100,
                                 [](std::size_t begin, std::size_t) {
                                     if (begin == 300)
                                         throw InvalidInput("stop");
                                 }),
                 InvalidInput);
    EXPECT_EQ(parallel_stats().blocks, 4U);
    reset_parallel_stats();
    stats = parallel_stats();
    EXPECT_EQ(stats.loops + stats.blocks + stats.multi_block_loops, 0U);
    EXPECT_EQ(stats.max_team_threads, 0);
    EXPECT_EQ(stats.max_threads_per_loop, 0);
    // One block, or one thread: a team of one.
    set_thread_count(3);
    parallel_blocks(50, 100, busy);
    EXPECT_EQ(parallel_stats().max_team_threads, 1);
    set_thread_count(0);
}

TEST(ParallelBlocks, RethrowsTheFirstFailingBlock)
{
    set_thread_count(2);
    try
    {
        parallel_blocks(10000, 100, [](std::size_t begin, std::size_t) {
            if (begin == 300 || begin == 7000)
                throw InvalidInput("block " + std::to_string(begin));
        });
        ADD_FAILURE() << "no exception";
    }
    catch (const InvalidInput& e)
    {
        // With two threads either failing block may run first, but never a non-failing one.
        const std::string what = e.what();
        EXPECT_TRUE(what == "block 300" || what == "block 7000") << what;
    }
    set_thread_count(0);
}

TEST(ParallelSort, GivesStdSortsResultWhateverTheThreadCount)
{
    // Keys with many repeats, paired with their index (a strict order), in pieces of more than
    // 65,536: 1 thread sorts 4 pieces, 3 threads 8, then merges them.
    std::mt19937_64 rng(5);
    std::vector<std::pair<std::uint32_t, std::uint32_t>> items(300001);
    for (std::size_t i = 0; i < items.size(); ++i)
        items[i] = {static_cast<std::uint32_t>(rng() % 1000), static_cast<std::uint32_t>(i)};
    auto expected = items;
    std::sort(expected.begin(), expected.end());
    for (const int threads : {1, 2, 3})
    {
        set_thread_count(threads);
        reset_parallel_stats();
        auto sorted = items;
        parallel_sort(sorted);
        EXPECT_EQ(sorted, expected) << threads << " threads";
        EXPECT_GE(parallel_stats().multi_block_loops, 1U);
    }
    set_thread_count(0);
    // A descending order through the comparator, and inputs too small to split.
    auto descending = items;
    parallel_sort(descending, std::greater<>{});
    EXPECT_TRUE(std::is_sorted(descending.begin(), descending.end(), std::greater<>{}));
    std::vector<int> small = {3, 1, 2};
    parallel_sort(small);
    EXPECT_EQ(small, (std::vector<int>{1, 2, 3}));
    std::vector<int> empty;
    parallel_sort(empty);
    EXPECT_TRUE(empty.empty());
}

TEST(Progress, ReportsMonotonicFractionsAndCancels)
{
    std::vector<double> seen;
    const ProgressCallback record = [&](std::string_view stage, double fraction) {
        EXPECT_EQ(stage, "stage");
        seen.push_back(fraction);
        return true;
    };
    ProgressReporter reporter(record, "stage");
    for (int i = 0; i <= 1000; ++i)
        reporter.update(i, 1000);
    reporter.finish();
    ASSERT_FALSE(seen.empty());
    EXPECT_LE(seen.size(), 103U); // throttled to about every percent
    EXPECT_TRUE(std::is_sorted(seen.begin(), seen.end()));
    EXPECT_EQ(seen.back(), 1.0);

    const ProgressCallback stop = [](std::string_view, double) {
        return false;
    };
    ProgressReporter cancelling(stop, "work");
    EXPECT_THROW(cancelling.update(1, 2), Cancelled);

    // No callback: nothing happens.
    ProgressReporter silent({}, "quiet");
    EXPECT_NO_THROW(silent.update(1, 2));
}

TEST(Progress, CancellationStopsParallelWork)
{
    std::atomic<std::size_t> blocks{0};
    const ProgressCallback stop = [](std::string_view, double) {
        return false;
    };
    ProgressReporter reporter(stop, "work");
    EXPECT_THROW(parallel_blocks(
                     1000000, 1000,
                     [&](std::size_t, std::size_t) {
                         // Real work takes time; without it one thread races through every block
                         // before the other has even reported its first.
                         std::this_thread::sleep_for(std::chrono::microseconds(200));
                         blocks.fetch_add(1);
                     },
                     &reporter),
                 Cancelled);
    // The first report cancels; only blocks already started may finish.
    EXPECT_LT(blocks.load(), 100U);
}

TEST(IoErrorMessage, NamesFileLineAndOffset)
{
    const IoError with_line("scan.xyz", "bad number", 12);
    EXPECT_STREQ(with_line.what(), "scan.xyz:12: bad number");
    EXPECT_EQ(with_line.line(), 12U);
    const IoError with_offset("scan.ply", "truncated", std::nullopt, 4096);
    EXPECT_STREQ(with_offset.what(), "scan.ply (byte 4096): truncated");
    EXPECT_EQ(with_offset.path(), "scan.ply");
}

TEST(Ids, CompareAndValidity)
{
    EXPECT_FALSE(PointId{}.is_valid());
    EXPECT_TRUE(PointId(3).is_valid());
    EXPECT_LT(PointId(2), PointId(3));
    EXPECT_EQ(FaceId(7), FaceId(7));
}

TEST(JsonDepth, CountsBracketsOutsideStrings)
{
    EXPECT_FALSE(json_nests_deeper_than("", 0));
    EXPECT_FALSE(json_nests_deeper_than("3", 0));
    EXPECT_TRUE(json_nests_deeper_than("[]", 0));
    EXPECT_FALSE(json_nests_deeper_than(R"({"t": [[1, 2, 3], [4, 5, 6]]})", 3));
    EXPECT_TRUE(json_nests_deeper_than(R"({"t": [[[1]]]})", 3));
    // Brackets in strings, escaped quotes included, do not count; closing ones do.
    EXPECT_FALSE(json_nests_deeper_than(R"(["[[[[\"[[", {"a": "{{{{"}])", 2));
    EXPECT_FALSE(json_nests_deeper_than("[][][][][][]", 1));
    EXPECT_FALSE(json_nests_deeper_than("]]]][", 1)); // stray closers do not go below zero
    // A hostile million brackets: answered at the limit, without recursion.
    EXPECT_TRUE(json_nests_deeper_than(std::string(1000000, '['), 16));
}

} // namespace
} // namespace pointform
