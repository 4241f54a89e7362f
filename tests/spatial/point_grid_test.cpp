// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/spatial/point_grid.h"

#include "pointform/core/error.h"
#include "pointform/geometry/shapes.h"
#include "pointform/spatial/kd_tree.h"
#include "pointform/spatial/spatial_sort.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <limits>
#include <random>
#include <vector>

namespace pointform {
namespace {

/// Every squared distance, sorted with ties by index.
std::vector<std::pair<float, std::uint32_t>> brute_sorted(std::span<const Vec3f> points,
                                                          const Vec3f& q)
{
    std::vector<std::pair<float, std::uint32_t>> all;
    for (std::uint32_t i = 0; i < points.size(); ++i)
    {
        all.emplace_back((points[i] - q).squaredNorm(), i);
    }
    std::sort(all.begin(), all.end());
    return all;
}

void expect_exact(const PointGrid& grid, std::span<const Vec3f> points, const Vec3f& q,
                  std::size_t k)
{
    std::vector<std::uint32_t> slots(k);
    std::vector<float> d2(k);
    const std::size_t found = grid.knn(q, k, slots, d2);
    const auto truth = brute_sorted(points, q);
    ASSERT_EQ(found, std::min(k, points.size()));
    std::vector<std::uint32_t> seen;
    for (std::size_t j = 0; j < found; ++j)
    {
        // The same distances as brute force (to float rounding: the grid sums in another
        // order), each belonging to the point reported; ties may pick either tied point.
        const std::uint32_t index = grid.original_index(slots[j]);
        ASSERT_LT(index, points.size());
        EXPECT_FLOAT_EQ(d2[j], truth[j].first) << "query " << q.transpose() << " rank " << j;
        EXPECT_FLOAT_EQ(d2[j], (points[index] - q).squaredNorm()) << "rank " << j;
        seen.push_back(index);
    }
    std::sort(seen.begin(), seen.end());
    EXPECT_EQ(std::adjacent_find(seen.begin(), seen.end()), seen.end()) << "a point twice";
}

TEST(PointGrid, KnnOnASurfaceMatchesBruteForceNearAndFar)
{
    // A sphere sampled like a scan; queries on it, off it by up to a few cells, and far away
    // (which the grid hands to the kd-tree).
    const PointCloud cloud = sample_shape(Shape::Sphere, {.count = 3000, .seed = 5});
    const KdTree tree(cloud.positions);
    for (const float cell : {0.02F, 0.1F, 0.5F})
    {
        const PointGrid grid(cloud.positions, cell, tree);
        std::mt19937_64 rng(11);
        std::normal_distribution<float> gauss;
        std::uniform_real_distribution<float> radius(0.0F, 3.0F);
        for (int q = 0; q < 300; ++q)
        {
            const Vec3f dir = Vec3f(gauss(rng), gauss(rng), gauss(rng)).normalized();
            const float r = q < 200 ? 1.0F + 0.05F * gauss(rng) : radius(rng);
            for (const std::size_t k : {1U, 9U, 17U})
            {
                expect_exact(grid, cloud.positions, dir * r, k);
            }
        }
    }
}

TEST(PointGrid, KnnFarAnswersWhatTheCellsTurnDown)
{
    // knn_far() is the kd-tree's exact answer anywhere: where knn_nearby() turns a query down
    // it is knn()'s answer bit for bit, and near the points the same distances.
    const PointCloud cloud = sample_shape(Shape::Sphere, {.count = 3000, .seed = 6});
    const KdTree tree(cloud.positions);
    const PointGrid grid(cloud.positions, 0.05F, tree);
    std::mt19937_64 rng(12);
    std::normal_distribution<float> gauss;
    std::uniform_real_distribution<float> radius(0.5F, 2.0F);
    int turned_down = 0;
    for (int q = 0; q < 400; ++q)
    {
        const Vec3f query = Vec3f(gauss(rng), gauss(rng), gauss(rng)).normalized() * radius(rng);
        for (const std::size_t k : {1U, 9U})
        {
            std::vector<std::uint32_t> near_slots(k), far_slots(k), slots(k);
            std::vector<float> near_d2(k), far_d2(k), d2(k);
            const std::size_t near = grid.knn_nearby(query, k, near_slots, near_d2);
            ASSERT_EQ(grid.knn_far(query, k, far_slots, far_d2), k);
            ASSERT_EQ(grid.knn(query, k, slots, d2), k);
            for (std::size_t j = 0; j < k; ++j)
            {
                EXPECT_FLOAT_EQ(far_d2[j], d2[j]);
                if (near == 0)
                {
                    EXPECT_EQ(far_slots[j], slots[j]);
                    EXPECT_EQ(far_d2[j], d2[j]);
                }
            }
            turned_down += near == 0 ? 1 : 0;
        }
    }
    EXPECT_GT(turned_down, 100);
    std::vector<std::uint32_t> short_slots(2);
    std::vector<float> short_d2(2);
    EXPECT_THROW(static_cast<void>(grid.knn_far(Vec3f::Zero(), 9, short_slots, short_d2)),
                 InvalidInput);
}

TEST(PointGrid, SquaredDistancesAreTheBitsOfEveryQuery)
{
    // squared_distances() of the slots a query found gives the distances that query reported,
    // bit for bit, from the cells (knn_nearby()) and from the kd-tree (knn_far()) alike: a
    // caller that re-ranks candidates it holds gets what a new query would.
    const PointCloud cloud = sample_shape(Shape::Part, {.count = 4000, .seed = 8});
    const KdTree tree(cloud.positions);
    const PointGrid grid(cloud.positions, 0.25F, tree);
    std::mt19937_64 rng(14);
    std::uniform_real_distribution<float> u(-1.6F, 1.6F);
    std::normal_distribution<float> gauss(0.0F, 0.02F);
    constexpr std::size_t k = 17;
    int near_queries = 0;
    for (int q = 0; q < 500; ++q)
    {
        // Half near the points (the cells answer), half anywhere (mostly the kd-tree).
        const Vec3f query = q % 2 == 0 ? Vec3f(cloud.positions[static_cast<std::size_t>(q) * 7] +
                                               Vec3f(gauss(rng), gauss(rng), gauss(rng)))
                                       : Vec3f(u(rng), u(rng), u(rng));
        std::array<std::uint32_t, k> slots{};
        std::array<float, k> d2{};
        std::array<float, k> again{};
        if (grid.knn_nearby(query, k, slots, d2) == k)
        {
            ++near_queries;
            grid.squared_distances(query, slots, again);
            for (std::size_t j = 0; j < k; ++j)
                ASSERT_EQ(std::bit_cast<std::uint32_t>(again[j]),
                          std::bit_cast<std::uint32_t>(d2[j]));
        }
        ASSERT_EQ(grid.knn_far(query, k, slots, d2), k);
        grid.squared_distances(query, slots, again);
        for (std::size_t j = 0; j < k; ++j)
            ASSERT_EQ(std::bit_cast<std::uint32_t>(again[j]), std::bit_cast<std::uint32_t>(d2[j]));
    }
    EXPECT_GT(near_queries, 200);
    std::array<std::uint32_t, 3> three{};
    std::array<float, 2> short_d2{};
    EXPECT_THROW(grid.squared_distances(Vec3f::Zero(), three, short_d2), InvalidInput);
}

TEST(PointGrid, SparseRegionsAndGridsQueriedInTurnStayExact)
{
    // A plane sampled densely on one half and 8 times as sparsely on the other (a scan's near
    // and far sides), with cells sized for the dense half: queries over the sparse half are
    // beyond the cells around them (the kd-tree answers). Three grids are queried in turn, so
    // each thread's cached lookups of cells change grids on every query.
    std::vector<Vec3f> points;
    for (int y = 0; y < 40; ++y)
    {
        for (int x = 0; x < 80; ++x)
        {
            const float spacing = x < 40 ? 0.01F : 0.08F;
            const float px =
                x < 40 ? 0.01F * static_cast<float>(x) : 0.4F + 0.08F * static_cast<float>(x - 40);
            points.emplace_back(px, spacing * static_cast<float>(y), 0.0F);
        }
    }
    const KdTree tree(points);
    const PointGrid fine(points, 0.02F, tree);
    const PointGrid mid(points, 0.05F, tree);
    const PointGrid coarse(points, 0.2F, tree);
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<float> x(-0.2F, 3.8F);
    std::uniform_real_distribution<float> y(-0.2F, 3.3F);
    std::uniform_real_distribution<float> z(-0.3F, 0.3F);
    for (int q = 0; q < 400; ++q)
    {
        const Vec3f query(x(rng), y(rng), z(rng));
        for (const PointGrid* grid : {&fine, &mid, &coarse})
        {
            expect_exact(*grid, points, query, q % 2 == 0 ? 9U : 17U);
        }
    }
}

TEST(PointGrid, TiesAreExactAndRepeatable)
{
    // A lattice queried at cell corners and centres: many neighbours at equal distances.
    std::vector<Vec3f> points;
    for (int z = 0; z < 6; ++z)
    {
        for (int y = 0; y < 6; ++y)
        {
            for (int x = 0; x < 6; ++x)
            {
                points.emplace_back(static_cast<float>(x), static_cast<float>(y),
                                    static_cast<float>(z));
            }
        }
    }
    std::reverse(points.begin(), points.end());
    const KdTree tree(points);
    const PointGrid grid(points, 1.5F, tree);
    for (const Vec3f& q : {Vec3f(2.5F, 2.5F, 2.5F), Vec3f(2.0F, 3.0F, 1.0F),
                           Vec3f(0.5F, 0.0F, 0.0F), Vec3f(5.0F, 5.0F, 2.5F)})
    {
        expect_exact(grid, points, q, 8);
        // Asked again after other queries (the thread's cache of cells changed), the same
        // answer.
        std::array<std::uint32_t, 8> first{};
        std::array<std::uint32_t, 8> again{};
        std::array<float, 8> d2{};
        grid.knn(q, 8, first, d2);
        grid.knn(Vec3f(0, 0, 0), 8, again, d2);
        grid.knn(q, 8, again, d2);
        EXPECT_EQ(first, again);
    }
}

TEST(PointGrid, FewPointsDuplicatesAndNonFiniteQueries)
{
    const std::vector<Vec3f> points = {Vec3f(1, 1, 1), Vec3f(1, 1, 1), Vec3f(2, 0, 0)};
    const KdTree tree(points);
    const PointGrid grid(points, 0.1F, tree);
    expect_exact(grid, points, Vec3f(1, 1, 1.01F), 5); // k beyond the count
    expect_exact(grid, points, Vec3f(1e6F, -1e6F, 0), 2);

    const std::vector<Vec3f> none;
    const KdTree empty_tree(none);
    const PointGrid empty(none, 1.0F, empty_tree);
    std::vector<std::uint32_t> slots(3);
    std::vector<float> d2(3);
    EXPECT_EQ(empty.knn(Vec3f::Zero(), 3, slots, d2), 0U);

    EXPECT_THROW(PointGrid(points, 0.0F, tree), InvalidInput);
    EXPECT_THROW(PointGrid(points, -1.0F, tree), InvalidInput);
}

TEST(PointGrid, FarOutlierGrowsTheCellsButStaysExact)
{
    PointCloud cloud = sample_shape(Shape::Sphere, {.count = 500, .seed = 2});
    cloud.positions.emplace_back(3e6F, 0.0F, 0.0F);
    const KdTree tree(cloud.positions);
    const PointGrid grid(cloud.positions, 0.01F, tree);
    EXPECT_GT(grid.cell_size(), 0.01F);
    for (const Vec3f& q : {Vec3f(1, 0, 0), Vec3f(0, 0.7F, 0.7F), Vec3f(2.9e6F, 0, 0)})
    {
        expect_exact(grid, cloud.positions, q, 4);
    }
}

/// The batch knn_nearby() against one query at a time: the same count, slots and distance bits.
/// \return how many queries the grid answered
std::size_t expect_batch_as_single(const PointGrid& grid, std::span<const Vec3f> queries,
                                   std::size_t k)
{
    std::vector<std::uint32_t> slots(queries.size() * k);
    std::vector<float> d2(queries.size() * k);
    std::vector<std::uint32_t> found(queries.size());
    grid.knn_nearby(queries, k, slots, d2, found);
    std::vector<std::uint32_t> single_slots(k);
    std::vector<float> single_d2(k);
    std::size_t answered = 0;
    for (std::size_t i = 0; i < queries.size(); ++i)
    {
        const std::size_t single = grid.knn_nearby(queries[i], k, single_slots, single_d2);
        EXPECT_EQ(found[i], single) << "query " << i << " k " << k;
        if (found[i] != single)
        {
            return answered;
        }
        answered += single > 0 ? 1 : 0;
        for (std::size_t j = 0; j < single; ++j)
        {
            EXPECT_EQ(slots[i * k + j], single_slots[j]) << "query " << i << " k " << k;
            EXPECT_EQ(std::bit_cast<std::uint32_t>(d2[i * k + j]),
                      std::bit_cast<std::uint32_t>(single_d2[j]))
                << "query " << i << " k " << k;
        }
    }
    return answered;
}

TEST(PointGrid, BatchAnswersAsOneByOneInAnyOrder)
{
    // A sphere with a cell as a point field chooses it, queried within a few cells of the
    // surface (some beyond, for the 3 × 3 × 3 pass and none), in Morton order (coherent runs)
    // and at random, for k from 1 to beyond the grid's limit.
    const PointCloud cloud = sample_shape(Shape::Sphere, {.count = 20000, .seed = 4});
    const KdTree tree(cloud.positions);
    std::vector<std::uint32_t> index(9);
    std::vector<float> d2(9);
    tree.knn(cloud.positions[0], 9, index, d2);
    const float cell = 2.5F * std::sqrt(d2[8]);
    const PointGrid grid(cloud.positions, cell, tree);
    std::mt19937_64 rng(12);
    std::normal_distribution<float> gauss;
    std::uniform_real_distribution<float> shell(-1.5F * cell, 1.5F * cell);
    std::vector<Vec3f> random(4000);
    for (Vec3f& q : random)
    {
        q = Vec3f(gauss(rng), gauss(rng), gauss(rng)).normalized() * (1.0F + shell(rng));
    }
    const std::vector<std::uint32_t> order = spatial_order(random);
    std::vector<Vec3f> coherent(random.size());
    for (std::size_t i = 0; i < order.size(); ++i)
    {
        coherent[i] = random[order[i]];
    }
    for (const std::size_t k : {1U, 2U, 9U, 17U, 33U, 64U})
    {
        // Not a comparison of empty answers: for few neighbours the grid answers most of
        // these queries, for many about half (the rest is the kd-tree's).
        const std::size_t enough = k <= 17 ? random.size() * 2 / 3 : random.size() / 3;
        EXPECT_GT(expect_batch_as_single(grid, coherent, k), enough) << "k " << k;
        EXPECT_GT(expect_batch_as_single(grid, random, k), enough) << "k " << k;
    }
}

/// The k smallest (squared distance, slot) keys of every point of the grid, the distance
/// summed as the grid sums it ((x − q)² + (y − q)² + (z − q)², in float, in that order).
std::vector<std::uint32_t> smallest_slots(const PointGrid& grid, std::span<const Vec3f> points,
                                          const Vec3f& q, std::size_t k)
{
    std::vector<std::pair<std::uint32_t, std::uint32_t>> keys;
    for (std::uint32_t slot = 0; slot < grid.slot_count(); ++slot)
    {
        const std::uint32_t index = grid.original_index(slot);
        if (index == PointGrid::padding_slot)
        {
            continue;
        }
        const float dx = points[index].x() - q.x();
        const float dy = points[index].y() - q.y();
        const float dz = points[index].z() - q.z();
        const float xx = dx * dx;
        const float yy = dy * dy;
        const float zz = dz * dz;
        keys.emplace_back(std::bit_cast<std::uint32_t>((xx + yy) + zz), slot);
    }
    std::partial_sort(keys.begin(), keys.begin() + static_cast<std::ptrdiff_t>(k), keys.end());
    std::vector<std::uint32_t> slots;
    for (std::size_t j = 0; j < k; ++j)
    {
        slots.push_back(keys[j].second);
    }
    return slots;
}

TEST(PointGrid, AnswersAreTheExactSmallestKeysWhateverCameBefore)
{
    // Whatever the grid answers, one by one (which keeps what it looked up from one query to
    // the next) or in a batch, is the k smallest (distance, slot) keys of all its points, bit
    // for bit: queries on and off a sphere, in Morton order and at random, far ones among them
    // (where the guess from the last query fails and the selection narrows or widens), for k
    // on both sides of the short ranking's limit.
    const PointCloud cloud = sample_shape(Shape::Sphere, {.count = 5000, .seed = 9});
    const KdTree tree(cloud.positions);
    std::mt19937_64 rng(21);
    std::normal_distribution<float> gauss;
    std::uniform_real_distribution<float> shell(-2.0F, 2.0F); // in cells
    std::vector<Vec3f> directions(600);
    std::vector<float> offsets(directions.size());
    for (std::size_t i = 0; i < directions.size(); ++i)
    {
        directions[i] = Vec3f(gauss(rng), gauss(rng), gauss(rng)).normalized();
        offsets[i] = shell(rng);
    }
    for (const std::size_t k : {2U, 9U, 17U, 24U, 25U, 40U})
    {
        // Cells as a point field sizes them for k neighbours.
        std::vector<std::uint32_t> index(k);
        std::vector<float> d2(k);
        tree.knn(cloud.positions[0], k, index, d2);
        const float cell = 2.5F * std::sqrt(d2[k - 1]);
        const PointGrid grid(cloud.positions, cell, tree);
        std::vector<Vec3f> queries(directions.size());
        for (std::size_t i = 0; i < queries.size(); ++i)
        {
            queries[i] = directions[i] * (1.0F + offsets[i] * cell);
        }
        const std::vector<std::uint32_t> order = spatial_order(queries);
        std::vector<Vec3f> coherent(queries.size());
        for (std::size_t i = 0; i < order.size(); ++i)
        {
            coherent[i] = queries[order[i]];
        }
        for (const std::vector<Vec3f>* run : {&coherent, &queries})
        {
            std::vector<std::uint32_t> slots(run->size() * k);
            std::vector<float> batch_d2(run->size() * k);
            std::vector<std::uint32_t> found(run->size());
            grid.knn_nearby(*run, k, slots, batch_d2, found);
            std::size_t answered = 0;
            for (std::size_t i = 0; i < run->size(); ++i)
            {
                std::vector<std::uint32_t> single(k);
                std::vector<float> single_d2(k);
                const std::size_t count = grid.knn_nearby((*run)[i], k, single, single_d2);
                ASSERT_EQ(count, found[i]) << "query " << i << " k " << k;
                if (count == 0)
                {
                    continue;
                }
                ++answered;
                const std::vector<std::uint32_t> truth =
                    smallest_slots(grid, cloud.positions, (*run)[i], k);
                ASSERT_EQ(single, truth) << "query " << i << " k " << k;
                ASSERT_TRUE(std::equal(truth.begin(), truth.end(), slots.begin() + i * k))
                    << "query " << i << " k " << k;
            }
            EXPECT_GT(answered, run->size() / 3) << "k " << k;
        }
    }
}

TEST(PointGrid, BatchHandlesTiesCrowdsAndQueriesItCannotPlace)
{
    // A lattice (ties everywhere), with a pile of duplicates in one cell (more than a pass
    // holds: none from the grid) and queries at lattice points, far away and not finite.
    std::vector<Vec3f> points;
    for (int z = 0; z < 8; ++z)
    {
        for (int y = 0; y < 8; ++y)
        {
            for (int x = 0; x < 8; ++x)
            {
                points.emplace_back(static_cast<float>(x), static_cast<float>(y),
                                    static_cast<float>(z));
            }
        }
    }
    points.insert(points.end(), 1500, Vec3f(6.2F, 6.2F, 6.2F));
    const KdTree tree(points);
    const PointGrid grid(points, 1.5F, tree);
    std::vector<Vec3f> queries;
    for (float z = 0.0F; z <= 7.0F; z += 0.5F)
    {
        for (float y = 0.0F; y <= 7.0F; y += 0.5F)
        {
            for (float x = 0.0F; x <= 7.0F; x += 0.5F)
            {
                queries.emplace_back(x, y, z);
            }
        }
    }
    queries.emplace_back(1e9F, 0.0F, 0.0F);
    queries.emplace_back(std::numeric_limits<float>::quiet_NaN(), 1.0F, 1.0F);
    queries.emplace_back(1.0F, std::numeric_limits<float>::infinity(), 1.0F);
    queries.emplace_back(6.2F, 6.2F, 6.2F);
    for (const std::size_t k : {1U, 8U, 27U})
    {
        EXPECT_GT(expect_batch_as_single(grid, queries, k), queries.size() / 10) << "k " << k;
    }
    // The crowd: one by one and together, none.
    std::array<std::uint32_t, 8> slots{};
    std::array<float, 8> d2{};
    EXPECT_EQ(grid.knn_nearby(Vec3f(6.2F, 6.2F, 6.2F), 8, slots, d2), 0U);
}

TEST(PointGrid, BatchOfNothingAndOfAnEmptyGrid)
{
    const std::vector<Vec3f> points = {Vec3f(0, 0, 0), Vec3f(1, 0, 0)};
    const KdTree tree(points);
    const PointGrid grid(points, 2.0F, tree);
    std::vector<std::uint32_t> found(2, 7U);
    std::vector<std::uint32_t> slots(6);
    std::vector<float> d2(6);
    grid.knn_nearby(std::span<const Vec3f>(), 3, slots, d2, std::span<std::uint32_t>());
    const std::vector<Vec3f> queries = {Vec3f(0.1F, 0, 0), Vec3f(0.9F, 0, 0)};
    grid.knn_nearby(queries, 3, slots, d2, found); // k beyond the count: both points
    EXPECT_EQ(found[0], 2U);
    EXPECT_EQ(grid.original_index(slots[0]), 0U);
    EXPECT_EQ(grid.original_index(slots[3]), 1U);
    grid.knn_nearby(queries, 0, slots, d2, found);
    EXPECT_EQ(found[0], 0U);

    const std::vector<Vec3f> none;
    const KdTree empty_tree(none);
    const PointGrid empty(none, 1.0F, empty_tree);
    found.assign(2, 7U);
    empty.knn_nearby(queries, 3, slots, d2, found);
    EXPECT_EQ(found[0], 0U);
    EXPECT_EQ(found[1], 0U);
}

} // namespace
} // namespace pointform
