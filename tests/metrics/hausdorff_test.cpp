// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// Distances and their statistics against analytic truth: offsets from a sphere mesh and a
// plane, a cube against its translate, a mesh against itself; determinism and bad input.

#include "pointform/metrics/hausdorff.h"

#include "pointform/core/error.h"
#include "pointform/core/parallel.h"
#include "pointform/io/io.h"
#include "pointform/metrics/surface_sampling.h"

#include "support/test_meshes.h"
#include "support/test_support.h"
#include "support/thread_counts.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

namespace pointform {
namespace {

Vec3d random_direction(std::mt19937_64& rng)
{
    std::normal_distribution<double> normal;
    Vec3d d(normal(rng), normal(rng), normal(rng));
    return d.normalized();
}

/// Largest gap between an inscribed mesh and its sphere: R minus the smallest distance from the
/// centre to a face's plane (all vertices lie on the sphere).
double inscribed_gap(const TriMesh& mesh, double radius)
{
    double nearest_plane = radius;
    for (const auto& t : mesh.triangles)
    {
        const Vec3d a = mesh.vertices.positions[t[0]].cast<double>();
        const Vec3d b = mesh.vertices.positions[t[1]].cast<double>();
        const Vec3d c = mesh.vertices.positions[t[2]].cast<double>();
        const Vec3d n = (b - a).cross(c - a).normalized();
        nearest_plane = std::min(nearest_plane, std::abs(n.dot(a)));
    }
    return radius - nearest_plane;
}

TEST(Distances, PointsAtKnownOffsetsFromASphereMesh)
{
    const double radius = 1.5;
    const Vec3d centre(0.25, -3.0, 7.0);
    const TriMesh sphere = test::icosphere(4, centre, radius);
    const double gap = inscribed_gap(sphere, radius);
    ASSERT_LT(gap, 0.01 * radius);
    const double eps = 1e-6 * radius; // float storage of vertices and queries

    std::mt19937_64 rng(12);
    for (const double offset : {0.3, 0.05, 0.01, -0.2})
    {
        PointCloud points;
        points.origin = centre;
        for (int i = 0; i < 500; ++i)
            points.positions.push_back(((radius + offset) * random_direction(rng)).cast<float>());
        const auto distances = distances_to_mesh(points, sphere);
        ASSERT_EQ(distances.size(), points.size());
        for (const double d : distances)
        {
            // The mesh lies inside the sphere, within `gap` of it.
            if (offset > 0.0)
            {
                EXPECT_GE(d, offset - eps);
                EXPECT_LE(d, offset + gap + eps);
            }
            else
            {
                EXPECT_GE(d, -offset - gap - eps);
                EXPECT_LE(d, -offset + eps);
            }
        }
    }
}

TEST(Distances, PointsAtKnownOffsetsFromAPlane)
{
    const TriMesh plane = test::square_grid(16);
    std::mt19937_64 rng(4);
    std::uniform_real_distribution<float> uni(-1.0F, 1.0F);
    PointCloud points;
    std::vector<double> truth;
    for (int i = 0; i < 2000; ++i)
    {
        const Vec3f p(1.5F * uni(rng), 1.5F * uni(rng), uni(rng));
        points.positions.push_back(p);
        const double dx = std::max(std::abs(static_cast<double>(p.x())) - 1.0, 0.0);
        const double dy = std::max(std::abs(static_cast<double>(p.y())) - 1.0, 0.0);
        const double dz = p.z();
        truth.push_back(std::sqrt(dx * dx + dy * dy + dz * dz));
    }
    const auto distances = distances_to_mesh(points, plane);
    for (std::size_t i = 0; i < truth.size(); ++i)
        EXPECT_NEAR(distances[i], truth[i], 1e-12);
}

TEST(Distances, PointToPointMatchesBruteForceAcrossOrigins)
{
    std::mt19937_64 rng(9);
    std::uniform_real_distribution<float> uni(-1.0F, 1.0F);
    PointCloud points;
    PointCloud targets;
    points.origin = Vec3d(1000.0, 2000.0, -50.0);
    targets.origin = Vec3d(1000.5, 1999.0, -50.0);
    for (int i = 0; i < 800; ++i)
        points.positions.emplace_back(uni(rng), uni(rng), uni(rng));
    for (int i = 0; i < 600; ++i)
        targets.positions.emplace_back(uni(rng), uni(rng), uni(rng));
    const auto distances = distances_to_points(points, targets);
    for (std::size_t i = 0; i < points.size(); ++i)
    {
        double best = std::numeric_limits<double>::infinity();
        for (std::size_t j = 0; j < targets.size(); ++j)
            best = std::min(best, (points.world(i) - targets.world(j)).norm());
        EXPECT_NEAR(distances[i], best, 1e-6);
    }
}

TEST(DistanceStats, DefinitionsOnASmallSet)
{
    const std::vector<double> d = {4.0, 0.0, 3.0, 1.0, 2.0};
    const DistanceStats s = summarize_distances(d);
    EXPECT_EQ(s.count, 5U);
    EXPECT_EQ(s.min, 0.0);
    EXPECT_EQ(s.max, 4.0);
    EXPECT_DOUBLE_EQ(s.mean, 2.0);
    EXPECT_DOUBLE_EQ(s.rms, std::sqrt((16.0 + 9.0 + 1.0 + 4.0) / 5.0));
    EXPECT_DOUBLE_EQ(s.p50, 2.0);
    EXPECT_DOUBLE_EQ(s.p90, 3.6); // rank 0.9 * 4 = 3.6 between 3 and 4
    EXPECT_DOUBLE_EQ(s.p99, 3.96);
    const DistanceStats half = scaled(s, 0.5);
    EXPECT_DOUBLE_EQ(half.max, 2.0);
    EXPECT_EQ(half.count, 5U);

    EXPECT_THROW((void)summarize_distances({}), InvalidInput);
    const std::vector<double> nan = {1.0, std::numeric_limits<double>::quiet_NaN()};
    EXPECT_THROW((void)summarize_distances(nan), InvalidInput);
}

TEST(Compare, MeshAgainstItselfIsZero)
{
    const TriMesh bunny = read_mesh(test::data_path("meshes/bunny_uniform.off"));
    const DistanceComparison c = compare(bunny, bunny, {.samples = 10000});
    EXPECT_GT(c.diagonal, 0.0);
    EXPECT_LT(c.relative.hausdorff, 1e-6);
    EXPECT_LT(c.relative.chamfer, 1e-7);
    EXPECT_EQ(c.absolute.a_to_b.count, 10000U + bunny.vertex_count());
    EXPECT_EQ(c.absolute.symmetric.count, 2 * (10000U + bunny.vertex_count()));

    PointCloud cloud = bunny.vertices;
    TriMesh points;
    points.vertices = cloud;
    const DistanceComparison p = compare(points, points);
    EXPECT_EQ(p.absolute.hausdorff, 0.0);
    EXPECT_EQ(p.absolute.chamfer, 0.0);
}

TEST(Compare, UnitCubeAgainstItsTranslate)
{
    // A = [0,1]³, B = A + (t, 0, 0). From A: the face x = 0 (area 1) is at distance t; the face
    // x = 1 lies inside B, at min(t, y, 1-y, z, 1-z) from B's surface; the strips x < t of the
    // four side faces (area 4t) are at t - x; the rest lies on B's faces (0). Area-weighted:
    //   mean = (t + 2t² + (1 - (1-2t)³)/6) / 6,  mean of squares = (2t² - 4t³/3 + 2t⁴) / 6,
    // max = t, more than a sixth of the area is at exactly t (so p90 = p99 = t), and less than
    // half is at a positive distance (p50 = 0). B → A is the mirror image.
    const double t = 0.125;
    const TriMesh a = test::box_mesh(Vec3d(0, 0, 0), Vec3d(1, 1, 1));
    const TriMesh b = test::box_mesh(Vec3d(t, 0, 0), Vec3d(1 + t, 1, 1));
    constexpr std::size_t n = 30000;
    const DistanceComparison c = compare(a, b, {.samples = n, .seed = 7});

    const double mean = (t + 2 * t * t + (1 - std::pow(1 - 2 * t, 3)) / 6.0) / 6.0;
    const double mean2 = (2 * t * t - 4 * t * t * t / 3.0 + 2 * std::pow(t, 4)) / 6.0;
    const double sigma = std::sqrt((mean2 - mean * mean) / n);
    for (const DistanceStats& s : {c.absolute.a_to_b, c.absolute.b_to_a})
    {
        EXPECT_NEAR(s.max, t, 1e-9);
        EXPECT_NEAR(s.mean, mean, 5 * sigma);
        EXPECT_NEAR(s.rms * s.rms, mean2, 0.05 * mean2);
        EXPECT_NEAR(s.p50, 0.0, 1e-9);
        EXPECT_NEAR(s.p90, t, 1e-9);
        EXPECT_NEAR(s.p99, t, 1e-9);
        EXPECT_NEAR(s.min, 0.0, 1e-9);
    }
    EXPECT_NEAR(c.absolute.hausdorff, t, 1e-9);
    EXPECT_NEAR(c.absolute.chamfer, 2 * mean, 10 * sigma);
    EXPECT_EQ(c.absolute.chamfer, c.absolute.a_to_b.mean + c.absolute.b_to_a.mean);
    EXPECT_EQ(c.absolute.symmetric.max, c.absolute.hausdorff);
    const double diagonal = std::sqrt((1 + t) * (1 + t) + 2.0);
    EXPECT_NEAR(c.diagonal, diagonal, 1e-12);
    EXPECT_NEAR(c.relative.hausdorff, t / diagonal, 1e-9);
    EXPECT_NEAR(c.relative.a_to_b.p90, t / diagonal, 1e-9);
}

TEST(Compare, PointSetAgainstMesh)
{
    // Samples of a unit sphere against an inscribed icosphere: every sample lies within the gap.
    const TriMesh sphere = test::icosphere(4);
    const double gap = inscribed_gap(sphere, 1.0);
    TriMesh points;
    std::mt19937_64 rng(2);
    for (int i = 0; i < 3000; ++i)
        points.vertices.positions.push_back(random_direction(rng).cast<float>());
    const DistanceComparison c = compare(points, sphere, {.samples = 3000});
    EXPECT_LE(c.absolute.a_to_b.max, gap + 1e-6);
    EXPECT_GE(c.absolute.a_to_b.mean, 0.0);
    // Mesh samples to the point set: bounded by the sampling density of the points.
    EXPECT_LT(c.absolute.b_to_a.max, 0.15);
    EXPECT_EQ(c.absolute.a_to_b.count, 3000U);
}

TEST(Compare, SameResultWhateverTheThreadCount)
{
    const TriMesh bunny = read_mesh(test::data_path("meshes/bunny_uniform.off"));
    const TriMesh sphere = test::icosphere(3, bunny.vertices.bounds().center(), 0.06);
    const CompareOptions options{.samples = 3000, .seed = 3};
    const auto runs = test::at_thread_counts([&] { return compare(bunny, sphere, options); });
    const DistanceComparison& one = runs[0];
    for (std::size_t i = 1; i < runs.size(); ++i)
    {
        const DistanceComparison& other = runs[i];
        for (const auto& [x, y] : {std::pair{one.absolute.a_to_b, other.absolute.a_to_b},
                                   std::pair{one.absolute.b_to_a, other.absolute.b_to_a},
                                   std::pair{one.absolute.symmetric, other.absolute.symmetric}})
        {
            EXPECT_EQ(x.max, y.max) << i + 1 << " threads";
            EXPECT_EQ(x.mean, y.mean) << i + 1 << " threads";
            EXPECT_EQ(x.rms, y.rms) << i + 1 << " threads";
            EXPECT_EQ(x.p50, y.p50) << i + 1 << " threads";
            EXPECT_EQ(x.p99, y.p99) << i + 1 << " threads";
        }
    }
    const PointCloud samples = sample_surface(bunny, {.count = 3000});
    const auto distances =
        test::at_thread_counts([&] { return distances_to_mesh(samples, sphere); });
    EXPECT_TRUE(distances[0] == distances[1]);
    EXPECT_TRUE(distances[0] == distances[2]);
}

/// The rectangle [0, 1] × [0, height] in the plane z = 0, two triangles.
TriMesh rectangle(float height)
{
    TriMesh mesh;
    mesh.vertices.positions = {Vec3f(0, 0, 0), Vec3f(1, 0, 0), Vec3f(1, height, 0),
                               Vec3f(0, height, 0)};
    mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
    return mesh;
}

TEST(Compare, FScoreOfAHalfCoveredSquare)
{
    // A: the unit square; B: its lower half. Every sample of B lies on A (precision 1); a sample
    // of A at height y is max(0, y - 1/2) from B, so the share within τ (recall) is 1/2 + τ for
    // τ < 1/2, with binomial noise of the sampling.
    const TriMesh a = rectangle(1.0F);
    const TriMesh b = rectangle(0.5F);
    const std::size_t samples = 40000;
    const DistanceComparison result =
        compare(a, b, {.samples = samples, .fscore_thresholds = {0.05, 0.2}});
    ASSERT_EQ(result.fscores.size(), 2U);
    const double diagonal = std::sqrt(2.0);
    EXPECT_NEAR(result.diagonal, diagonal, 1e-9);
    for (const FScore& score : result.fscores)
    {
        const double tau = score.threshold * diagonal;
        EXPECT_DOUBLE_EQ(score.absolute_threshold, tau);
        const double recall = 0.5 + tau;
        const double tolerance = 4.0 * std::sqrt(recall * (1.0 - recall) / samples) + 1e-3;
        EXPECT_DOUBLE_EQ(score.precision, 1.0);
        EXPECT_NEAR(score.recall, recall, tolerance);
        EXPECT_NEAR(score.f, 2.0 * recall / (1.0 + recall), tolerance);
    }
    // Swapping the roles swaps precision and recall.
    const DistanceComparison swapped =
        compare(b, a, {.samples = samples, .fscore_thresholds = {0.05}});
    EXPECT_DOUBLE_EQ(swapped.fscores[0].recall, 1.0);
    EXPECT_NEAR(swapped.fscores[0].precision, 0.5 + 0.05 * diagonal, 0.01);
    EXPECT_THROW((void)compare(a, b, {.fscore_thresholds = {0.0}}), InvalidInput);
    EXPECT_THROW((void)compare(a, b, {.fscore_thresholds = {std::nan("")}}), InvalidInput);
}

TEST(Compare, FScoreSharesAreOfAreaNotOfVertices)
{
    // A: the unit square. B: the unit square (two triangles) and, 1 above it, a square of a
    // tenth of the area cut into 20000 triangles. Precision is B's share of area within τ of A,
    // 1 / 1.1, however many vertices the far square has (counted with the area samples, its
    // 10201 vertices would pull it to about 0.75).
    const TriMesh a = rectangle(1.0F);
    TriMesh b = rectangle(1.0F);
    const int n = 100;
    const float side = std::sqrt(0.1F);
    const auto first = static_cast<std::uint32_t>(b.vertex_count());
    for (int y = 0; y <= n; ++y)
        for (int x = 0; x <= n; ++x)
            b.vertices.positions.emplace_back(side * static_cast<float>(x) / n,
                                              side * static_cast<float>(y) / n, 1.0F);
    const auto id = [first](int x, int y) {
        return first + static_cast<std::uint32_t>(y * (n + 1) + x);
    };
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x)
        {
            b.triangles.push_back({id(x, y), id(x + 1, y), id(x + 1, y + 1)});
            b.triangles.push_back({id(x, y), id(x + 1, y + 1), id(x, y + 1)});
        }
    const std::size_t samples = 40000;
    const DistanceComparison result =
        compare(a, b, {.samples = samples, .fscore_thresholds = {0.05}});
    const double precision = 1.0 / 1.1;
    EXPECT_NEAR(result.fscores[0].precision, precision,
                4.0 * std::sqrt(precision * (1.0 - precision) / samples));
    EXPECT_DOUBLE_EQ(result.fscores[0].recall, 1.0);
    // The maxima still see the vertices: the far square's corners are 1 from A at least.
    EXPECT_GE(result.absolute.b_to_a.max, 1.0);
}

TEST(Compare, BadInputIsRejected)
{
    const TriMesh cube = test::box_mesh(Vec3d(0, 0, 0), Vec3d(1, 1, 1));
    const TriMesh empty;
    EXPECT_THROW((void)compare(empty, cube), InvalidInput);
    EXPECT_THROW((void)compare(cube, empty), InvalidInput);
    EXPECT_THROW((void)compare(cube, cube, {.samples = 0, .include_vertices = false}),
                 InvalidInput);
    TriMesh nan_points;
    nan_points.vertices.positions = {Vec3f(0, 0, 0),
                                     Vec3f(std::numeric_limits<float>::quiet_NaN(), 0, 0)};
    EXPECT_THROW((void)compare(nan_points, cube), InvalidInput);
    EXPECT_THROW((void)distances_to_points(cube.vertices, PointCloud{}), InvalidInput);
    TriMesh no_faces = cube;
    no_faces.triangles.clear();
    EXPECT_THROW((void)distances_to_mesh(cube.vertices, no_faces), InvalidInput);
}

} // namespace
} // namespace pointform
