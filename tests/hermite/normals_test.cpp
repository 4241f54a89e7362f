// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/hermite/normals.h"

#include "pointform/core/error.h"
#include "pointform/core/parallel.h"
#include "pointform/geometry/shapes.h"
#include "pointform/spatial/kd_tree.h"

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

/// The normals of a plate whose faces lie 2.2 sample spacings apart: the neighbourhood of 16
/// reaches the far face, a few of its samples at the edge. \return the share of the faces'
/// samples (away from the rim) whose normal lies more than 30° off the true one, by `weights`.
double thin_plate_share_off(NeighbourWeights weights)
{
    constexpr std::size_t count = 30000;
    const double spacing = std::sqrt(8.3 / static_cast<double>(count));
    const PointCloud plate =
        sample_shape(Shape::Plate, {.count = count, .seed = 5, .thickness = 2.2 * spacing});
    const KdTree tree(plate.positions);
    const KnnTable table = knn_batch(tree, plate.positions, default_neighbors + 1);
    const Normals normals = estimate_normals(plate.positions, table, {}, weights);
    EXPECT_TRUE(normals.degenerate.empty());
    std::size_t faces = 0;
    std::size_t off = 0;
    for (std::size_t i = 0; i < plate.size(); ++i)
    {
        const Vec3f& p = plate.positions[i];
        if (std::abs(plate.normals[i].z()) < 0.99F || std::abs(p.x()) > 1.0 - 3.0 * spacing ||
            std::abs(p.y()) > 1.0 - 3.0 * spacing)
            continue;
        ++faces;
        off += std::abs(normals.normals[i].dot(plate.normals[i])) < std::cos(M_PI / 6.0) ? 1 : 0;
    }
    EXPECT_GT(faces, count / 2);
    return static_cast<double>(off) / static_cast<double>(faces);
}

TEST(EstimateNormals, LocalWeightsKeepAThinPlatesFacesApart)
{
    // Uniform weights: the far face's samples turn about a tenth of the normals (12.6% at 100k
    // samples); the local weights hold them to their own face.
    EXPECT_GT(thin_plate_share_off(NeighbourWeights::Uniform), 0.05);
    EXPECT_LT(thin_plate_share_off(NeighbourWeights::Local), 0.002);
}

// Only samples by a parallel sheet are refitted: none on the sphere, a few by the creases of the
// blobby and the part (at 20k samples the part's 90th percentile of the angle to the true normal
// 18.32° -> 18.06°, its 99th 52.37° -> 52.39°).
TEST(EstimateNormals, LocalWeightsAreAtLeastAsCloseOnCleanShapes)
{
    for (const Shape shape : {Shape::Sphere, Shape::Blobby, Shape::Part})
    {
        const PointCloud cloud = sample_shape(shape, {.count = 20000, .seed = 6});
        const KdTree tree(cloud.positions);
        const KnnTable table = knn_batch(tree, cloud.positions, default_neighbors + 1);
        const Normals uniform = estimate_normals(cloud.positions, table);
        const Normals local = estimate_normals(cloud.positions, table, {}, NeighbourWeights::Local);
        const auto quantile = [&](const Normals& normals, double q) {
            return test::line_angle_quantile_deg(normals.normals, cloud.normals, q);
        };
        const int id = static_cast<int>(shape);
        EXPECT_LE(quantile(local, 0.5), quantile(uniform, 0.5)) << id;
        EXPECT_LE(quantile(local, 0.9), quantile(uniform, 0.9)) << id;
        EXPECT_LE(quantile(local, 0.99), 1.05 * quantile(uniform, 0.99)) << id;
    }
}

TEST(EstimateNormals, LocalWeightsKeepTheUniformFitWhereTheyLeaveALine)
{
    // A point, two neighbours on a line through it and six at the farthest distance, one on
    // each axis: the uniform fit is ill-defined (an isotropic spread), and the local weights
    // (nothing for the point itself and for the farthest) leave the line alone, which spans no
    // plane: the uniform fit's normal stays.
    const std::vector<Vec3f> points = {Vec3f(0, 0, 0),  Vec3f(0.1F, 0, 0), Vec3f(-0.1F, 0, 0),
                                       Vec3f(1, 0, 0),  Vec3f(-1, 0, 0),   Vec3f(0, 1, 0),
                                       Vec3f(0, -1, 0), Vec3f(0, 0, 1),    Vec3f(0, 0, -1)};
    KnnTable table;
    table.k = points.size();
    for (std::uint32_t j = 0; j < points.size(); ++j)
    {
        table.indices.push_back(j);
        table.squared_distances.push_back(points[j].squaredNorm());
    }
    // Only row 0 is the point's own; the others are the same row, read for their own points.
    for (std::size_t r = 1; r < points.size(); ++r)
        for (std::uint32_t j = 0; j < points.size(); ++j)
        {
            table.indices.push_back(j);
            table.squared_distances.push_back((points[j] - points[r]).squaredNorm());
        }
    const Normals uniform = estimate_normals(points, table);
    const Normals local = estimate_normals(points, table, {}, NeighbourWeights::Local);
    ASSERT_TRUE(uniform.degenerate.empty());
    EXPECT_EQ(local.normals[0], uniform.normals[0]);
    EXPECT_NEAR(local.normals[0].norm(), 1.0F, 1e-6F);
}

TEST(EstimateNormals, LocalWeightsSameResultForOneAndTwoThreads)
{
    const PointCloud torus = sample_shape(Shape::Torus, {.count = 20000, .seed = 4});
    const KdTree tree(torus.positions);
    const KnnTable table = knn_batch(tree, torus.positions, 13);
    const auto runs = test::at_thread_counts(
        [&] { return estimate_normals(torus.positions, table, {}, NeighbourWeights::Local); });
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
