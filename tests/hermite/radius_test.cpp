// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/hermite/radius.h"

#include "pointform/core/error.h"
#include "pointform/spatial/kd_tree.h"

#include "support/test_support.h"
#include "support/thread_counts.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

namespace pointform {
namespace {

/// A unit-spaced grid in the plane z = 0: the distance to the k-th neighbour is known exactly.
std::vector<Vec3f> grid(int n)
{
    std::vector<Vec3f> points;
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j)
            points.emplace_back(static_cast<float>(i), static_cast<float>(j), 0.0F);
    return points;
}

TEST(InfluenceRadii, DistanceToKthNeighbourTimesScale)
{
    const auto points = grid(20);
    const KdTree tree(points);
    // Self, 4 at distance 1, 4 at √2, 4 at 2: the 9th nearest (self included) is at √2.
    const KnnTable table = knn_batch(tree, points, 9);
    const std::vector<float> radii = influence_radii(table, 1.5);
    const std::size_t interior = 10 * 20 + 10;
    EXPECT_NEAR(radii[interior], 1.5 * std::sqrt(2.0), 1e-6);
    // The same from a table that keeps only the farthest distances.
    EXPECT_EQ(influence_radii(knn_batch(tree, points, 9, {.farthest_distance_only = true}), 1.5),
              radii);
    EXPECT_THROW((void)influence_radii(table, 0.0), InvalidInput);
    EXPECT_THROW((void)influence_radii(table, std::nan("")), InvalidInput);
}

/// The smallest, the value at n / 2 in order (by std::nth_element) and the largest.
RadiusSummary summary_by_sorting(std::vector<float> values)
{
    const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
    std::nth_element(values.begin(), middle, values.end());
    const auto [lo, hi] = std::minmax_element(values.begin(), values.end());
    return {.min = *lo, .median = *middle, .max = *hi};
}

TEST(SummarizeRadii, SameAsSortingWhateverTheThreadCount)
{
    std::mt19937 random(7);
    std::lognormal_distribution<float> spread(-4.0F, 0.3F);
    std::vector<std::vector<float>> cases;
    // Radii of a scan: 3 million, so that each pass runs in several blocks.
    cases.emplace_back(3'000'000);
    for (auto& r : cases.back())
        r = spread(random);
    // Every radius the same (a grid): the median's bucket holds them all.
    cases.emplace_back(2'500'000, 0.125F);
    // Signed values, zeros of both signs and many ties, an even count.
    std::uniform_int_distribution<int> small(-50, 50);
    cases.emplace_back(2'200'000);
    for (auto& r : cases.back())
        r = static_cast<float>(small(random)) * 0.37F;
    cases.back()[17] = -0.0F;
    cases.back()[18] = std::numeric_limits<float>::infinity();
    // Few values: one block.
    cases.push_back({3.0F});
    cases.push_back({2.0F, 1.0F});
    cases.push_back({5.0F, -1.0F, 4.0F, 4.0F, 0.5F});
    for (const auto& values : cases)
    {
        const RadiusSummary expected = summary_by_sorting(values);
        // Small inputs run in one block, on one thread.
        const auto runs = values.size() > 2'000'000
                              ? test::at_thread_counts([&] { return summarize_radii(values); },
                                                       {.min_multi_block_loops = 2})
                              : std::vector<RadiusSummary>{summarize_radii(values)};
        for (const RadiusSummary& got : runs)
        {
            EXPECT_EQ(got.min, expected.min) << values.size();
            EXPECT_EQ(got.median, expected.median) << values.size();
            EXPECT_EQ(got.max, expected.max) << values.size();
        }
    }
    EXPECT_THROW((void)summarize_radii({}), InvalidInput);
    std::vector<float> with_nan(1'500'000, 1.0F);
    with_nan[1'234'567] = std::numeric_limits<float>::quiet_NaN();
    EXPECT_THROW((void)summarize_radii(with_nan), InvalidInput);
}

/// `count` points of a blob (a cube of half-side `spread`) around `centre`, appended to `points`.
/// \return the index of the first
std::uint32_t add_blob(std::vector<Vec3f>& points, const Vec3f& centre, int count, float spread,
                       std::mt19937& random)
{
    std::uniform_real_distribution<float> offset(-spread, spread);
    const auto first = static_cast<std::uint32_t>(points.size());
    for (int i = 0; i < count; ++i)
        points.push_back(centre + Vec3f(offset(random), offset(random), offset(random)));
    return first;
}

// Stray returns come alone or in small groups away from the scan (100k samples of the unit
// sphere; each sample's reach, its distance to its 16th neighbour, is about 0.025). Groups of
// 1, 5 and 16 samples half a radius off the sphere, whose reach is the gap to the sphere, are
// isolated; nothing else is: groups of 32 and 40 spread thinly and a dense group of 20 (each
// holds neighbourhoods of its own: a component of the field, which the debris filter
// judges), a group of 8 within a reach of the surface (noise, held by the sphere), the sparse
// far face of a thin plate (each of its rows holds only the dense face's samples, but its
// samples hold each other at their own spacing), a
// second sphere sampled 40 times more sparsely (its gaps are many times the first's reaches,
// but its samples hold each other), and the first sphere itself. The same at 1-3 threads.
TEST(IsolatedSamples, SmallGroupsAwayFromTheSurface)
{
    std::mt19937 random(11);
    std::normal_distribution<float> gauss;
    std::vector<Vec3f> points;
    const auto on_sphere = [&](const Vec3f& centre, int count) {
        for (int i = 0; i < count; ++i)
        {
            const Vec3f d(gauss(random), gauss(random), gauss(random));
            points.push_back(centre + d.normalized());
        }
    };
    on_sphere(Vec3f::Zero(), 100000);
    std::vector<std::uint32_t> expected;
    for (const auto& [where, count] :
         {std::pair{Vec3f(1.5F, 0.0F, 0.0F), 1}, std::pair{Vec3f(0.0F, 1.5F, 0.0F), 5},
          std::pair{Vec3f(0.0F, 0.0F, 1.5F), 16}})
    {
        const std::uint32_t first = add_blob(points, where, count, 0.01F, random);
        for (int i = 0; i < count; ++i)
            expected.push_back(first + static_cast<std::uint32_t>(i));
    }
    add_blob(points, Vec3f(-1.1F, -1.1F, 0.0F), 32, 0.15F, random);
    add_blob(points, Vec3f(0.0F, 0.0F, -1.6F), 40, 0.15F, random);
    add_blob(points, Vec3f(-1.6F, 0.0F, 0.0F), 20, 0.01F, random);
    add_blob(points, Vec3f(0.0F, -1.02F, 0.0F), 8, 0.01F, random);
    on_sphere(Vec3f(5.0F, 0.0F, 0.0F), 2500);
    // A thin plate scanned from one side: a dense face, and its far face 0.1 away sampled 100
    // times more sparsely, whose rows hold only the dense face's samples.
    std::uniform_real_distribution<float> side(0.0F, 2.0F);
    for (int i = 0; i < 40000; ++i)
        points.emplace_back(side(random), side(random) + 3.0F, 0.0F);
    for (int i = 0; i < 400; ++i)
        points.emplace_back(side(random), side(random) + 3.0F, 0.1F);

    const KdTree tree(points);
    const KnnTable table = knn_batch(tree, points, 17, {.farthest_distance_only = true});
    const auto runs = test::at_thread_counts([&] { return isolated_samples(points, table); },
                                             {.min_multi_block_loops = 1});
    for (const auto& got : runs)
        EXPECT_EQ(got, expected);
    // A table of the whole distances gives the same.
    EXPECT_EQ(isolated_samples(points, knn_batch(tree, points, 17)), expected);
    // Copies of one point far away (no gap between them, no reach) are not isolated, and a
    // table that does not fit the points is refused.
    std::vector<Vec3f> copies(points.begin(), points.begin() + 100000);
    copies.insert(copies.end(), 20, Vec3f(3.0F, 0.0F, 0.0F));
    const KdTree copies_tree(copies);
    EXPECT_TRUE(isolated_samples(copies, knn_batch(copies_tree, copies, 17)).empty());
    EXPECT_THROW((void)isolated_samples(copies, table), InvalidInput);
}

TEST(RadiusRegions, BallSetsAndBoxScales)
{
    const auto regions = parse_radius_regions(R"({"regions": [
        {"ball": {"center": [100, 200, 0], "radius": 2.5}, "set": 0.75},
        {"box": {"min": [109.5, 209.5, -1], "max": [119.5, 219.5, 1]}, "scale": 3}
    ]})",
                                              "inline.json");
    ASSERT_EQ(regions.size(), 2U);
    // Points stored relative to an origin: regions are in world coordinates.
    const Vec3d origin(100.0, 200.0, 0.0);
    const auto points = grid(20);
    const std::vector<float> automatic(points.size(), 1.0F);
    const std::vector<float> radii = apply_radius_regions(points, origin, automatic, regions);
    for (std::size_t i = 0; i < points.size(); ++i)
    {
        const Vec3d p = origin + points[i].cast<double>();
        float expected = 1.0F;
        if ((p - origin).norm() <= 2.5)
            expected = 0.75F;
        if (p.x() >= 109.5 && p.y() >= 209.5)
            expected = 3.0F;
        EXPECT_EQ(radii[i], expected) << "point " << i;
    }
}

TEST(RadiusRegions, ErrorsNameTheProblem)
{
    const auto expect_error = [](const std::string& json, const std::string& fragment) {
        try
        {
            (void)parse_radius_regions(json, "regions.json");
            ADD_FAILURE() << "no error for " << json;
        }
        catch (const IoError& e)
        {
            const std::string what = e.what();
            EXPECT_NE(what.find("regions.json"), std::string::npos) << what;
            EXPECT_NE(what.find(fragment), std::string::npos) << what;
        }
    };
    expect_error("{\"regions\": [\n  {\"ball\": }\n]}", "regions.json:2");
    expect_error(R"({"regions": [{"ball": {"center": [0,0,0], "radius": 1}}]})", "\"set\"");
    expect_error(R"({"regions": [{"ball": {"center": [0,0], "radius": 1}, "set": 1}]})",
                 "array of 3");
    expect_error(R"({"regions": [{"ball": {"center": [0,0,0], "radius": -1}, "set": 1}]})",
                 "negative");
    expect_error(R"({"regions": [{"box": {"min": [0,0,0], "max": [1,1,1]}, "set": -2}]})",
                 "positive");
    expect_error(R"({"regions": [{"box": {"min": [2,0,0], "max": [1,1,1]}, "set": 2}]})", "exceed");
    expect_error(R"({"zones": []})", "\"regions\"");
}

TEST(RadiusRegions, ReadsFileAndReportsMissingFile)
{
    test::TempDir dir;
    test::write_file(dir / "r.json",
                     R"({"regions": [{"ball": {"center": [0,0,0], "radius": 1}, "set": 0.5}]})");
    EXPECT_EQ(read_radius_regions(dir / "r.json").size(), 1U);
    EXPECT_THROW((void)read_radius_regions(dir / "missing.json"), IoError);
}

} // namespace
} // namespace pointform
