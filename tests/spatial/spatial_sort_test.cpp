// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/spatial/spatial_sort.h"

#include "pointform/geometry/shapes.h"

#include "../support/thread_counts.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <random>
#include <vector>

namespace pointform {
namespace {

/// The Morton key of a point's cell: 21 bits a coordinate, interleaved x, y, z from the lowest
/// bit, over a cube of `size` from `lo` (the order spatial_order() documents), bit by bit.
std::uint64_t reference_key(const Vec3f& p, const Vec3d& lo, double size)
{
    std::uint64_t key = 0;
    for (int axis = 0; axis < 3; ++axis)
    {
        const double q = (static_cast<double>(p[axis]) - lo[axis]) * (((1U << 21U) - 1U) / size);
        const auto cell = static_cast<std::uint64_t>(std::clamp(q, 0.0, double{0x1FFFFF}));
        for (unsigned bit = 0; bit < 21; ++bit)
            key |= ((cell >> bit) & 1U) << (3U * bit + static_cast<unsigned>(axis));
    }
    return key;
}

TEST(SpatialOrder, MortonOrderTiesByIndexWhateverTheThreadCount)
{
    // Large enough for many blocks of the bucketed sort: a sphere's samples, shuffled, and
    // piles of duplicates (ties) at a few of them.
    PointCloud cloud = sample_shape(Shape::Sphere, {.count = 600000, .seed = 3});
    std::vector<Vec3f> points = cloud.positions;
    std::mt19937 rng(5);
    std::shuffle(points.begin(), points.end(), rng);
    for (std::size_t pile = 0; pile < 40; ++pile)
        points.insert(points.end(), 500, points[pile * 997]);
    const auto orders = test::at_thread_counts([&] { return spatial_order(points); });
    EXPECT_EQ(orders[0], orders[1]);
    EXPECT_EQ(orders[0], orders[2]);
    const std::vector<std::uint32_t>& order = orders[0];
    ASSERT_EQ(order.size(), points.size());
    std::vector<std::uint8_t> seen(points.size(), 0);
    Vec3d lo = points[0].cast<double>();
    Vec3d hi = lo;
    for (const Vec3f& p : points)
    {
        lo = lo.cwiseMin(p.cast<double>());
        hi = hi.cwiseMax(p.cast<double>());
    }
    const double size = (hi - lo).maxCoeff();
    std::size_t out_of_order = 0;
    for (std::size_t j = 0; j < order.size(); ++j)
    {
        ASSERT_LT(order[j], points.size());
        EXPECT_EQ(seen[order[j]]++, 0) << "index " << order[j] << " twice";
        if (j == 0)
            continue;
        const std::uint64_t before = reference_key(points[order[j - 1]], lo, size);
        const std::uint64_t key = reference_key(points[order[j]], lo, size);
        out_of_order += before > key || (before == key && order[j - 1] > order[j]) ? 1U : 0U;
    }
    EXPECT_EQ(out_of_order, 0U);
}

/// The mean distance between points that follow each other in `order`, over those whose both
/// points are `near` the origin.
double mean_step(const std::vector<Vec3f>& points, const std::vector<std::uint32_t>& order,
                 float near)
{
    double sum = 0.0;
    std::size_t steps = 0;
    for (std::size_t j = 1; j < order.size(); ++j)
    {
        const Vec3f& a = points[order[j - 1]];
        const Vec3f& b = points[order[j]];
        if (a.norm() < near && b.norm() < near)
        {
            sum += (a - b).norm();
            ++steps;
        }
    }
    return sum / static_cast<double>(steps);
}

// One point far away (a stray return) makes the grid's cells so large that a whole sphere falls
// into a few of them; the points of such a cell are ordered again over their own box, so those
// that follow each other stay as close as without the outlier (in their input order they would
// be a sphere's size apart). Copies of one point stay in index order.
TEST(SpatialOrder, AFarOutlierLeavesNeighboursClose)
{
    PointCloud cloud = sample_shape(Shape::Sphere, {.count = 200000, .seed = 8});
    std::vector<Vec3f> points = cloud.positions;
    std::mt19937 rng(9);
    std::shuffle(points.begin(), points.end(), rng);
    const double without = mean_step(points, spatial_order(points), 10.0F);
    points.insert(points.end(), 300, points[12345]);
    points.emplace_back(1e7F, 0.0F, 0.0F);
    const auto orders = test::at_thread_counts([&] { return spatial_order(points); });
    EXPECT_EQ(orders[0], orders[1]);
    EXPECT_EQ(orders[0], orders[2]);
    const std::vector<std::uint32_t>& order = orders[0];
    std::vector<std::uint32_t> sorted = order;
    std::sort(sorted.begin(), sorted.end());
    for (std::uint32_t i = 0; i < sorted.size(); ++i)
        ASSERT_EQ(sorted[i], i);
    const double with = mean_step(points, order, 10.0F);
    EXPECT_LT(with, 1.5 * without) << "without the outlier " << without;
    std::vector<std::uint32_t> copies;
    for (const std::uint32_t i : order)
        if (points[i] == points[12345])
            copies.push_back(i);
    ASSERT_EQ(copies.size(), 301U);
    EXPECT_TRUE(std::is_sorted(copies.begin(), copies.end()));
}

} // namespace

// Copies of samples, as a scan merged with itself or coordinates quantized by a file format
// leave them: every copy is named with the first sample at its place, whether a place holds two
// samples or 40 (spread through the cloud), and the order is spatial_order()'s. -0 and +0 are
// one place. A cloud without copies has none. 150k points, so that the passes run in several
// blocks: the same at 1-3 threads.
TEST(SpatialOrder, CopiesWithTheFirstSampleAtTheirPlace)
{
    std::mt19937 random(3);
    std::uniform_real_distribution<float> unit(0.0F, 1.0F);
    std::vector<Vec3f> points(150000);
    for (auto& p : points)
        p = Vec3f(unit(random), unit(random), unit(random));
    std::vector<CoincidentCopy> none{{1, 0}};
    EXPECT_EQ(spatial_order(points, none), spatial_order(points));
    EXPECT_TRUE(none.empty());

    std::vector<CoincidentCopy> expected;
    // A second copy of every 1000th point, at the end.
    for (std::uint32_t i = 0; i < 150000; i += 1000)
    {
        expected.push_back({static_cast<std::uint32_t>(points.size()), i});
        points.push_back(points[i]);
    }
    // 40 copies of point 7, spread through the cloud (overwriting points there).
    for (std::uint32_t c = 1; c <= 40; ++c)
    {
        const std::uint32_t at = 3000 * c + 1;
        points[at] = points[7];
        expected.push_back({at, 7});
    }
    // A point at the origin with signed zeros.
    points[9] = Vec3f(0.0F, 0.0F, 0.0F);
    points[11] = Vec3f(-0.0F, 0.0F, -0.0F);
    expected.push_back({11, 9});
    std::sort(expected.begin(), expected.end(),
              [](const CoincidentCopy& a, const CoincidentCopy& b) { return a.copy < b.copy; });
    const auto runs = test::at_thread_counts(
        [&] {
            std::vector<CoincidentCopy> copies;
            std::vector<std::uint32_t> order = spatial_order(points, copies);
            return std::pair{order, copies};
        },
        {.min_multi_block_loops = 1});
    for (const auto& [order, copies] : runs)
    {
        EXPECT_EQ(order, spatial_order(points));
        ASSERT_EQ(copies.size(), expected.size());
        for (std::size_t c = 0; c < copies.size(); ++c)
        {
            EXPECT_EQ(copies[c].copy, expected[c].copy) << c;
            EXPECT_EQ(copies[c].original, expected[c].original) << c;
        }
    }
}

} // namespace pointform
