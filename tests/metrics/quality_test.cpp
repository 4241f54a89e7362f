// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/metrics/quality.h"

#include "pointform/core/error.h"
#include "pointform/metrics/sampling_density.h"
#include "pointform/spatial/kd_tree.h"

#include "support/test_meshes.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

namespace pointform {
namespace {

constexpr double degrees = std::numbers::pi / 180.0;

TEST(Quality, TriangleMinAngleOfKnownTriangles)
{
    // Equilateral: 60°; right isosceles: 45°; 3-4-5: atan(3/4).
    EXPECT_NEAR(triangle_min_angle({0, 0, 0}, {1, 0, 0}, {0.5, std::sqrt(3.0) / 2, 0}),
                60.0 * degrees, 1e-12);
    EXPECT_NEAR(triangle_min_angle({0, 0, 0}, {1, 0, 0}, {0, 1, 0}), 45.0 * degrees, 1e-12);
    EXPECT_NEAR(triangle_min_angle({0, 0, 0}, {4, 0, 0}, {4, 3, 0}), std::atan(3.0 / 4.0), 1e-12);
    // A needle keeps its tiny angle accurate (atan2, not acos).
    EXPECT_NEAR(triangle_min_angle({0, 0, 0}, {1, 0, 0}, {0.5, 1e-9, 0}), 2e-9, 1e-15);
    EXPECT_EQ(triangle_min_angle({0, 0, 0}, {0, 0, 0}, {1, 0, 0}), 0.0);
}

TEST(Quality, TriangleMinAngleIsTheSmallestOfTheThree)
{
    // Random triangles, obtuse, needles and caps among them: the angle opposite the shortest
    // side, against all three angles by the law of cosines.
    std::mt19937 random(5);
    std::uniform_real_distribution<double> coordinate(-1.0, 1.0);
    const auto angle_at = [](const Vec3d& p, const Vec3d& q, const Vec3d& r) {
        const Vec3d u = q - p;
        const Vec3d v = r - p;
        return std::acos(std::clamp(u.dot(v) / (u.norm() * v.norm()), -1.0, 1.0));
    };
    for (int trial = 0; trial < 2000; ++trial)
    {
        const Vec3d a(coordinate(random), coordinate(random), coordinate(random));
        const Vec3d b(coordinate(random), coordinate(random), coordinate(random));
        // Every fifth triangle nearly flat: c close to the segment ab.
        const double squash = trial % 5 == 0 ? 1e-3 : 1.0;
        const Vec3d c = 0.5 * (a + b) +
                        squash * Vec3d(coordinate(random), coordinate(random), coordinate(random));
        const double expected = std::min({angle_at(a, b, c), angle_at(b, c, a), angle_at(c, a, b)});
        EXPECT_NEAR(triangle_min_angle(a, b, c), expected, 1e-9) << trial;
        EXPECT_EQ(triangle_min_angle(a, b, c), triangle_min_angle(b, c, a)) << trial;
    }
}

TEST(Quality, AngleQualityOfAGridAndItsBoundary)
{
    // A 4 × 4 square grid split into right isosceles triangles: every smallest angle is 45°.
    const TriMesh grid = test::square_grid(4);
    const AngleQuality q = angle_quality(grid);
    EXPECT_EQ(q.faces, grid.face_count());
    EXPECT_NEAR(q.min_degrees, 45.0, 1e-9);
    EXPECT_NEAR(q.mean_min_degrees, 45.0, 1e-9);
    EXPECT_EQ(q.sliver_share, 0.0);
    EXPECT_EQ(angle_quality(grid, 50.0).sliver_share, 1.0);
    // Interior faces: those with no vertex on the outer ring of the grid.
    EXPECT_GT(q.interior_faces, 0U);
    EXPECT_LT(q.interior_faces, q.faces);
}

TEST(Quality, SliversAreCountedAwayFromTheBoundary)
{
    // A closed mesh (no boundary): every face is interior; flatten one vertex's neighbourhood
    // into slivers by squashing the icosphere along z.
    TriMesh sphere = test::icosphere(2);
    const AngleQuality round = angle_quality(sphere);
    EXPECT_EQ(round.interior_faces, round.faces);
    EXPECT_GT(round.min_degrees, 40.0);
    for (auto& p : sphere.vertices.positions)
        p.z() *= 0.05F;
    const AngleQuality flat = angle_quality(sphere);
    EXPECT_LT(flat.min_degrees, 20.0);
    EXPECT_GT(flat.sliver_share, 0.0);
    EXPECT_EQ(flat.interior_sliver_share, flat.sliver_share);
    TriMesh bad = sphere;
    bad.triangles[0][0] = 100000;
    EXPECT_THROW((void)angle_quality(bad), InvalidInput);
}

TEST(SamplingDensity, RegularGridSpacingAndDuplicates)
{
    // A 20 × 20 grid of spacing 0.5: every nearest distinct neighbour is at 0.5.
    PointCloud grid;
    for (int i = 0; i < 20; ++i)
        for (int j = 0; j < 20; ++j)
            grid.positions.emplace_back(0.5F * static_cast<float>(i), 0.5F * static_cast<float>(j),
                                        0.0F);
    const SamplingDensity d = measure_sampling_density(grid);
    EXPECT_FLOAT_EQ(d.median, 0.5);
    EXPECT_FLOAT_EQ(d.mean, 0.5);
    EXPECT_EQ(d.measured, grid.size());
    EXPECT_EQ(estimate_sampling_density(grid), d.median);
    // Every point doubled: duplicates are skipped, the density stays the spacing.
    PointCloud doubled = grid;
    doubled.positions.insert(doubled.positions.end(), grid.positions.begin(), grid.positions.end());
    EXPECT_FLOAT_EQ(measure_sampling_density(doubled).median, 0.5);
    EXPECT_FLOAT_EQ(measure_sampling_density(doubled).mean, 0.5);

    PointCloud same;
    same.positions.assign(10, Vec3f(1.0F, 2.0F, 3.0F));
    EXPECT_THROW((void)measure_sampling_density(same), InvalidInput);
    EXPECT_THROW((void)measure_sampling_density(PointCloud{}), InvalidInput);
}

TEST(SamplingDensity, LargeCloudsAreMeasuredOnAFixedStride)
{
    // 250k points on a line at spacing 0.01: a stride of 2 measures 125k of them, all 0.01.
    PointCloud line;
    for (int i = 0; i < 250000; ++i)
        line.positions.emplace_back(0.01F * static_cast<float>(i % 500),
                                    0.01F * static_cast<float>(i / 500), 0.0F);
    const SamplingDensity d = measure_sampling_density(line);
    EXPECT_EQ(d.measured, 125000U);
    EXPECT_NEAR(d.median, 0.01, 1e-5);
}

TEST(SamplingDensity, ACallersTreeGivesTheSameFigures)
{
    // Samples of a unit sphere at random: with the caller's tree of the same positions, every
    // figure is the one the function's own tree gives, bit for bit.
    std::mt19937 rng(7);
    std::normal_distribution<float> normal;
    PointCloud sphere;
    for (int i = 0; i < 3000; ++i)
    {
        const Vec3f p(normal(rng), normal(rng), normal(rng));
        sphere.positions.push_back(p.normalized());
    }
    const SamplingDensity own = measure_sampling_density(sphere);
    const KdTree tree(sphere.positions);
    const SamplingDensity given = measure_sampling_density(tree, sphere);
    EXPECT_EQ(given.median, own.median);
    EXPECT_EQ(given.mean, own.mean);
    EXPECT_EQ(given.measured, own.measured);
    // About the spacing of 3000 points on the sphere's area 4π.
    EXPECT_GT(own.median, 0.2 * std::sqrt(4.0 * std::numbers::pi / 3000.0));
    EXPECT_LT(own.median, 2.0 * std::sqrt(4.0 * std::numbers::pi / 3000.0));
    // A tree of other points is refused.
    PointCloud fewer = sphere;
    fewer.positions.resize(100);
    EXPECT_THROW((void)measure_sampling_density(tree, fewer), InvalidInput);
}

} // namespace
} // namespace pointform
