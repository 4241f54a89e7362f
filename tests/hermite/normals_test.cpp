// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/hermite/normals.h"

#include "pointform/core/error.h"
#include "pointform/core/parallel.h"
#include "pointform/geometry/shapes.h"

#include "support/test_support.h"
#include "support/thread_counts.h"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>

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

TEST(EstimateNormals, AgreesWithTheClosedFormSolveAtEveryAnisotropy)
{
    // Clouds of 17 points (a point and 16 neighbours, as a default row) drawn with spreads
    // s0 <= s1 <= s2 along a random frame far from the origin: from planes (s0 = 0) and thin
    // slabs to near-isotropic blobs (where the least eigenvalue is nearly double), thin needles
    // and exact lines. estimate_normals() takes a faster route than fit_plane()'s eigen-solve
    // where it can; both must give the same line, and the same degenerate flags.
    std::mt19937 random(11);
    std::normal_distribution<double> gauss;
    const std::array<std::array<double, 3>, 10> spreads = {{{0.0, 1.0, 1.0},
                                                            {1e-4, 0.5, 1.0},
                                                            {0.05, 0.9, 1.0},
                                                            {0.3, 0.6, 1.0},
                                                            {0.9, 0.95, 1.0},
                                                            {0.99, 0.995, 1.0},
                                                            {1.0, 1.0, 1.0},
                                                            {1e-5, 1e-3, 1.0},
                                                            {0.0, 1e-7, 1.0},
                                                            {0.0, 0.0, 1.0}}};
    constexpr std::size_t row = 17;
    constexpr std::size_t clouds_per_spread = 200;
    std::vector<Vec3f> points;
    for (const auto& spread : spreads)
        for (std::size_t c = 0; c < clouds_per_spread; ++c)
        {
            const bool line = spread[1] == 0.0;
            const Eigen::Quaterniond frame = Eigen::Quaterniond::UnitRandom();
            const Vec3d centre(100.0 + gauss(random), -50.0 + gauss(random), 20.0);
            for (std::size_t p = 0; p < row; ++p)
            {
                const Vec3d local(spread[0] * gauss(random), spread[1] * gauss(random),
                                  spread[2] * gauss(random));
                // A line exactly collinear in float: along z, at a multiple of 1/64.
                points.push_back(
                    line ? Vec3f(100.0F, -50.0F,
                                 20.0F + static_cast<float>(std::round(local.z() * 64.0) / 64.0))
                         : (centre + 0.01 * (frame * local)).cast<float>());
            }
        }
    KnnTable table;
    table.k = row;
    for (std::size_t cloud = 0; cloud < points.size() / row; ++cloud)
        for (std::size_t p = 0; p < row; ++p)
            for (std::size_t q = 0; q < row; ++q)
            {
                table.indices.push_back(static_cast<std::uint32_t>(cloud * row + (p + q) % row));
                table.squared_distances.push_back(0.0F); // not read by the fit
            }
    const Normals normals = estimate_normals(points, table);
    std::size_t degenerate = 0;
    for (std::size_t i = 0; i < points.size(); ++i)
    {
        const LocalPlane fit = fit_plane(points, table.neighbors(i));
        const bool flagged = std::binary_search(
            normals.degenerate.begin(), normals.degenerate.end(), static_cast<std::uint32_t>(i));
        ASSERT_EQ(flagged, fit.degenerate) << "point " << i;
        degenerate += flagged ? 1U : 0U;
        if (fit.degenerate)
        {
            EXPECT_EQ(normals.normals[i], Vec3f::Zero());
            continue;
        }
        // The same line, to within float rounding where the least eigenvalue is well apart;
        // near-isotropic clouds leave it ill-conditioned, so a looser bound there.
        const double gap = (fit.eigenvalues[1] - fit.eigenvalues[0]) / fit.eigenvalues[2];
        const double tolerance = gap > 1e-2 ? 1e-6 : 1e-3;
        EXPECT_NEAR(std::abs(normals.normals[i].cast<double>().dot(fit.normal)), 1.0, tolerance)
            << "point " << i << ", eigenvalues " << fit.eigenvalues.transpose();
        EXPECT_NEAR(normals.normals[i].norm(), 1.0F, 1e-6F);
    }
    // The exact lines (and no other cloud: float rounding far from the origin leaves the
    // rotated ones a little width) have no normal.
    EXPECT_EQ(degenerate, clouds_per_spread * row);
}

TEST(EstimateNormals, RejectsTooFewPointsAndTinyK)
{
    const PointCloud sphere = sample_shape(Shape::Sphere, {.count = 10});
    EXPECT_THROW((void)estimate_normals(sphere.positions, {.k = 16}), InvalidInput);
    EXPECT_THROW((void)estimate_normals(sphere.positions, {.k = 2}), InvalidInput);
}

} // namespace
} // namespace pointform
