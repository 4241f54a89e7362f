// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/spatial/kd_tree.h"

#include "pointform/core/error.h"
#include "pointform/core/parallel.h"
#include "pointform/geometry/shapes.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <random>
#include <vector>

namespace pointform {
namespace {

std::vector<Vec3f> random_points(std::size_t n, std::uint64_t seed)
{
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<float> uni(-1.0F, 1.0F);
    std::vector<Vec3f> points(n);
    for (auto& p : points)
        p = Vec3f(uni(rng), uni(rng), uni(rng));
    return points;
}

/// Brute force: all squared distances, sorted with ties by index.
std::vector<std::pair<float, std::uint32_t>> brute_sorted(const std::vector<Vec3f>& points,
                                                          const Vec3f& q)
{
    std::vector<std::pair<float, std::uint32_t>> all;
    for (std::uint32_t i = 0; i < points.size(); ++i)
        all.emplace_back((points[i] - q).squaredNorm(), i);
    std::sort(all.begin(), all.end());
    return all;
}

TEST(KdTree, KnnMatchesBruteForce)
{
    const auto points = random_points(2000, 7);
    const auto queries = random_points(200, 8);
    const KdTree tree(points);
    constexpr std::size_t k = 12;
    const KnnTable table = knn_batch(tree, queries, k);
    ASSERT_EQ(table.rows(), queries.size());
    for (std::size_t q = 0; q < queries.size(); ++q)
    {
        const auto truth = brute_sorted(points, queries[q]);
        for (std::size_t j = 0; j < k; ++j)
        {
            EXPECT_NEAR(table.distances2(q)[j], truth[j].first, 1e-6F);
            EXPECT_EQ(table.neighbors(q)[j], truth[j].second);
        }
    }
}

TEST(KdTree, SelfQueryFindsItselfFirst)
{
    const auto points = random_points(500, 3);
    const KdTree tree(points);
    const KnnTable table = knn_batch(tree, points, 4);
    for (std::size_t i = 0; i < points.size(); ++i)
    {
        EXPECT_EQ(table.neighbors(i)[0], i);
        EXPECT_EQ(table.distances2(i)[0], 0.0F);
    }
}

TEST(KdTree, RadiusMatchesBruteForce)
{
    const auto points = random_points(3000, 11);
    const auto queries = random_points(100, 12);
    const KdTree tree(points);
    const float radius = 0.15F;
    const RadiusTable table = radius_batch(tree, queries, radius);
    ASSERT_EQ(table.rows(), queries.size());
    for (std::size_t q = 0; q < queries.size(); ++q)
    {
        std::vector<std::uint32_t> expected;
        for (const auto& [d2, i] : brute_sorted(points, queries[q]))
            if (d2 <= radius * radius)
                expected.push_back(i);
        const auto got = table.neighbors(q);
        EXPECT_EQ(std::vector<std::uint32_t>(got.begin(), got.end()), expected);
    }
}

TEST(KdTree, ResultsIndependentOfThreadCount)
{
    const PointCloud cloud = sample_shape(Shape::Torus, {.count = 20000, .seed = 5});
    const KdTree tree(cloud.positions);
    set_thread_count(1);
    const KnnTable one = knn_batch(tree, cloud.positions, 10);
    set_thread_count(2);
    const KnnTable two = knn_batch(tree, cloud.positions, 10);
    set_thread_count(0);
    EXPECT_EQ(one.indices, two.indices);
    EXPECT_EQ(one.squared_distances, two.squared_distances);
}

TEST(KdTree, DuplicatePointsAreOrderedByIndex)
{
    std::vector<Vec3f> points(10, Vec3f(1.0F, 2.0F, 3.0F));
    points.push_back(Vec3f(5.0F, 5.0F, 5.0F));
    const KdTree tree(points);
    const KnnTable table = knn_batch(tree, std::span<const Vec3f>(points).first(1), 10);
    std::vector<std::uint32_t> expected(10);
    std::iota(expected.begin(), expected.end(), 0U);
    EXPECT_EQ(table.indices, expected);
}

TEST(KdTree, NearestAndEmptyTree)
{
    const std::vector<Vec3f> none;
    const KdTree empty(none);
    EXPECT_FALSE(empty.nearest(Vec3f::Zero()).is_valid());
    EXPECT_THROW((void)knn_batch(empty, none, 1), InvalidInput);

    const auto points = random_points(100, 1);
    const KdTree tree(points);
    float d2 = -1.0F;
    const PointId id = tree.nearest(points[42], &d2);
    EXPECT_EQ(id.value, 42U);
    EXPECT_EQ(d2, 0.0F);
}

TEST(KdTree, RejectsBadArguments)
{
    const auto points = random_points(10, 1);
    const KdTree tree(points);
    EXPECT_THROW((void)knn_batch(tree, points, 0), InvalidInput);
    EXPECT_THROW((void)knn_batch(tree, points, 11), InvalidInput);
    EXPECT_THROW((void)radius_batch(tree, points, -1.0F), InvalidInput);
}

} // namespace
} // namespace pointform
