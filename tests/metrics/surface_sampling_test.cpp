// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// Area-uniform sampling: proportional to area, uniform inside a triangle, on the surface,
// deterministic whatever the thread count, and bad input rejected.

#include "pointform/metrics/surface_sampling.h"

#include "pointform/core/error.h"
#include "pointform/core/parallel.h"
#include "pointform/spatial/triangle_bvh.h"

#include "support/test_meshes.h"
#include "support/thread_counts.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <limits>

namespace pointform {
namespace {

/// Two disjoint triangles in z = 0 with areas 1 and 3.
TriMesh two_triangles()
{
    TriMesh mesh;
    mesh.vertices.positions = {Vec3f(0, 0, 0), Vec3f(1, 0, 0), Vec3f(0, 2, 0),
                               Vec3f(5, 0, 0), Vec3f(8, 0, 0), Vec3f(5, 2, 0)};
    mesh.triangles = {{0, 1, 2}, {3, 4, 5}};
    return mesh;
}

TEST(SurfaceSampling, ProportionalToAreaAndUniformInsideATriangle)
{
    const TriMesh mesh = two_triangles();
    EXPECT_DOUBLE_EQ(surface_area(mesh), 4.0);
    constexpr std::size_t n = 40000;
    const PointCloud samples = sample_surface(mesh, {.count = n, .seed = 17});
    ASSERT_EQ(samples.size(), n);

    // Counts per triangle: binomial with p = 1/4; allow 4.5 standard deviations.
    std::size_t small = 0;
    // Inside the large triangle: the four midpoint sub-triangles have equal areas.
    std::array<double, 4> quarters{};
    for (std::size_t i = 0; i < n; ++i)
    {
        const Vec3d p = samples.world(i);
        EXPECT_EQ(p.z(), 0.0);
        if (p.x() < 2.5)
        {
            ++small;
            continue;
        }
        // Barycentric weights of b = (8, 0) and c = (5, 2) relative to a = (5, 0).
        const double v = (p.x() - 5.0) / 3.0;
        const double w = p.y() / 2.0;
        const double u = 1.0 - v - w;
        ASSERT_GE(std::min({u, v, w}), -1e-6);
        const int quarter = u > 0.5 ? 0 : (v > 0.5 ? 1 : (w > 0.5 ? 2 : 3));
        quarters[static_cast<std::size_t>(quarter)] += 1.0;
    }
    const double expected_small = n / 4.0;
    const double sigma = std::sqrt(n * 0.25 * 0.75);
    EXPECT_LT(std::abs(static_cast<double>(small) - expected_small), 4.5 * sigma);

    const double large = static_cast<double>(n - small);
    double chi2 = 0.0;
    for (const double count : quarters)
        chi2 += (count - large / 4.0) * (count - large / 4.0) / (large / 4.0);
    EXPECT_LT(chi2, 16.27); // chi-square, 3 degrees of freedom, p = 0.001
}

TEST(SurfaceSampling, SamplesLieOnTheSurface)
{
    const TriMesh sphere = test::icosphere(3, Vec3d(10.0, -4.0, 2.5), 2.0);
    const PointCloud samples = sample_surface(sphere, {.count = 5000, .seed = 3});
    const TriangleBvh bvh(sphere);
    for (std::size_t i = 0; i < samples.size(); ++i)
        EXPECT_LT(bvh.distance(samples.world(i)), 1e-6 * 2.0); // float rounding of positions
}

TEST(SurfaceSampling, VerticesAreAppendedWhenAsked)
{
    TriMesh mesh = two_triangles();
    mesh.vertices.positions.emplace_back(100.0F, 100.0F, 100.0F); // used by no triangle
    const PointCloud samples =
        sample_surface(mesh, {.count = 100, .seed = 5, .include_vertices = true});
    ASSERT_EQ(samples.size(), 100U + 6U);
    for (std::size_t v = 0; v < 6; ++v)
        EXPECT_EQ(samples.positions[100 + v], mesh.vertices.positions[v]);
    const PointCloud only_vertices = sample_surface(mesh, {.count = 0, .include_vertices = true});
    EXPECT_EQ(only_vertices.size(), 6U);
}

TEST(SurfaceSampling, NormalsOfTheTrianglesAndAreaWeightedAtVertices)
{
    // An icosphere (outward triangles): every random sample's normal is its triangle's, within
    // the angle a facet makes with the radius; every vertex normal is the area-weighted mean,
    // close to the radius there. The positions are those sampled without normals.
    const TriMesh sphere = test::icosphere(3);
    const SurfaceSamplingOptions plain{.count = 2000, .seed = 9, .include_vertices = true};
    SurfaceSamplingOptions with_normals = plain;
    with_normals.normals = true;
    const PointCloud samples = sample_surface(sphere, with_normals);
    ASSERT_EQ(samples.normals.size(), samples.size());
    EXPECT_EQ(samples.positions, sample_surface(sphere, plain).positions);
    for (std::size_t i = 0; i < samples.size(); ++i)
    {
        const Vec3d n = samples.normals[i].cast<double>();
        const Vec3d radial = samples.positions[i].cast<double>().normalized();
        EXPECT_NEAR(n.norm(), 1.0, 1e-6);
        // Facets of a level-3 icosphere span about 4.6°; vertex normals are within a degree.
        EXPECT_GT(n.dot(radial), i < 2000 ? std::cos(0.1) : std::cos(0.02)) << i;
    }
}

TEST(SurfaceSampling, ZeroAreaTrianglesGetNoSamples)
{
    TriMesh mesh = two_triangles();
    mesh.vertices.positions.emplace_back(50.0F, 0.0F, 0.0F);
    mesh.vertices.positions.emplace_back(60.0F, 0.0F, 0.0F);
    // Zero-area triangles first, between and last.
    mesh.triangles = {{6, 7, 6}, mesh.triangles[0], {7, 7, 7}, mesh.triangles[1], {6, 6, 7}};
    const PointCloud samples = sample_surface(mesh, {.count = 5000, .seed = 8});
    for (std::size_t i = 0; i < samples.size(); ++i)
        EXPECT_LT(samples.world(i).x(), 10.0);
}

TEST(SurfaceSampling, SameSamplesWhateverTheThreadCount)
{
    const TriMesh sphere = test::icosphere(3);
    const SurfaceSamplingOptions options{.count = 30000, .seed = 42};
    const auto runs = test::at_thread_counts([&] { return sample_surface(sphere, options); });
    const PointCloud& one = runs[0];
    for (std::size_t i = 1; i < runs.size(); ++i)
    {
        ASSERT_EQ(one.size(), runs[i].size());
        EXPECT_TRUE(one.positions == runs[i].positions) << i + 1 << " threads";
    }
    const PointCloud other = sample_surface(sphere, {.count = 30000, .seed = 43});
    EXPECT_FALSE(one.positions == other.positions);
}

TEST(SurfaceSampling, BadInputIsRejected)
{
    TriMesh no_faces;
    no_faces.vertices.positions = {Vec3f(0, 0, 0)};
    EXPECT_THROW((void)sample_surface(no_faces), InvalidInput);

    TriMesh flat;
    flat.vertices.positions = {Vec3f(0, 0, 0), Vec3f(1, 0, 0), Vec3f(2, 0, 0)};
    flat.triangles = {{0, 1, 2}};
    EXPECT_THROW((void)sample_surface(flat), InvalidInput);

    TriMesh bad_index = two_triangles();
    bad_index.triangles.push_back({0, 1, 9});
    EXPECT_THROW((void)sample_surface(bad_index), InvalidInput);

    TriMesh nan = two_triangles();
    nan.vertices.positions[2].y() = std::numeric_limits<float>::quiet_NaN();
    EXPECT_THROW((void)sample_surface(nan), InvalidInput);
}

} // namespace
} // namespace pointform
