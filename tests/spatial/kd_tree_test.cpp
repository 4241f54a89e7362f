// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/spatial/kd_tree.h"

#include "pointform/core/error.h"
#include "pointform/core/parallel.h"
#include "pointform/geometry/shapes.h"
#include "pointform/spatial/spatial_sort.h"

#include "support/thread_counts.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
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

TEST(KdTree, FarthestDistanceOnlyKeepsTheKthOfEveryRow)
{
    const auto points = random_points(5000, 9);
    const KdTree tree(points);
    constexpr std::size_t k = 9;
    const KnnTable all = knn_batch(tree, points, k);
    const KnnTable farthest = knn_batch(tree, points, k, {.farthest_distance_only = true});
    ASSERT_TRUE(all.has_all_distances());
    ASSERT_FALSE(farthest.has_all_distances());
    ASSERT_EQ(farthest.squared_distances.size(), points.size());
    EXPECT_EQ(farthest.indices, all.indices);
    for (std::size_t i = 0; i < points.size(); ++i)
    {
        ASSERT_EQ(farthest.farthest2(i), all.distances2(i).back());
        ASSERT_EQ(all.farthest2(i), all.distances2(i).back());
    }
    EXPECT_NO_THROW(check_knn_table(farthest, points.size(), points.size(), "test"));
    KnnTable odd = farthest;
    odd.squared_distances.push_back(0.0F); // neither one a row nor one an index
    EXPECT_THROW(check_knn_table(odd, points.size(), points.size(), "test"), InvalidInput);
}

TEST(KdTree, NearestWithinFactorWithAndWithoutAStart)
{
    // Samples of a unit sphere; queries deep inside (where every sample is nearly as far) and
    // outside. The point returned is a real point at most `factor` times as far as the nearest,
    // from any start; with factor 1 it is as near as the nearest.
    const PointCloud sphere = sample_shape(Shape::Sphere, {.count = 3000, .seed = 4});
    const std::vector<Vec3f>& points = sphere.positions;
    const KdTree tree(points);
    std::mt19937_64 rng(5);
    std::uniform_int_distribution<std::uint32_t> any(0,
                                                     static_cast<std::uint32_t>(points.size() - 1));
    std::vector<Vec3f> queries = random_points(100, 9);
    for (Vec3f& q : random_points(100, 10))
        queries.push_back(q * 0.3F);
    for (Vec3f& q : random_points(100, 11))
        queries.push_back(q * 3.0F);
    for (const Vec3f& q : queries)
    {
        const float nearest = brute_sorted(points, q).front().first;
        for (const float factor : {1.0F, 1.01F, 1.2F})
        {
            const auto check = [&](PointId found, float d2) {
                ASSERT_TRUE(found.is_valid());
                // The tree sums the squares in its own order: equal up to float rounding.
                const float exact = (points[found.value] - q).squaredNorm();
                EXPECT_NEAR(d2, exact, 1e-6F * exact);
                EXPECT_GE(d2, nearest * (1.0F - 1e-6F));
                EXPECT_LE(std::sqrt(d2), factor * std::sqrt(nearest) * (1.0F + 1e-6F));
            };
            float d2 = 0.0F;
            const PointId plain = tree.nearest_within_factor(q, factor, &d2);
            check(plain, d2);
            const PointId started = tree.nearest_within_factor(q, factor, PointId(any(rng)), &d2);
            check(started, d2);
        }
        // A start that is the nearest comes back.
        const std::uint32_t best = brute_sorted(points, q).front().second;
        float d2 = 0.0F;
        EXPECT_EQ(tree.nearest_within_factor(q, 1.5F, PointId(best), &d2).value, best);
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
    const auto runs = test::at_thread_counts([&] { return knn_batch(tree, cloud.positions, 10); });
    for (std::size_t i = 1; i < runs.size(); ++i)
    {
        EXPECT_EQ(runs[0].indices, runs[i].indices) << i + 1 << " threads";
        EXPECT_EQ(runs[0].squared_distances, runs[i].squared_distances) << i + 1 << " threads";
    }
}

/// Squared distance as nanoflann's L2_Simple_Adaptor sums it (x, then y, then z, in float), so
/// that exact ties are ties in both.
float squared_distance(const Vec3f& a, const Vec3f& b)
{
    float d2 = 0.0F;
    for (int k = 0; k < 3; ++k)
    {
        const float d = a[k] - b[k];
        d2 += d * d;
    }
    return d2;
}

// Points out of Morton order are searched in a sorted copy: every answer is in the caller's
// indices and the same as over the same points given in Morton order (mapped), ties at the k-th
// distance and at distance 0 (copies) included, whatever the thread count; the queries of
// knn_batch() over the tree's own points run in the tree's order, in more than one block.
TEST(KdTree, PointsOutOfOrderAreSearchedInASortedCopy)
{
    // 60,000 points on a coarse lattice (many ties, exact in float), some repeated, in random
    // order.
    std::vector<Vec3f> points = random_points(60000, 17);
    for (auto& p : points)
        p = (p * 16.0F).array().round().matrix() / 16.0F;
    for (std::size_t i = 0; i < 1000; ++i)
        points[points.size() - 1 - i] = points[i * 7];
    const std::vector<std::uint32_t> order = spatial_order(points);
    std::vector<Vec3f> sorted(points.size());
    for (std::size_t i = 0; i < order.size(); ++i)
        sorted[i] = points[order[i]];

    const KdTree in_order(sorted);
    EXPECT_TRUE(in_order.spatial_order().empty());
    EXPECT_EQ(in_order.positions().data(), sorted.data());
    constexpr std::size_t k = 20;
    const KnnTable expected_sorted = knn_batch(in_order, sorted, k);
    const auto runs = test::at_thread_counts(
        [&] {
            const KdTree tree(points);
            EXPECT_EQ(tree.positions().data(), points.data());
            EXPECT_EQ(std::vector<std::uint32_t>(tree.spatial_order().begin(),
                                                 tree.spatial_order().end()),
                      order);
            return knn_batch(tree, points, k);
        },
        {.min_multi_block_loops = 2}, {1, 2, 3});
    for (const KnnTable& table : runs)
    {
        ASSERT_EQ(table.rows(), points.size());
        EXPECT_EQ(table.indices, runs[0].indices);
        // Row order[i] over the caller's points is row i over the sorted ones: the same
        // distances.
        for (std::size_t i = 0; i < order.size(); ++i)
            ASSERT_TRUE(std::equal(table.distances2(order[i]).begin(),
                                   table.distances2(order[i]).end(),
                                   expected_sorted.distances2(i).begin()));
    }
    // The neighbours, ties taken by the caller's index (the lattice's distances are exact).
    for (std::size_t q = 0; q < points.size(); q += 211)
    {
        const auto truth = brute_sorted(points, points[q]);
        for (std::size_t j = 0; j < k; ++j)
            ASSERT_EQ(runs[0].neighbors(q)[j], truth[j].second) << "query " << q << " rank " << j;
    }

    // nearest_within_factor() and radius_search() answer in the caller's indices too.
    const KdTree tree(points);
    const std::vector<Vec3f> queries = random_points(300, 18);
    for (const Vec3f& q : queries)
    {
        const auto truth = brute_sorted(points, q);
        float d2 = 0.0F;
        const PointId near = tree.nearest_within_factor(q, 1.0F, &d2);
        ASSERT_EQ(d2, squared_distance(points[near.value], q));
        ASSERT_NEAR(d2, truth.front().first, 1e-6F * truth.front().first);
        const PointId started = tree.nearest_within_factor(q, 2.0F, PointId(truth[5].second), &d2);
        ASSERT_EQ(d2, squared_distance(points[started.value], q));
        ASSERT_LE(d2, truth[5].first * (1.0F + 1e-6F));
        // The radius halfway between two distances, so that rounding cannot move a point
        // across it.
        const float radius = std::sqrt(0.5F * (truth[30].first + truth[31].first));
        if (truth[31].first - truth[30].first < 1e-4F * truth[31].first)
            continue;
        std::vector<std::uint32_t> within;
        std::vector<float> within_d2;
        ASSERT_EQ(tree.radius_search(q, radius, within, within_d2), 31U);
        std::vector<std::uint32_t> brute;
        for (std::size_t j = 0; j < 31; ++j)
            brute.push_back(truth[j].second);
        std::sort(within.begin(), within.end());
        std::sort(brute.begin(), brute.end());
        ASSERT_EQ(within, brute);
    }
}

TEST(KdTree, DuplicatePointsAreOrderedByIndex)
{
    std::vector<Vec3f> points(10, Vec3f(1.0F, 2.0F, 3.0F));
    points.push_back(Vec3f(5.0F, 5.0F, 5.0F));
    const KdTree tree(points);
    const KnnTable table = knn_batch(tree, std::span<const Vec3f>(points).first(1), 10);
    std::vector<std::uint32_t> expected(10);
    std::iota(expected.begin(), expected.end(), 0U);
    EXPECT_TRUE(std::ranges::equal(table.indices, expected));
}

/// Sites with many coincident copies each (their indices scattered through the array), plus
/// scattered points, so that the k-th neighbour distance of a query often ties.
std::vector<Vec3f> clustered_points(std::uint64_t seed)
{
    std::vector<Vec3f> points = random_points(400, seed);
    const std::vector<Vec3f> sites = random_points(8, seed + 1);
    for (const Vec3f& site : sites)
        for (int copy = 0; copy < 40; ++copy)
            points.push_back(site);
    // Two sites at the same distance from the origin, on opposite sides: ties across sites too.
    for (int copy = 0; copy < 30; ++copy)
    {
        points.emplace_back(0.5F, 0.0F, 0.0F);
        points.emplace_back(-0.5F, 0.0F, 0.0F);
    }
    std::mt19937_64 rng(seed + 2);
    std::shuffle(points.begin(), points.end(), rng);
    return points;
}

TEST(KdTree, TiesAtTheKthNeighbourGoToTheLowestIndices)
{
    const std::vector<Vec3f> points = clustered_points(31);
    std::vector<Vec3f> queries = random_points(100, 32);
    queries.emplace_back(0.0F, 0.0F, 0.0F); // equidistant from the two opposite sites
    for (std::size_t i = 0; i < points.size(); i += 7)
        queries.push_back(points[i]); // on a site: many neighbours at distance 0
    for (const std::size_t leaf : {1, 4, 16, 64})
    {
        const KdTree tree(points, {.leaf_size = leaf});
        for (const std::size_t k : {1, 5, 39, 40, 41, 60, 75})
        {
            const KnnTable table = knn_batch(tree, queries, k);
            std::size_t tied = 0; // queries whose k-th distance is shared beyond k
            for (std::size_t q = 0; q < queries.size(); ++q)
            {
                std::vector<std::pair<float, std::uint32_t>> truth;
                for (std::uint32_t i = 0; i < points.size(); ++i)
                    truth.emplace_back(squared_distance(points[i], queries[q]), i);
                std::sort(truth.begin(), truth.end());
                tied += truth[k].first == truth[k - 1].first ? 1 : 0;
                for (std::size_t j = 0; j < k; ++j)
                {
                    ASSERT_EQ(table.neighbors(q)[j], truth[j].second)
                        << "leaf " << leaf << " k " << k << " query " << q << " rank " << j;
                    ASSERT_EQ(table.distances2(q)[j], truth[j].first);
                }
            }
            if (k > 1)
            {
                EXPECT_GT(tied, 10U) << "k " << k; // the case under test does occur
            }
        }
    }
}

/// A bound that k points lie within (KdTree::knn() with bound2) changes nothing, bit for bit,
/// from the tightest (the k-th distance itself, ties at it included) to one from the triangle
/// inequality (a point of the tree and its own k-th distance), near the points and far from
/// them; a bound that fewer lie within gives those, nearest first.
TEST(KdTree, BoundedKnnMatchesUnbounded)
{
    const std::vector<Vec3f> points = clustered_points(41);
    std::vector<Vec3f> queries = random_points(60, 42);
    for (std::size_t i = 0; i < 60; ++i)
        queries.push_back(queries[i] * 6.0F); // far outside the points' box
    for (std::size_t i = 0; i < points.size(); i += 11)
        queries.push_back(points[i]); // on a site: ties at distance 0
    for (const std::size_t leaf : {1, 16})
    {
        const KdTree tree(points, {.leaf_size = leaf});
        for (const std::size_t k : {1, 9, 40, 41})
        {
            std::vector<std::uint32_t> want(k);
            std::vector<float> want_d2(k);
            std::vector<std::uint32_t> got(k);
            std::vector<float> got_d2(k);
            for (const Vec3f& q : queries)
            {
                ASSERT_EQ(tree.knn(q, k, want, want_d2), k);
                // The tree's point nearest the query and its own k-th distance.
                std::vector<std::uint32_t> near_index(k);
                std::vector<float> near_d2(k);
                tree.knn(points[want[0]], k, near_index, near_d2);
                const double by_point = (std::sqrt(static_cast<double>(want_d2[0])) +
                                         std::sqrt(static_cast<double>(near_d2[k - 1]))) *
                                        (1.0 + 1e-6);
                for (const float bound2 : {want_d2[k - 1], 1.5F * want_d2[k - 1],
                                           static_cast<float>(by_point * by_point),
                                           std::numeric_limits<float>::infinity()})
                {
                    std::fill(got.begin(), got.end(), ~std::uint32_t{0});
                    ASSERT_EQ(tree.knn(q, k, bound2, got, got_d2), k);
                    EXPECT_EQ(got, want) << "leaf " << leaf << " k " << k;
                    EXPECT_EQ(got_d2, want_d2);
                }
                // Too small a bound: only the nearest within it (up to the slack).
                if (k > 1 && want_d2[0] < want_d2[k - 1] * 0.5F)
                {
                    const float small = want_d2[k - 1] * 0.5F;
                    const std::size_t inside = static_cast<std::size_t>(
                        std::count_if(want_d2.begin(), want_d2.end(),
                                      [&](float d2) { return d2 < small * (1.0F + 0x1p-16F); }));
                    ASSERT_EQ(tree.knn(q, k, small, got, got_d2), inside);
                    for (std::size_t j = 0; j < inside; ++j)
                        EXPECT_EQ(got[j], want[j]);
                }
            }
        }
    }
}

/// Points in Morton order (spatial_order()) get the tree split where their Morton keys differ
/// (KdTree::Impl::build_in_order()): the same neighbours, ties included, as brute force: many
/// coincident copies (cells holding more points than a leaf), a lattice (points on the split
/// planes) and a flat plate (keys that never differ along one axis), at every leaf size and
/// thread count (the subtrees are built at once), with k above and below the 40 copies of a
/// cluster (below: a query on a cluster stops at its first copy past the k-th).
TEST(KdTree, PointsInMortonOrderGetTheirNeighbours)
{
    std::vector<Vec3f> lattice = random_points(30000, 51);
    for (auto& p : lattice)
        p = (p * 16.0F).array().round().matrix() / 16.0F;
    std::vector<Vec3f> plate = random_points(30000, 52);
    for (auto& p : plate)
        p.z() = 0.25F;
    for (std::vector<Vec3f> points : {clustered_points(61), lattice, plate})
    {
        const std::vector<std::uint32_t> order = spatial_order(points);
        std::vector<Vec3f> sorted(points.size());
        for (std::size_t j = 0; j < order.size(); ++j)
            sorted[j] = points[order[j]];
        std::vector<Vec3f> queries = random_points(60, 62);
        for (std::size_t i = 0; i < sorted.size(); i += sorted.size() / 40)
            queries.push_back(sorted[i]);
        for (const auto& [leaf, k] :
             {std::pair<std::size_t, std::size_t>{1, 41}, {4, 17}, {16, 41}, {16, 17}, {64, 5}})
        {
            const auto build_and_query = [&] {
                const KdTree tree(sorted, {.leaf_size = leaf});
                return knn_batch(tree, queries, k);
            };
            // The clusters are too few points for parallel blocks.
            const std::vector<KnnTable> runs =
                sorted.size() < 10000
                    ? std::vector<KnnTable>{build_and_query()}
                    : test::at_thread_counts(build_and_query, {.min_multi_block_loops = 2}, {1, 3});
            for (const KnnTable& table : runs)
                for (std::size_t q = 0; q < queries.size(); ++q)
                {
                    std::vector<std::pair<float, std::uint32_t>> truth;
                    for (std::uint32_t i = 0; i < sorted.size(); ++i)
                        truth.emplace_back(squared_distance(sorted[i], queries[q]), i);
                    std::partial_sort(truth.begin(), truth.begin() + static_cast<std::ptrdiff_t>(k),
                                      truth.end());
                    for (std::size_t j = 0; j < k; ++j)
                    {
                        ASSERT_EQ(table.neighbors(q)[j], truth[j].second)
                            << "leaf " << leaf << " k " << k << " query " << q << " rank " << j;
                        ASSERT_EQ(table.distances2(q)[j], truth[j].first);
                    }
                }
        }
    }
}

/// Tens of thousands of copies of one point (a scanner's zero returns) in Morton order: each
/// copy's k nearest are the first k copies, found without offering every copy to every query
/// (which made this quadratic).
TEST(KdTree, ManyCopiesOfOnePointInMortonOrder)
{
    std::vector<Vec3f> points = random_points(20000, 71);
    points.resize(80000, Vec3f(0.125F, -0.5F, 0.25F));
    const std::vector<std::uint32_t> order = spatial_order(points);
    std::vector<Vec3f> sorted(points.size());
    for (std::size_t j = 0; j < order.size(); ++j)
        sorted[j] = points[order[j]];
    const KdTree tree(sorted);
    const KnnTable table = knn_batch(tree, sorted, 17);
    std::vector<std::uint32_t> copies;
    for (std::uint32_t i = 0; i < sorted.size(); ++i)
        if (sorted[i] == Vec3f(0.125F, -0.5F, 0.25F))
            copies.push_back(i);
    ASSERT_EQ(copies.size(), 60000U);
    for (std::size_t c = 0; c < copies.size(); c += 997)
        for (std::size_t j = 0; j < 17; ++j)
        {
            ASSERT_EQ(table.neighbors(copies[c])[j], copies[j]) << c;
            ASSERT_EQ(table.distances2(copies[c])[j], 0.0F);
        }
    for (std::uint32_t q = 0; q < sorted.size(); q += 1999)
    {
        std::vector<std::pair<float, std::uint32_t>> truth;
        for (std::uint32_t i = 0; i < sorted.size(); ++i)
            truth.emplace_back(squared_distance(sorted[i], sorted[q]), i);
        std::partial_sort(truth.begin(), truth.begin() + 17, truth.end());
        for (std::size_t j = 0; j < 17; ++j)
            ASSERT_EQ(table.neighbors(q)[j], truth[j].second) << q;
    }
}

/// Points in Morton order of a grid whose cells a far outlier made large (a sphere in a few
/// cells, in the input's order inside each): the tree keys such a cell's points again over their
/// own box instead of leaving thousands in one leaf, and the neighbours, ties and copies
/// included, are brute force's at every leaf size.
TEST(KdTree, CellsMadeLargeByAFarOutlier)
{
    PointCloud cloud = sample_shape(Shape::Sphere, {.count = 20000, .seed = 81});
    std::vector<Vec3f> points = cloud.positions;
    points.insert(points.end(), 40, points[777]);
    points.emplace_back(1e7F, 0.0F, 0.0F);
    std::vector<std::uint64_t> keys(points.size());
    morton_keys(points, keys);
    std::vector<std::uint32_t> order(points.size());
    std::iota(order.begin(), order.end(), 0U);
    std::stable_sort(order.begin(), order.end(),
                     [&](std::uint32_t a, std::uint32_t b) { return keys[a] < keys[b]; });
    std::vector<Vec3f> sorted(points.size());
    for (std::size_t j = 0; j < order.size(); ++j)
        sorted[j] = points[order[j]];
    std::vector<Vec3f> queries;
    for (std::size_t i = 0; i < sorted.size(); i += 97)
        queries.push_back(sorted[i]);
    queries.push_back(points[777]);
    for (const std::size_t leaf : {1U, 16U, 64U})
    {
        const KdTree tree(sorted, {.leaf_size = leaf});
        const KnnTable table = knn_batch(tree, queries, 45);
        for (std::size_t q = 0; q < queries.size(); ++q)
        {
            std::vector<std::pair<float, std::uint32_t>> truth;
            for (std::uint32_t i = 0; i < sorted.size(); ++i)
                truth.emplace_back(squared_distance(sorted[i], queries[q]), i);
            std::partial_sort(truth.begin(), truth.begin() + 45, truth.end());
            for (std::size_t j = 0; j < 45; ++j)
            {
                ASSERT_EQ(table.neighbors(q)[j], truth[j].second)
                    << "leaf " << leaf << " query " << q << " rank " << j;
                ASSERT_EQ(table.distances2(q)[j], truth[j].first);
            }
        }
    }
}

TEST(KdTree, TiedResultsIndependentOfThreadCountAndLayout)
{
    const std::vector<Vec3f> points = clustered_points(41);
    const std::vector<Vec3f> queries = points; // every point: ties at distance 0
    const KdTree reference_tree(points, {.leaf_size = 1});
    set_thread_count(1);
    const KnnTable reference = knn_batch(reference_tree, queries, 45);
    for (const int threads : {2, 0})
        for (const std::size_t leaf : {8, 32})
        {
            set_thread_count(threads);
            const KdTree tree(points, {.leaf_size = leaf});
            const KnnTable table = knn_batch(tree, queries, 45);
            EXPECT_EQ(table.indices, reference.indices) << threads << " threads, leaf " << leaf;
            EXPECT_EQ(table.squared_distances, reference.squared_distances);
        }
    set_thread_count(0);
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
