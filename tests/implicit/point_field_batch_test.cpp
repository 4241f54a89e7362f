// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// PointField's batch evaluation answers each query as evaluate() does, bit for bit, whatever the
// order of the queries, the thread count, the plane fit and whether the far grid is built yet.

#include "pointform/core/parallel.h"
#include "pointform/geometry/shapes.h"
#include "pointform/hermite/radius.h"
#include "pointform/implicit/point_field.h"
#include "pointform/spatial/kd_tree.h"
#include "pointform/spatial/spatial_sort.h"

#include "support/thread_counts.h"

#include <gtest/gtest.h>

#include <bit>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

namespace pointform {
namespace {

/// A sphere of radius 1 sampled like a scan (with a little noise), true normals and automatic
/// radii, far from the origin as georeferenced scans are.
PointCloud noisy_sphere(std::size_t count)
{
    PointCloud cloud = sample_shape(Shape::Sphere, {.count = count, .seed = 8});
    std::mt19937_64 rng(5);
    std::normal_distribution<float> noise(0.0F, 0.002F);
    cloud.normals.resize(cloud.size());
    for (std::size_t i = 0; i < cloud.size(); ++i)
    {
        cloud.normals[i] = cloud.positions[i].normalized();
        cloud.positions[i] += cloud.normals[i] * noise(rng);
    }
    const KdTree tree(cloud.positions);
    cloud.radii = influence_radii(knn_batch(tree, cloud.positions, 17), 1.5);
    cloud.origin = Vec3d(1000.0, -2000.0, 500.0);
    return cloud;
}

struct Queries
{
    std::string name;
    std::vector<Vec3d> points;
};

/// Near the surface (within `half_width`) in Morton order and at random; and spread over a
/// box three times the sphere's (deep inside, far outside and near, mixed).
std::vector<Queries> queries_around(const Vec3d& centre, double half_width)
{
    std::mt19937_64 rng(17);
    std::normal_distribution<double> gauss;
    std::uniform_real_distribution<double> shell(1.0 - half_width, 1.0 + half_width);
    std::uniform_real_distribution<double> box(-1.5, 1.5);
    std::vector<Vec3d> near(2000);
    for (Vec3d& p : near)
    {
        p = centre + Vec3d(gauss(rng), gauss(rng), gauss(rng)).normalized() * shell(rng);
    }
    std::vector<Vec3f> relative(near.size());
    for (std::size_t i = 0; i < near.size(); ++i)
    {
        relative[i] = (near[i] - centre).cast<float>();
    }
    const std::vector<std::uint32_t> order = spatial_order(relative);
    std::vector<Vec3d> coherent(near.size());
    for (std::size_t i = 0; i < order.size(); ++i)
    {
        coherent[i] = near[order[i]];
    }
    std::vector<Vec3d> mixed(1500);
    for (Vec3d& p : mixed)
    {
        p = centre + Vec3d(box(rng), box(rng), box(rng));
    }
    mixed.push_back(centre);
    mixed.push_back(centre + Vec3d(50.0, 0.0, 0.0));
    return {{"Morton order", coherent}, {"random order", near}, {"mixed", mixed}};
}

/// The batch result equals evaluate() per point, bit for bit.
void expect_batch_as_single(const PointField& field, const Queries& queries, int threads,
                            const std::string& what)
{
    const int saved = thread_count();
    set_thread_count(threads);
    reset_parallel_stats();
    std::vector<FieldSample> batch(queries.points.size());
    field.evaluate(queries.points, batch);
    test::expect_parallel_run(threads);
    set_thread_count(saved);
    std::size_t defined = 0;
    for (std::size_t i = 0; i < queries.points.size(); ++i)
    {
        const FieldSample single = field.evaluate(queries.points[i]);
        const std::string where = what + ", " + queries.name + ", " + std::to_string(threads) +
                                  " thread(s), query " + std::to_string(i);
        ASSERT_EQ(batch[i].defined, single.defined) << where;
        ASSERT_EQ(std::bit_cast<std::uint64_t>(batch[i].value),
                  std::bit_cast<std::uint64_t>(single.value))
            << where;
        for (Eigen::Index a = 0; a < 3; ++a)
        {
            ASSERT_EQ(std::bit_cast<std::uint64_t>(batch[i].gradient[a]),
                      std::bit_cast<std::uint64_t>(single.gradient[a]))
                << where;
        }
        defined += single.defined ? 1 : 0;
    }
    // Not a comparison of undefined answers only: near the surface the field is defined.
    if (queries.name != "mixed")
    {
        EXPECT_GT(defined, queries.points.size() * 9 / 10) << what << ", " << queries.name;
    }
}

struct Variant
{
    std::string name;
    PointFieldOptions options;
};

TEST(PointFieldBatch, EqualsEvaluatePerPointForEveryFitOrderAndThreadCount)
{
    const PointCloud surfels = noisy_sphere(4000);
    const std::vector<Variant> variants = {
        {"raw", {.fit = PlaneFit::Raw}},
        {"centroid", {.fit = PlaneFit::Centroid}},
        {"blend", {.fit = PlaneFit::Blend}},
        {"quadric", {.fit = PlaneFit::Quadric}},
        {"quadric, blend_k 2", {.fit = PlaneFit::Quadric, .blend_k = 2}},
        {"blend, blend_k 32", {.fit = PlaneFit::Blend, .blend_k = 32}},
        {"quadric, no far grid", {.fit = PlaneFit::Quadric, .far_grid = false}},
    };
    for (const Variant& variant : variants)
    {
        // A fresh field: its far grid is built during the first batch (by a mixed query).
        const PointField field(surfels, variant.options);
        const double cell = 0.4 * field.median_radius();
        const auto sets = queries_around(surfels.origin, cell);
        for (const int threads : {1, 3})
        {
            for (auto set = sets.rbegin(); set != sets.rend(); ++set)
            {
                expect_batch_as_single(field, *set, threads, variant.name);
            }
        }
    }
}

TEST(PointFieldBatch, EqualsEvaluatePerPointBeforeTheFarGridIsBuilt)
{
    // Only queries near the surface: the far grid is never built, and the batch answers as
    // evaluate() does all the same (half of them first, for the order).
    const PointCloud surfels = noisy_sphere(4000);
    const PointField field(surfels, {.fit = PlaneFit::Quadric});
    const auto sets = queries_around(surfels.origin, 0.4 * field.median_radius());
    expect_batch_as_single(field, sets[0], 2, "quadric, near only");
    expect_batch_as_single(field, sets[1], 1, "quadric, near only");
}

TEST(PointFieldBatch, EmptyBatchAndAFewPoints)
{
    const PointCloud surfels = noisy_sphere(500);
    const PointField field(surfels);
    std::vector<FieldSample> none;
    field.evaluate(std::span<const Vec3d>(), none);
    const std::vector<Vec3d> points = {surfels.world(0), surfels.origin, surfels.world(7)};
    std::vector<FieldSample> out(points.size());
    field.evaluate(points, out);
    for (std::size_t i = 0; i < points.size(); ++i)
    {
        const FieldSample single = field.evaluate(points[i]);
        EXPECT_EQ(out[i].value, single.value);
        EXPECT_EQ(out[i].gradient, single.gradient);
        EXPECT_EQ(out[i].defined, single.defined);
    }
    // On a sample, the field is about zero (noise of 0.2% of the radius).
    EXPECT_LT(std::abs(out[0].value), 0.01);
    EXPECT_LT(out[1].value, -0.5); // the centre is deep inside
}

} // namespace
} // namespace pointform
