// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/hermite/surfels.h"

#include "pointform/core/error.h"
#include "pointform/core/parallel.h"
#include "pointform/geometry/shapes.h"

#include "support/test_support.h"
#include "support/thread_counts.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace pointform {
namespace {

TEST(ComputeSurfels, TorusGivesOutwardNormalsAndRadii)
{
    const PointCloud torus = sample_shape(Shape::Torus, {.count = 30000, .seed = 9});
    PointCloud input = torus;
    input.normals.clear();
    const SurfelResult result = compute_surfels(input, {.k = 16, .radius_scale = 2.0});
    ASSERT_EQ(result.surfels.size(), torus.size());
    ASSERT_EQ(result.surfels.radii.size(), torus.size());
    EXPECT_GE(test::oriented_fraction(result.surfels.normals, torus.normals), 0.999);
    // Radii are of the order of the sampling step: area / N = 4π²Rr / N.
    const double step = std::sqrt(4.0 * M_PI * M_PI * 0.35 / 30000.0);
    for (const float r : result.surfels.radii)
    {
        EXPECT_GT(r, 0.5 * step);
        EXPECT_LT(r, 20.0 * step);
    }
    std::vector<std::string> stages;
    for (const auto& [stage, seconds] : result.stage_seconds)
    {
        stages.push_back(stage);
        EXPECT_GE(seconds, 0.0) << stage;
    }
    EXPECT_EQ(stages,
              (std::vector<std::string>{"check", "spatial sort", "kd-tree", "knn", "normals",
                                        "orientation", "radius", "output order"}));
}

TEST(ComputeSurfels, GeoreferencedCoordinatesKeepPrecision)
{
    // The same sphere at a UTM-like offset: float storage relative to the origin loses nothing.
    PointCloud sphere = sample_shape(Shape::Sphere, {.count = 8000, .seed = 10});
    const PointCloud reference = sphere;
    sphere.origin = Vec3d(512345.0, 4212345.0, 310.0);
    const SurfelResult near = compute_surfels(reference);
    const SurfelResult far = compute_surfels(sphere);
    EXPECT_EQ(near.surfels.normals, far.surfels.normals);
    EXPECT_EQ(far.surfels.origin, sphere.origin);
}

TEST(ComputeSurfels, OrientModes)
{
    const PointCloud sphere = sample_shape(Shape::Sphere, {.count = 5000, .seed = 11});
    const SurfelResult inward = compute_surfels(sphere, {.orient = OrientMode::Flip});
    EXPECT_EQ(test::oriented_fraction(inward.surfels.normals, sphere.normals), 0.0);
    const SurfelResult towards_center =
        compute_surfels(sphere, {.orient = OrientMode::Towards, .orient_target = Vec3d::Zero()});
    EXPECT_EQ(test::oriented_fraction(towards_center.surfels.normals, sphere.normals), 0.0);
    const SurfelResult along =
        compute_surfels(sphere, {.orient = OrientMode::Along, .orient_target = -Vec3d::UnitX()});
    for (const auto& n : along.surfels.normals)
        EXPECT_LE(n.x(), 0.0F);
}

/// What a depth camera at `sensor` sees of the unit sphere: the samples of a dense draw whose
/// outward normal faces it, with their true (outward) normals.
PointCloud sphere_seen_from(const Vec3d& sensor)
{
    const PointCloud sphere = sample_shape(Shape::Sphere, {.count = 12000, .seed = 21});
    PointCloud seen;
    for (std::size_t i = 0; i < sphere.size(); ++i)
    {
        const Vec3d p = sphere.world(i);
        if (sphere.normals[i].cast<double>().dot(sensor - p) > 0.0)
        {
            seen.positions.push_back(sphere.positions[i]);
            seen.normals.push_back(sphere.normals[i]);
        }
    }
    seen.origin = sphere.origin;
    return seen;
}

TEST(ComputeSurfels, DepthImageFacesItsSensor)
{
    // A depth image holds only surfaces that faced the camera: its estimated normals face the
    // sensor (OrientMode::Auto), outward here, whichever side it was seen from.
    for (const Vec3d& sensor : {Vec3d(0.0, 0.0, 3.0), Vec3d(-2.0, 1.0, -2.5)})
    {
        PointCloud seen = sphere_seen_from(sensor);
        const std::vector<Vec3f> truth = seen.normals;
        seen.normals.clear();
        seen.sensor = sensor;
        const SurfelResult result = compute_surfels(seen);
        EXPECT_TRUE(result.towards_sensor);
        ASSERT_TRUE(result.surfels.sensor.has_value());
        EXPECT_EQ(*result.surfels.sensor, sensor);
        EXPECT_EQ(test::oriented_fraction(result.surfels.normals, truth), 1.0) << sensor.z();
        for (std::size_t i = 0; i < seen.size(); ++i)
            ASSERT_GT(result.surfels.normals[i].cast<double>().dot(sensor - seen.world(i)), 0.0);
    }
    // A flat patch seen from below faces down, from above up.
    PointCloud patch;
    for (int y = 0; y < 60; ++y)
        for (int x = 0; x < 60; ++x)
            patch.positions.emplace_back(0.02F * static_cast<float>(x),
                                         0.02F * static_cast<float>(y), 0.0F);
    for (const double side : {-1.0, 1.0})
    {
        patch.sensor = Vec3d(0.6, 0.6, 2.0 * side);
        const SurfelResult result = compute_surfels(patch);
        for (const Vec3f& n : result.surfels.normals)
            ASSERT_GT(static_cast<double>(n.z()) * side, 0.99);
    }
}

TEST(ComputeSurfels, AutoIsMstWithoutASensor)
{
    // No sensor: the default orientation is the minimum spanning tree's, the same normals.
    PointCloud cloud =
        sample_shape(Shape::Torus, {.count = 6000, .seed = 22, .noise = 0.002, .holes = 2});
    cloud.normals.clear();
    const SurfelResult automatic = compute_surfels(cloud);
    const SurfelResult mst = compute_surfels(cloud, {.orient = OrientMode::Mst});
    EXPECT_FALSE(automatic.towards_sensor);
    EXPECT_FALSE(mst.towards_sensor);
    EXPECT_EQ(automatic.surfels.normals, mst.surfels.normals);
    // An explicit mode wins over the sensor.
    PointCloud seen = cloud;
    seen.sensor = Vec3d(0.0, 0.0, 5.0);
    const SurfelResult explicit_mst = compute_surfels(seen, {.orient = OrientMode::Mst});
    EXPECT_FALSE(explicit_mst.towards_sensor);
    EXPECT_EQ(explicit_mst.surfels.normals, mst.surfels.normals);
    seen.sensor = Vec3d(0.0, std::numeric_limits<double>::quiet_NaN(), 5.0);
    EXPECT_THROW((void)compute_surfels(seen), InvalidInput);
}

TEST(ComputeSurfels, SameOutputForOneAndTwoThreads)
{
    const PointCloud cloud =
        sample_shape(Shape::TwoSpheres, {.count = 20000, .seed = 12, .noise = 0.003, .holes = 4});
    const auto runs = test::at_thread_counts([&] { return compute_surfels(cloud); });
    for (std::size_t i = 1; i < runs.size(); ++i)
    {
        EXPECT_EQ(runs[0].surfels.normals, runs[i].surfels.normals) << i + 1 << " threads";
        EXPECT_EQ(runs[0].surfels.radii, runs[i].surfels.radii) << i + 1 << " threads";
        EXPECT_EQ(runs[0].orientation.flipped, runs[i].orientation.flipped) << i + 1;
    }
}

// Large enough that every stage splits its work: the kd-tree's top splits and subtrees, the
// spatial sort's box and gathers, the orientation's patches and votes (clean) or the spanning
// forest's fused costs and first Borůvka round, the guide's count, rings and sheets on the noisy
// cloud. Same surfels at any thread count.
TEST(ComputeSurfels, LargeCloudsAreTheSameWhateverTheThreadCount)
{
    for (const double noise : {0.0, 0.002})
    {
        const PointCloud cloud =
            sample_shape(Shape::Blobby, {.count = 150000, .seed = 21, .noise = noise});
        const auto runs = test::at_thread_counts([&] { return compute_surfels(cloud); },
                                                 {.min_multi_block_loops = 16}, {1, 2, 3, 4});
        for (std::size_t i = 1; i < runs.size(); ++i)
        {
            EXPECT_EQ(runs[0].surfels.normals, runs[i].surfels.normals) << "run " << i;
            EXPECT_EQ(runs[0].surfels.radii, runs[i].surfels.radii) << "run " << i;
            EXPECT_EQ(runs[0].orientation.flipped, runs[i].orientation.flipped) << "run " << i;
            EXPECT_EQ(runs[0].orientation.components, runs[i].orientation.components);
        }
        EXPECT_EQ(runs[0].orientation.components, 1U) << "noise " << noise;
        EXPECT_TRUE(runs[0].orientation.unoriented.empty());
    }
}

// A cloud handed over (as `pointform normals` does) gives the same surfels as one viewed, with
// its positions and colours moved in; a cloud that fails the checks is left as it was.
TEST(ComputeSurfels, CloudHandedOverGivesTheSameSurfels)
{
    PointCloud cloud = sample_shape(Shape::Torus, {.count = 30000, .seed = 5, .noise = 0.001});
    cloud.colors.assign(cloud.size(), Color{10, 20, 30});
    const SurfelResult viewed = compute_surfels(cloud);
    PointCloud handed = cloud;
    const Vec3f* const positions = handed.positions.data();
    const SurfelResult moved = compute_surfels(std::move(handed));
    EXPECT_EQ(moved.surfels.positions, viewed.surfels.positions);
    EXPECT_EQ(moved.surfels.positions.data(), positions); // moved, not copied
    EXPECT_EQ(moved.surfels.colors, viewed.surfels.colors);
    EXPECT_EQ(moved.surfels.normals, viewed.surfels.normals);
    EXPECT_EQ(moved.surfels.radii, viewed.surfels.radii);
    EXPECT_EQ(moved.radius.median, viewed.radius.median);
    EXPECT_EQ(moved.orientation.flipped, viewed.orientation.flipped);
    EXPECT_EQ(handed.size(), 0U); // NOLINT(bugprone-use-after-move): documented as left empty
    PointCloud few = cloud;
    few.positions.resize(10);
    few.colors.resize(10);
    EXPECT_THROW((void)compute_surfels(std::move(few), {.k = 16}), InvalidInput);
    EXPECT_EQ(few.size(), 10U); // NOLINT(bugprone-use-after-move): unchanged when it throws
}

// On a noisy cloud the orientation's guide normals are written into the handed cloud's position
// array while the work holds the points in Morton order: the array comes back with the points
// exactly as they were, both when the work is done and when it is cancelled after the guide grew.
// Torus, 30,000 samples, noise twice the sampling step: a guided cloud (see
// OrientNormalsMst.NoisyTorusNoiseTwiceTheSamplingStep).
TEST(ComputeSurfels, NoisyCloudHandedOverComesBackWhole)
{
    const PointCloud cloud =
        sample_shape(Shape::Torus, {.count = 30000, .seed = 9, .noise = 0.011});
    const SurfelResult viewed = compute_surfels(cloud);
    PointCloud handed = cloud;
    const Vec3f* const positions = handed.positions.data();
    const SurfelResult moved = compute_surfels(std::move(handed));
    EXPECT_EQ(moved.surfels.positions, cloud.positions);
    EXPECT_EQ(moved.surfels.positions.data(), positions);
    EXPECT_EQ(moved.surfels.normals, viewed.surfels.normals);
    EXPECT_EQ(moved.surfels.radii, viewed.surfels.radii);

    // Repeated samples: the work holds fewer places than samples, the array still every sample.
    PointCloud repeated = cloud;
    repeated.normals.clear();
    for (std::size_t i = 0; i < 500; ++i)
        repeated.positions.push_back(cloud.positions[(i * 7919) % cloud.size()]);
    const SurfelResult repeated_viewed = compute_surfels(repeated);
    PointCloud repeated_handed = repeated;
    const SurfelResult repeated_moved = compute_surfels(std::move(repeated_handed));
    EXPECT_EQ(repeated_moved.copies.size(), 500U);
    EXPECT_EQ(repeated_moved.surfels.positions, repeated.positions);
    EXPECT_EQ(repeated_moved.surfels.normals, repeated_viewed.surfels.normals);

    PointCloud cancelled = cloud;
    const Vec3f* const cancelled_positions = cancelled.positions.data();
    bool asked = false;
    const ProgressCallback stop = [&](std::string_view stage, double) {
        asked = asked || stage == "orientation";
        return stage != "orientation";
    };
    EXPECT_THROW((void)compute_surfels(std::move(cancelled), {.progress = stop}), Cancelled);
    EXPECT_TRUE(asked);
    // NOLINTBEGIN(bugprone-use-after-move): unchanged when it throws
    EXPECT_EQ(cancelled.positions, cloud.positions);
    EXPECT_EQ(cancelled.positions.data(), cancelled_positions);
    // NOLINTEND(bugprone-use-after-move)
}

// One point very far away makes the whole cloud's covariance a line (its spread 1e28 against the
// sphere's 1/3): the input check looks at the bulk then, and the sphere gets its normals. Points
// on a line stay a line with a far point beside them. Beyond 1e18 float distances overflow: a
// clear error.
// A clean plate whose faces lie 2.2 sample spacings apart: its normals come from the nearest
// neighbours (NeighbourWeights::Local), so the orientation finds each face's side. With every
// neighbour alike, about a tenth of the faces' normals turned more than 30° (the far face's
// samples at the neighbourhood's edge) and 1% were turned over (at 100k samples), and the field
// made a surface with hundreds of handles through the plate.
TEST(ComputeSurfels, AThinPlatesFacesFaceOut)
{
    constexpr std::size_t count = 30000;
    const double spacing = std::sqrt(8.3 / static_cast<double>(count));
    const PointCloud plate =
        sample_shape(Shape::Plate, {.count = count, .seed = 5, .thickness = 2.2 * spacing});
    PointCloud input = plate;
    input.normals.clear();
    const SurfelResult result = compute_surfels(input);
    std::size_t faces = 0;
    std::size_t out = 0;
    std::size_t flipped = 0;
    for (std::size_t i = 0; i < plate.size(); ++i)
    {
        if (std::abs(plate.normals[i].z()) < 0.99F)
            continue;
        ++faces;
        out += result.surfels.normals[i].dot(plate.normals[i]) > 0.9F ? 1 : 0;
        flipped += result.surfels.normals[i].dot(plate.normals[i]) < 0.0F ? 1 : 0;
    }
    // Within 26°: 97.1% (83.7% with every neighbour alike), the rest mostly by the rim, where
    // the far face and the side are both near; turned over: 8 of 28,922 (307).
    EXPECT_GT(static_cast<double>(out), 0.96 * static_cast<double>(faces));
    EXPECT_LT(static_cast<double>(flipped), 0.001 * static_cast<double>(faces));
}

TEST(ComputeSurfels, AFarOutlierDoesNotMakeASurfaceALine)
{
    PointCloud cloud = sample_shape(Shape::Sphere, {.count = 5000, .seed = 14});
    cloud.normals.clear();
    cloud.radii.clear();
    PointCloud too_far = cloud;
    too_far.positions.emplace_back(1e20F, 0.0F, 0.0F);
    EXPECT_THROW((void)compute_surfels(too_far), InvalidInput);
    cloud.positions.emplace_back(1e14F, 0.0F, 0.0F);
    const SurfelResult result = compute_surfels(cloud);
    EXPECT_EQ(result.isolated, std::vector<std::uint32_t>{5000});
    for (std::size_t i = 0; i < 5000; ++i)
        ASSERT_GT(result.surfels.normals[i].dot(result.surfels.positions[i].normalized()), 0.95F)
            << i;
    PointCloud line;
    for (int i = 0; i < 500; ++i)
        line.positions.emplace_back(0.01F * static_cast<float>(i), 0.0F, 0.0F);
    line.positions.emplace_back(0.0F, 1e14F, 0.0F);
    EXPECT_THROW((void)compute_surfels(line), InvalidInput);
}

// Samples repeated at one place (every sample of a sphere 20 times over, more than a row of
// neighbours: each sample's k nearest were all its own copies, with no reach and no plane):
// the surfels are worked out once a place, and every copy has its original's. The same normals
// (within float rounding) and radii as the sphere without copies; the copies are named in input
// order, the first of each place being the original. Too few distinct places is an error.
TEST(ComputeSurfels, CopiesShareTheirOriginalsSurfel)
{
    PointCloud sphere = sample_shape(Shape::Sphere, {.count = 3000, .seed = 41});
    sphere.normals.clear();
    sphere.radii.clear();
    PointCloud repeated;
    for (int copy = 0; copy < 20; ++copy)
        repeated.positions.insert(repeated.positions.end(), sphere.positions.begin(),
                                  sphere.positions.end());
    const SurfelResult plain = compute_surfels(sphere);
    const SurfelResult result = compute_surfels(repeated);
    EXPECT_TRUE(plain.copies.empty());
    ASSERT_EQ(result.copies.size(), 19U * 3000U);
    EXPECT_EQ(result.copies.front(), 3000U);
    EXPECT_EQ(result.copies.back(), 20U * 3000U - 1U);
    EXPECT_EQ(result.orientation.unoriented.size(), 0U);
    EXPECT_EQ(result.degenerate, 0U);
    for (std::size_t i = 0; i < repeated.size(); ++i)
    {
        const std::size_t j = i % 3000;
        ASSERT_GT(result.surfels.normals[i].dot(plain.surfels.normals[j]), 0.9999F) << i;
        ASSERT_FLOAT_EQ(result.surfels.radii[i], plain.surfels.radii[j]) << i;
    }
    PointCloud few;
    for (int copy = 0; copy < 3; ++copy)
        few.positions.insert(few.positions.end(), sphere.positions.begin(),
                             sphere.positions.begin() + 10);
    EXPECT_THROW((void)compute_surfels(few), InvalidInput);
}

TEST(ComputeSurfels, RejectsBadInput)
{
    PointCloud cloud = sample_shape(Shape::Sphere, {.count = 100, .seed = 13});
    EXPECT_THROW((void)compute_surfels(cloud, {.k = 100}), InvalidInput); // no 100 others each
    EXPECT_THROW((void)compute_surfels(cloud, {.k = 2}), InvalidInput);
    EXPECT_THROW((void)compute_surfels(cloud, {.radius_scale = 0.0}), InvalidInput);
    EXPECT_THROW((void)compute_surfels(PointCloud{}), InvalidInput); // empty

    PointCloud with_nan = cloud;
    with_nan.positions[17].y() = std::numeric_limits<float>::quiet_NaN();
    EXPECT_THROW((void)compute_surfels(with_nan), InvalidInput);
    PointCloud with_inf = cloud;
    with_inf.positions[3].x() = std::numeric_limits<float>::infinity();
    EXPECT_THROW((void)compute_surfels(with_inf), InvalidInput);

    PointCloud coincident;
    coincident.positions.assign(50, Vec3f(1.0F, 2.0F, 3.0F));
    try
    {
        (void)compute_surfels(coincident);
        ADD_FAILURE() << "coincident points accepted";
    }
    catch (const InvalidInput& e)
    {
        EXPECT_NE(std::string(e.what()).find("coincide"), std::string::npos) << e.what();
    }

    PointCloud collinear;
    for (int i = 0; i < 50; ++i)
        collinear.positions.emplace_back(0.1F * static_cast<float>(i), 0.2F * static_cast<float>(i),
                                         -0.3F * static_cast<float>(i));
    try
    {
        (void)compute_surfels(collinear);
        ADD_FAILURE() << "collinear points accepted";
    }
    catch (const InvalidInput& e)
    {
        EXPECT_NE(std::string(e.what()).find("line"), std::string::npos) << e.what();
    }
}

} // namespace
} // namespace pointform
