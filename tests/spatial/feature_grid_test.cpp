// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/spatial/feature_grid.h"

#include "pointform/core/error.h"
#include "pointform/core/parallel.h"

#include "support/thread_counts.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

namespace pointform {
namespace {

std::vector<Vec3f> random_points(std::size_t count, const Vec3f& low, const Vec3f& high,
                                 std::uint64_t seed)
{
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<float> u(0.0F, 1.0F);
    std::vector<Vec3f> points(count);
    for (Vec3f& p : points)
    {
        p = low + Vec3f(u(rng), u(rng), u(rng)).cwiseProduct(high - low);
    }
    return points;
}

Aabb box_of(const Vec3d& low, const Vec3d& high)
{
    Aabb box;
    box.extend(low);
    box.extend(high);
    return box;
}

/// Each point's site, the representative of each site (brute force: nearest to the node, ties to
/// the smallest index), and every node's exact squared distance to the nearest site.
void expect_exact_transform(const FeatureGrid& grid, std::span<const Vec3f> points)
{
    const auto [nx, ny, nz] = grid.dims();
    const auto key = [&](const std::array<std::uint32_t, 3>& s) {
        return (static_cast<std::size_t>(s[2]) * ny + s[1]) * nx + s[0];
    };
    std::vector<std::uint32_t> representative(static_cast<std::size_t>(nx) * ny * nz,
                                              std::numeric_limits<std::uint32_t>::max());
    std::vector<std::array<std::uint32_t, 3>> sites;
    double snap = 0.0;
    for (std::uint32_t i = 0; i < points.size(); ++i)
    {
        const auto s = grid.site_of(points[i]);
        // The site is the nearest node (up to rounding at a cell's midpoint).
        const Vec3d offset = points[i].cast<double>() - grid.node_position(s[0], s[1], s[2]);
        EXPECT_LE(offset.cwiseAbs().maxCoeff(), 0.5 * grid.spacing() * (1.0 + 1e-6));
        snap = std::max(snap, offset.norm());
        std::uint32_t& rep = representative[key(s)];
        if (rep == std::numeric_limits<std::uint32_t>::max())
        {
            sites.push_back(s);
            rep = i;
            continue;
        }
        const Vec3d node = grid.node_position(s[0], s[1], s[2]);
        const double mine = (points[i].cast<double>() - node).squaredNorm();
        const double theirs = (points[rep].cast<double>() - node).squaredNorm();
        if (mine < theirs || (mine == theirs && i < rep))
        {
            rep = i;
        }
    }
    EXPECT_GE(grid.snap_radius(), snap);
    EXPECT_LE(grid.snap_radius(), std::sqrt(3.0) / 2.0 * grid.spacing() * (1.0 + 1e-6));

    for (std::uint32_t k = 0; k < nz; ++k)
    {
        for (std::uint32_t j = 0; j < ny; ++j)
        {
            for (std::uint32_t i = 0; i < nx; ++i)
            {
                std::int64_t best = std::numeric_limits<std::int64_t>::max();
                for (const auto& s : sites)
                {
                    const std::int64_t dx = std::int64_t{s[0]} - i;
                    const std::int64_t dy = std::int64_t{s[1]} - j;
                    const std::int64_t dz = std::int64_t{s[2]} - k;
                    best = std::min(best, dx * dx + dy * dy + dz * dz);
                }
                const FeatureGrid::Node& node = grid.node(i, j, k);
                ASSERT_EQ(node.site_distance2, best) << "node " << i << ' ' << j << ' ' << k;
                // The point it names represents a site at exactly that distance.
                const auto s = grid.site_of(points[node.point]);
                ASSERT_EQ(representative[key(s)], node.point);
                const std::int64_t dx = std::int64_t{s[0]} - i;
                const std::int64_t dy = std::int64_t{s[1]} - j;
                const std::int64_t dz = std::int64_t{s[2]} - k;
                ASSERT_EQ(dx * dx + dy * dy + dz * dz, best);
            }
        }
    }
}

TEST(FeatureGrid, TransformIsExactOnRandomSites)
{
    // Sparse sites (most nodes far from any) and dense ones (many points per site).
    for (const std::size_t count : {std::size_t{40}, std::size_t{3000}})
    {
        const std::vector<Vec3f> points =
            random_points(count, Vec3f(-1.0F, 0.0F, 2.0F), Vec3f(1.0F, 0.7F, 2.4F), count);
        const FeatureGrid grid(points, box_of(Vec3d(-1.2, -0.1, 1.9), Vec3d(1.1, 0.8, 2.5)), 24);
        EXPECT_EQ(grid.dims()[0], 24U);
        EXPECT_LT(grid.dims()[1], 24U);
        expect_exact_transform(grid, points);
    }
}

TEST(FeatureGrid, TransformIsExactOnSitesOnAPlaneAndALine)
{
    // Degenerate boxes and sites all in one plane or on one line: many parabolas tie.
    std::vector<Vec3f> plane;
    std::vector<Vec3f> line;
    for (int i = 0; i < 20; ++i)
    {
        for (int j = 0; j < 20; ++j)
        {
            plane.emplace_back(0.05F * static_cast<float>(i), 0.05F * static_cast<float>(j), 0.3F);
        }
        line.emplace_back(0.1F * static_cast<float>(i), 0.0F, 0.0F);
    }
    const FeatureGrid flat(plane, bounding_box(plane), 16);
    EXPECT_EQ(flat.dims()[2], 2U);
    expect_exact_transform(flat, plane);
    const FeatureGrid padded(plane, box_of(Vec3d(-0.2, -0.2, 0.0), Vec3d(1.1, 1.1, 0.7)), 20);
    expect_exact_transform(padded, plane);
    const FeatureGrid thin(line, box_of(Vec3d(-0.5, -0.5, -0.5), Vec3d(2.4, 0.5, 0.5)), 30);
    expect_exact_transform(thin, line);
}

TEST(FeatureGrid, QueryBoundsTheNearestDistanceBothWays)
{
    const std::vector<Vec3f> points =
        random_points(500, Vec3f(0.0F, 0.0F, 0.0F), Vec3f(1.0F, 1.0F, 1.0F), 5);
    const FeatureGrid grid(points, box_of(Vec3d(-0.3, -0.3, -0.3), Vec3d(1.3, 1.3, 1.3)), 20);
    std::mt19937_64 rng(6);
    std::uniform_real_distribution<double> u(-0.3, 1.3);
    const double h = grid.spacing();
    for (int n = 0; n < 2000; ++n)
    {
        const Vec3d q(u(rng), u(rng), u(rng));
        const auto cell = grid.query(q);
        ASSERT_TRUE(cell.has_value());
        double nearest = std::numeric_limits<double>::infinity();
        for (const Vec3f& p : points)
        {
            nearest = std::min(nearest, (p.cast<double>() - q).norm());
        }
        double candidate = std::numeric_limits<double>::infinity();
        for (const std::uint32_t i : cell->points)
        {
            candidate = std::min(candidate, (points[i].cast<double>() - q).norm());
        }
        EXPECT_LE(cell->lower_bound, nearest);
        EXPECT_GE(candidate, nearest);
        EXPECT_LE(candidate, nearest + 2.0 * std::sqrt(3.0) * h);
    }
    // Outside the grid (or not finite), no answer.
    EXPECT_FALSE(grid.query(Vec3d(1.31, 0.5, 0.5)).has_value());
    EXPECT_FALSE(grid.query(Vec3d(0.5, -0.31, 0.5)).has_value());
    EXPECT_FALSE(grid.query(Vec3d(0.5, 0.5, std::nan(""))).has_value());
}

TEST(FeatureGrid, SameGridWhateverTheThreadCount)
{
    const std::vector<Vec3f> points =
        random_points(2000, Vec3f(0.0F, 0.0F, 0.0F), Vec3f(1.0F, 2.0F, 1.0F), 8);
    const Aabb box = box_of(Vec3d(-0.1, -0.1, -0.1), Vec3d(1.1, 2.1, 1.1));
    // 48 nodes a side: its lines and slices run in several parallel blocks.
    auto runs = test::at_thread_counts([&] { return FeatureGrid(points, box, 48); });
    const FeatureGrid& one = runs[0];
    for (std::size_t r = 1; r < runs.size(); ++r)
    {
        const FeatureGrid& two = runs[r];
        ASSERT_EQ(one.dims(), two.dims());
        EXPECT_EQ(one.snap_radius(), two.snap_radius());
        for (std::uint32_t k = 0; k < one.dims()[2]; ++k)
        {
            for (std::uint32_t j = 0; j < one.dims()[1]; ++j)
            {
                for (std::uint32_t i = 0; i < one.dims()[0]; ++i)
                {
                    ASSERT_EQ(one.node(i, j, k).point, two.node(i, j, k).point);
                    ASSERT_EQ(one.node(i, j, k).site_distance2, two.node(i, j, k).site_distance2);
                }
            }
        }
    }
}

TEST(FeatureGrid, RejectsWhatItCannotGrid)
{
    const std::vector<Vec3f> points{Vec3f(0.5F, 0.5F, 0.5F)};
    const Aabb box = box_of(Vec3d::Zero(), Vec3d::Ones());
    EXPECT_THROW(FeatureGrid({}, box, 16), InvalidInput);
    EXPECT_THROW(FeatureGrid(points, Aabb{}, 16), InvalidInput);
    EXPECT_THROW(FeatureGrid(points, box, 1), InvalidInput);
    EXPECT_THROW(FeatureGrid(points, box, 5000), InvalidInput);
    const std::vector<Vec3f> outside{Vec3f(0.5F, 0.5F, 1.5F)};
    EXPECT_THROW(FeatureGrid(outside, box, 16), InvalidInput);
    const std::vector<Vec3f> nan{Vec3f(0.5F, std::nanf(""), 0.5F)};
    EXPECT_THROW(FeatureGrid(nan, box, 16), InvalidInput);
}

} // namespace
} // namespace pointform
