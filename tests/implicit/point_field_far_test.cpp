// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// The point field far from its samples: deep inside (the far grid), far outside (the kd-tree),
// and the boundary between defined and undefined, against brute force.

#include "pointform/core/parallel.h"
#include "pointform/geometry/shapes.h"
#include "pointform/implicit/point_field.h"
#include "pointform/spatial/feature_grid.h"

#include "support/thread_counts.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <limits>
#include <numbers>
#include <random>
#include <vector>

namespace pointform {
namespace {

/// A unit sphere sampled exactly, with its true normals and one radius, away from the origin.
PointCloud sphere_surfels(std::size_t count, float radius)
{
    PointCloud cloud = sample_shape(Shape::Sphere, {.count = count, .seed = 4});
    cloud.normals.resize(cloud.size());
    for (std::size_t i = 0; i < cloud.size(); ++i)
    {
        cloud.normals[i] = cloud.positions[i].normalized();
    }
    cloud.radii.assign(cloud.size(), radius);
    cloud.origin = Vec3d(250.0, -40.0, 3.0);
    return cloud;
}

/// Adds a sample at each of `anchors`, its normal pointing away from the origin: far from the
/// rest, they widen the field's box, and so the far grid's spacing.
void add_anchors(PointCloud& cloud, std::initializer_list<Vec3f> anchors)
{
    for (const Vec3f& anchor : anchors)
    {
        cloud.positions.push_back(anchor);
        cloud.normals.push_back(anchor.normalized());
        cloud.radii.push_back(cloud.radii.front());
    }
}

/// The distance from `p` to sample i, computed as the field does (relative to the origin).
double distance_to(const PointCloud& cloud, std::size_t i, const Vec3d& p)
{
    return ((p - cloud.origin) - cloud.positions[i].cast<double>()).norm();
}

double nearest_distance(const PointCloud& cloud, const Vec3d& p)
{
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < cloud.size(); ++i)
    {
        best = std::min(best, distance_to(cloud, i, p));
    }
    return best;
}

/// `count` points at distances from the sphere's centre drawn from [from, to], in random
/// directions.
std::vector<Vec3d> shell_points(const Vec3d& centre, double from, double to, int count,
                                std::uint64_t seed)
{
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> gauss;
    std::uniform_real_distribution<double> radius(from, to);
    std::vector<Vec3d> points;
    for (int i = 0; i < count; ++i)
    {
        points.push_back(centre +
                         Vec3d(gauss(rng), gauss(rng), gauss(rng)).normalized() * radius(rng));
    }
    return points;
}

constexpr std::size_t count = 8000;
const double spacing = std::sqrt(4.0 * std::numbers::pi / static_cast<double>(count));

TEST(PointFieldFar, DeepInsideIsTheNearestCornerRepresentativeWithinTheGridBound)
{
    const auto radius = static_cast<float>(2.0 * spacing);
    const PointCloud surfels = sphere_surfels(count, radius);
    // The far grid as PointField documents it: 128 nodes along the longest side of bounds(),
    // the samples' box grown by the largest radius.
    Aabb box = bounding_box(surfels.positions);
    box.min -= Vec3d::Constant(static_cast<double>(radius));
    box.max += Vec3d::Constant(static_cast<double>(radius));
    const FeatureGrid grid(surfels.positions, box, 128);
    for (const PlaneFit fit : {PlaneFit::Raw, PlaneFit::Centroid, PlaneFit::Quadric})
    {
        const PointField field(surfels, {.fit = fit});
        const double h = field.bounds().size().maxCoeff() / 127.0;
        EXPECT_NEAR(h, grid.spacing(), 1e-6 * h);
        int from_far_grid = 0;
        for (const Vec3d& p : shell_points(surfels.origin, 0.0, 0.8, 300, 1))
        {
            const FieldSample f = field.evaluate(p);
            const double d = nearest_distance(surfels, p);
            ASSERT_FALSE(f.defined);
            ASSERT_LT(f.value, 0.0);
            // The distance to an actual sample: at least the nearest, at most 2√3 h farther.
            EXPECT_GE(-f.value, d * (1.0 - 1e-12));
            EXPECT_LE(-f.value, d + 2.0 * std::sqrt(3.0) * h);
            const auto cell = grid.query(p - surfels.origin);
            ASSERT_TRUE(cell.has_value());
            double best = std::numeric_limits<double>::infinity();
            std::uint32_t nearest = 0;
            for (const std::uint32_t i : cell->points)
            {
                const double distance = distance_to(surfels, i, p);
                if (distance < best || (distance == best && i < nearest))
                {
                    best = distance;
                    nearest = i;
                }
            }
            // It is the nearest of the representatives of the 8 nodes around p, or, where the
            // point grid reaches (its cells grow with the sample spacing), the nearest sample.
            if (-f.value == best)
            {
                ++from_far_grid;
                EXPECT_NEAR((f.gradient - surfels.normals[nearest].cast<double>()).norm(), 0.0,
                            1e-6);
            }
            else
            {
                EXPECT_EQ(-f.value, d);
            }
        }
        EXPECT_GT(from_far_grid, 100) << to_string(fit);
    }
}

TEST(PointFieldFar, NoPointThatAnInfluenceBallReachesIsUndefined)
{
    // Radii of 2 sample spacings (the boundary of the union of balls lies where the point grid
    // answers) and 0.3 (beyond it: there the far grid must prove that no ball reaches).
    for (const double radius : {2.0 * spacing, 0.3})
    {
        const PointCloud surfels = sphere_surfels(count, static_cast<float>(radius));
        // Across the boundary, inside and outside.
        const double band = 2.5 * radius;
        std::vector<Vec3d> points = shell_points(surfels.origin, 1.0 - band, 1.0, 500, 2);
        const std::vector<Vec3d> outer = shell_points(surfels.origin, 1.0, 1.0 + band, 500, 3);
        points.insert(points.end(), outer.begin(), outer.end());
        for (const PlaneFit fit : {PlaneFit::Raw, PlaneFit::Quadric})
        {
            const PointField field(surfels, {.fit = fit});
            const double h = field.bounds().size().maxCoeff() / 127.0;
            int reached = 0;
            int unreached = 0;
            for (const Vec3d& p : points)
            {
                const double d = nearest_distance(surfels, p);
                const FieldSample f = field.evaluate(p);
                if (d <= static_cast<double>(surfels.radii[0]))
                {
                    ++reached;
                    EXPECT_TRUE(f.defined) << "at distance " << d << " of the samples";
                }
                else
                {
                    ++unreached;
                    EXPECT_FALSE(f.defined);
                    // Undefined values are ± the distance to a nearly nearest sample.
                    EXPECT_GE(std::abs(f.value), d * (1.0 - 1e-12));
                    EXPECT_LE(std::abs(f.value), 1.01 * d + 2.0 * std::sqrt(3.0) * h);
                    EXPECT_EQ(f.value < 0.0, (p - surfels.origin).norm() < 1.0);
                }
            }
            // Both sides of the boundary were tried.
            EXPECT_GT(reached, 250);
            EXPECT_GT(unreached, 250);
        }
    }
}

TEST(PointFieldFar, WithoutTheFarGridDeepInsideIsWithinOnePercent)
{
    // far_grid = false (what morphs ask): deep inside, the nearly nearest kd-tree search, as
    // outside.
    const PointCloud surfels = sphere_surfels(count, static_cast<float>(2.0 * spacing));
    for (const PlaneFit fit : {PlaneFit::Raw, PlaneFit::Quadric})
    {
        const PointField field(surfels, {.fit = fit, .far_grid = false});
        for (const Vec3d& p : shell_points(surfels.origin, 0.0, 0.8, 200, 5))
        {
            const FieldSample f = field.evaluate(p);
            const double d = nearest_distance(surfels, p);
            ASSERT_FALSE(f.defined);
            ASSERT_LT(f.value, 0.0);
            EXPECT_GE(-f.value, d * (1.0 - 1e-6));
            EXPECT_LE(-f.value, (fit == PlaneFit::Raw ? 1.0 + 1e-6 : 1.01) * d);
        }
    }
}

TEST(PointFieldFar, FarOutsideIsWithinOnePercentOfTheNearestDistance)
{
    const PointCloud surfels = sphere_surfels(count, static_cast<float>(2.0 * spacing));
    // Inside the field's box and beyond it.
    const std::vector<Vec3d> points = shell_points(surfels.origin, 1.1, 3.0, 400, 4);
    for (const PlaneFit fit : {PlaneFit::Raw, PlaneFit::Quadric})
    {
        const PointField field(surfels, {.fit = fit});
        for (const Vec3d& p : points)
        {
            const FieldSample f = field.evaluate(p);
            const double d = nearest_distance(surfels, p);
            ASSERT_FALSE(f.defined);
            EXPECT_GE(f.value, d * (1.0 - 1e-6));
            // Raw takes the nearest sample; the blends a nearly nearest one.
            EXPECT_LE(f.value, (fit == PlaneFit::Raw ? 1.0 + 1e-6 : 1.01) * d);
        }
    }
}

TEST(PointFieldFar, AThinWallStaysOutsideOnBothSides)
{
    // A 2 × 2 plate 0.005 thick, sampled on both faces with outward normals: every point off it
    // is outside, however far. Two samples 1 above and below make the box tall enough for the
    // far grid to cover the points tried: the box is 2.1 wide (radii 0.05) on every side, the
    // far grid's spacing h = 2.1 / 127, and the plate is centred on a layer of nodes, so both
    // faces snap to the same nodes, whose representatives face one way only: on the other
    // side they say "inside". (Within 0.45 of the plate, 1% of the distance stays below the
    // thickness, so a nearly nearest sample is on the near face.)
    PointCloud plate;
    const double thickness = 0.005;
    const double middle = -1.05 + 64.0 * (2.1 / 127.0);
    for (int side = 0; side < 2; ++side)
    {
        for (int i = 0; i <= 80; ++i)
        {
            for (int j = 0; j <= 80; ++j)
            {
                const auto z = static_cast<float>(middle + (side == 0 ? 0.5 : -0.5) * thickness);
                plate.positions.emplace_back(static_cast<float>(-1.0 + 0.025 * i),
                                             static_cast<float>(-1.0 + 0.025 * j), z);
                plate.normals.emplace_back(0.0F, 0.0F, side == 0 ? 1.0F : -1.0F);
            }
        }
    }
    plate.radii.assign(plate.size(), 0.05F);
    add_anchors(plate, {Vec3f(0.0F, 0.0F, 1.0F), Vec3f(0.0F, 0.0F, -1.0F)});
    for (const PlaneFit fit : {PlaneFit::Raw, PlaneFit::Quadric})
    {
        const PointField field(plate, {.fit = fit});
        std::mt19937_64 rng(5);
        std::uniform_real_distribution<double> xy(-0.9, 0.9);
        std::uniform_real_distribution<double> height(0.1, 0.45);
        for (int n = 0; n < 2000; ++n)
        {
            const double z = middle + (n % 2 == 0 ? height(rng) : -height(rng));
            const Vec3d p(xy(rng), xy(rng), z);
            const FieldSample f = field.evaluate(p);
            EXPECT_FALSE(f.defined);
            EXPECT_GT(f.value, 0.0) << "at " << p.transpose();
        }
    }
}

TEST(PointFieldFar, SameValuesWhateverTheThreadCountAndTheQueryOrder)
{
    // Far-grid spacing 0.063 (the box widened by two samples 4 away), so that its nodes
    // represent about 2.5 samples each and the far grid's values differ from the point grid's.
    PointCloud surfels = sphere_surfels(count, static_cast<float>(2.0 * spacing));
    add_anchors(surfels, {Vec3f(4.0F, 0.0F, 0.0F), Vec3f(-4.0F, 0.0F, 0.0F)});
    std::vector<Vec3d> points = shell_points(surfels.origin, 0.0, 2.0, 6000, 6);
    // Nearest the surface first, so that the first field answers many queries before it builds
    // its far grid (in a parallel batch), while the second builds it at once.
    std::sort(points.begin(), points.end(), [&](const Vec3d& a, const Vec3d& b) {
        return std::abs((a - surfels.origin).norm() - 1.0) <
               std::abs((b - surfels.origin).norm() - 1.0);
    });
    const PointField first(surfels);
    const PointField second(surfels);
    const int saved = thread_count();
    std::vector<FieldSample> two(points.size());
    std::vector<FieldSample> one(points.size());
    set_thread_count(2);
    reset_parallel_stats();
    first.evaluate(points, two);
    test::expect_parallel_run(2);
    set_thread_count(1);
    reset_parallel_stats();
    first.evaluate(points, one);
    test::expect_parallel_run(1);
    set_thread_count(saved);
    // The second builds it in a lone query at the deepest point.
    const auto deepest = static_cast<std::size_t>(
        std::min_element(points.begin(), points.end(),
                         [&](const Vec3d& a, const Vec3d& b) {
                             return (a - surfels.origin).norm() < (b - surfels.origin).norm();
                         }) -
        points.begin());
    ASSERT_EQ(second.evaluate(points[deepest]).value, one[deepest].value);
    int far_from_samples = 0;
    for (std::size_t n = 0; n < points.size(); ++n)
    {
        const FieldSample single = second.evaluate(points[n]);
        ASSERT_EQ(one[n].value, single.value);
        ASSERT_EQ(two[n].value, single.value);
        ASSERT_EQ(two[n].defined, single.defined);
        ASSERT_EQ(one[n].defined, single.defined);
        ASSERT_EQ(two[n].gradient, single.gradient);
        far_from_samples += single.defined ? 0 : 1;
    }
    EXPECT_GT(far_from_samples, 1000);
}

} // namespace
} // namespace pointform
