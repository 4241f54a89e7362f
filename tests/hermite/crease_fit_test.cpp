// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/hermite/crease_fit.h"

#include "pointform/core/parallel.h"
#include "pointform/geometry/shapes.h"
#include "pointform/hermite/surfels.h"

#include "support/test_support.h"
#include "support/thread_counts.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

namespace pointform {
namespace {

/// Samples whose normal's line is more than `degrees` off the truth's.
std::size_t off_by_more_than(std::span<const Vec3f> estimated, std::span<const Vec3f> truth,
                             double degrees)
{
    const auto cosine = static_cast<float>(std::cos(degrees * M_PI / 180.0));
    std::size_t count = 0;
    for (std::size_t i = 0; i < truth.size(); ++i)
        count += std::abs(estimated[i].dot(truth[i])) < cosine ? 1U : 0U;
    return count;
}

/// The mean angle in degrees between the lines of the normals and the truth's.
double mean_angle_deg(std::span<const Vec3f> estimated, std::span<const Vec3f> truth)
{
    double sum = 0.0;
    for (std::size_t i = 0; i < truth.size(); ++i)
        sum += std::acos(std::min(1.0, std::abs(static_cast<double>(estimated[i].dot(truth[i])))));
    return sum * 180.0 / M_PI / static_cast<double>(truth.size());
}

// Every edge and corner of the thin plate (side 2, thickness 0.05) and of the CAD-like part is a
// crease the principal normals blend over: about 5% of the plate's 40,000 samples have a normal
// more than 10° off its face's. Refitted, the normals at the edges take their own face's, and
// the orientation's signs stay.
TEST(SharpCreases, EdgeSamplesTakeTheirOwnFacesNormal)
{
    for (const Shape shape : {Shape::Plate, Shape::Part})
    {
        const PointCloud truth = sample_shape(shape, {.count = 40000, .seed = 5});
        const PointCloud raw = test::without_normals(truth);
        const SurfelResult blended = compute_surfels(raw);
        const SurfelResult sharp = compute_surfels(raw, {.sharp_creases = true});
        EXPECT_EQ(blended.crease_refits, 0U);
        EXPECT_GT(sharp.crease_refits, truth.size() / 50);
        const std::size_t before = off_by_more_than(blended.surfels.normals, truth.normals, 10.0);
        const std::size_t after = off_by_more_than(sharp.surfels.normals, truth.normals, 10.0);
        EXPECT_GT(before, truth.size() / 40);
        EXPECT_LT(after, before / 3) << "shape " << static_cast<int>(shape);
        // Samples on the edge itself may take either face (90° off the one they were drawn
        // from): the mean, not the largest errors, halves.
        EXPECT_LT(mean_angle_deg(sharp.surfels.normals, truth.normals),
                  0.5 * mean_angle_deg(blended.surfels.normals, truth.normals));
        EXPECT_GE(test::oriented_fraction(sharp.surfels.normals, truth.normals), 0.9995);
        // Away from the creases nothing moves.
        std::size_t moved = 0;
        for (std::size_t i = 0; i < truth.size(); ++i)
            moved += sharp.surfels.normals[i] != blended.surfels.normals[i] ? 1U : 0U;
        EXPECT_EQ(moved, sharp.crease_refits);
    }
}

// A 45° wedge (the cone's rim, whose faces' normals turn by 135°): the refit is signed by the
// neighbours on its own face, and fixes more of the rim's turned-over normals than it turns.
TEST(SharpCreases, AConesRimKeepsItsSigns)
{
    const PointCloud truth = sample_shape(Shape::Cone, {.count = 40000, .seed = 6});
    const PointCloud raw = test::without_normals(truth);
    const SurfelResult blended = compute_surfels(raw);
    const SurfelResult sharp = compute_surfels(raw, {.sharp_creases = true});
    EXPECT_GE(test::oriented_fraction(sharp.surfels.normals, truth.normals),
              test::oriented_fraction(blended.surfels.normals, truth.normals));
    EXPECT_LT(off_by_more_than(sharp.surfels.normals, truth.normals, 10.0),
              off_by_more_than(blended.surfels.normals, truth.normals, 10.0) / 2);
}

// Without a crease (no neighbour's normal turns by 30°) or under noise (the planes would be the
// noise's) the normals are the principal ones.
TEST(SharpCreases, SmoothOrNoisyCloudsKeepTheirNormals)
{
    const PointCloud torus = test::without_normals(sample_shape(Shape::Torus, {.count = 30000}));
    const SurfelResult smooth = compute_surfels(torus, {.sharp_creases = true});
    EXPECT_EQ(smooth.crease_refits, 0U);
    EXPECT_EQ(smooth.surfels.normals, compute_surfels(torus).surfels.normals);

    const PointCloud noisy =
        test::without_normals(sample_shape(Shape::Plate, {.count = 30000, .noise = 0.002}));
    const SurfelResult kept = compute_surfels(noisy, {.sharp_creases = true});
    EXPECT_EQ(kept.crease_refits, 0U);
    EXPECT_EQ(kept.surfels.normals, compute_surfels(noisy).surfels.normals);
    std::vector<std::string> stages;
    for (const auto& [stage, seconds] : kept.stage_seconds)
        stages.push_back(stage);
    EXPECT_NE(std::find(stages.begin(), stages.end(), "creases"), stages.end());
}

// The refits read the normals as the orientation left them, block by block: the same normals at
// any thread count (150,000 samples: 37 blocks of crease_refit_block).
TEST(SharpCreases, SameNormalsWhateverTheThreadCount)
{
    const PointCloud cloud = test::without_normals(sample_shape(Shape::Part, {.count = 150000}));
    const auto runs =
        test::at_thread_counts([&] { return compute_surfels(cloud, {.sharp_creases = true}); },
                               {.min_multi_block_loops = 16}, {1, 2, 3});
    ASSERT_GT(runs[0].crease_refits, 0U);
    for (std::size_t i = 1; i < runs.size(); ++i)
    {
        EXPECT_EQ(runs[0].surfels.normals, runs[i].surfels.normals) << "run " << i;
        EXPECT_EQ(runs[0].crease_refits, runs[i].crease_refits) << "run " << i;
    }
}

} // namespace
} // namespace pointform
