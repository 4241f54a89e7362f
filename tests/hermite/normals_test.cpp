// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/hermite/normals.h"

#include "pointform/core/error.h"
#include "pointform/core/parallel.h"
#include "pointform/geometry/shapes.h"

#include "support/test_support.h"
#include "support/thread_counts.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>

namespace pointform {
namespace {

TEST(FitPlane, RecoversTiltedPlaneExactly)
{
    // Points on the plane through (1, 2, 3) with normal (1, 1, 1)/√3, far from the origin.
    const Vec3d n = Vec3d(1.0, 1.0, 1.0).normalized();
    const Vec3d u = n.unitOrthogonal();
    const Vec3d v = n.cross(u);
    std::vector<Vec3f> points;
    std::vector<std::uint32_t> indices;
    for (int a = -2; a <= 2; ++a)
        for (int b = -2; b <= 2; ++b)
        {
            indices.push_back(static_cast<std::uint32_t>(points.size()));
            points.push_back((Vec3d(1.0, 2.0, 3.0) + 0.1 * a * u + 0.07 * b * v).cast<float>());
        }
    const LocalPlane fit = fit_plane(points, indices);
    EXPECT_FALSE(fit.degenerate);
    EXPECT_NEAR(std::abs(fit.normal.dot(n)), 1.0, 1e-6);
    EXPECT_NEAR((fit.centroid - Vec3d(1.0, 2.0, 3.0)).norm(), 0.0, 1e-6);
    EXPECT_LT(fit.variation(), 1e-10);
}

TEST(FitPlane, FlagsCollinearAndCoincidentPoints)
{
    const std::vector<Vec3f> line = {Vec3f(0, 0, 0), Vec3f(1, 1, 1), Vec3f(2, 2, 2),
                                     Vec3f(3, 3, 3)};
    const std::array<std::uint32_t, 4> all = {0, 1, 2, 3};
    EXPECT_TRUE(fit_plane(line, all).degenerate);
    EXPECT_EQ(fit_plane(line, all).normal, Vec3d::Zero());

    const std::vector<Vec3f> same(4, Vec3f(0.5F, 0.5F, 0.5F));
    EXPECT_TRUE(fit_plane(same, all).degenerate);
}

TEST(EstimateNormals, SphereNormalsAreRadial)
{
    const PointCloud sphere = sample_shape(Shape::Sphere, {.count = 20000, .seed = 2});
    const Normals normals = estimate_normals(sphere.positions, {.k = 16});
    ASSERT_EQ(normals.normals.size(), sphere.size());
    EXPECT_TRUE(normals.degenerate.empty());
    // Sampling step h ≈ sqrt(4π/N) ≈ 0.025 on a unit sphere: the fit's tilt is O(h), a degree or
    // so.
    EXPECT_LT(test::line_angle_quantile_deg(normals.normals, sphere.normals, 0.5), 1.0);
    EXPECT_LT(test::line_angle_quantile_deg(normals.normals, sphere.normals, 1.0), 5.0);
    for (const auto& n : normals.normals)
        EXPECT_NEAR(n.norm(), 1.0F, 1e-5F);
}

TEST(EstimateNormals, TorusNormalsWithNoise)
{
    const PointCloud torus =
        sample_shape(Shape::Torus, {.count = 50000, .seed = 3, .noise = 0.001});
    const Normals normals = estimate_normals(torus.positions, {.k = 24});
    EXPECT_LT(test::line_angle_quantile_deg(normals.normals, torus.normals, 0.5), 8.0);
    EXPECT_LT(test::line_angle_quantile_deg(normals.normals, torus.normals, 0.9), 20.0);
}

TEST(EstimateNormals, SameResultForOneAndTwoThreads)
{
    const PointCloud torus = sample_shape(Shape::Torus, {.count = 20000, .seed = 4});
    const auto runs =
        test::at_thread_counts([&] { return estimate_normals(torus.positions, {.k = 12}); });
    EXPECT_EQ(runs[0].normals, runs[1].normals);
    EXPECT_EQ(runs[0].normals, runs[2].normals);
}

TEST(EstimateNormals, RejectsTooFewPointsAndTinyK)
{
    const PointCloud sphere = sample_shape(Shape::Sphere, {.count = 10});
    EXPECT_THROW((void)estimate_normals(sphere.positions, {.k = 16}), InvalidInput);
    EXPECT_THROW((void)estimate_normals(sphere.positions, {.k = 2}), InvalidInput);
}

} // namespace
} // namespace pointform
