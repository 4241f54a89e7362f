// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/core/error.h"
#include "pointform/geometry/shapes.h"
#include "pointform/hermite/surfels.h"

#include "support/test_meshes.h"
#include "support/thread_counts.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>

namespace pointform {
namespace {

/// Share of the normals within `degrees` of the outward radius of the unit sphere.
double outward_share(const PointCloud& cloud, double degrees)
{
    std::size_t good = 0;
    for (std::size_t i = 0; i < cloud.size(); ++i)
    {
        const Vec3d radial = cloud.positions[i].cast<double>().normalized();
        good += cloud.normals[i].cast<double>().dot(radial) >
                std::cos(degrees * std::numbers::pi / 180.0);
    }
    return static_cast<double>(good) / static_cast<double>(cloud.size());
}

// One stray return far from a scan (here 10^6 radii off a unit sphere) gets the gap to the
// others as its radius and a plane of its own: it is left out, whether the normals are
// estimated or given, and counted. Copies of one point (no gap) are not isolated (they are one
// surfel, with their original), and a clean sphere loses nothing.
TEST(SurfelsFromSamples, AStrayPointFarAwayIsLeftOut)
{
    PointCloud points = sample_shape(Shape::Sphere, {.count = 20000, .seed = 23});
    points.radii.clear();
    points.positions.insert(points.positions.end(), 30, points.positions[4321]);
    points.normals.insert(points.normals.end(), 30, points.normals[4321]);
    const std::size_t kept = points.size();
    points.positions.emplace_back(1e6F, 0.0F, 0.0F);
    points.normals.emplace_back(1.0F, 0.0F, 0.0F);
    for (const bool estimate : {true, false})
    {
        const SurfelsFromSamples out = surfels_from_samples(points, {.reestimate = estimate});
        EXPECT_EQ(out.estimated_normals, estimate);
        EXPECT_EQ(out.isolated, 1U) << "estimated " << estimate;
        EXPECT_EQ(out.copies, 30U) << "estimated " << estimate; // one surfel a place
        ASSERT_EQ(out.surfels.size(), kept - 30);
        for (std::size_t i = 0; i < out.surfels.size(); ++i)
        {
            ASSERT_LT(out.surfels.positions[i].norm(), 1.001F) << i;
            ASSERT_LT(out.surfels.radii[i], 0.2F) << i;
        }
    }
    PointCloud clean = sample_shape(Shape::Sphere, {.count = 20000, .seed = 24});
    clean.normals.clear();
    clean.radii.clear();
    const SurfelResult result = compute_surfels(clean);
    EXPECT_TRUE(result.isolated.empty());
    EXPECT_EQ(surfels_from_samples(clean).isolated, 0U);
}

TEST(SurfelsFromSamples, StraysThroughTheBoxLeaveTheTorusOutward)
{
    // `pointform sample torus --strays 0.01` (the bench's strays variant): 1,000 strays through
    // the box grown by 30%, raw points. The strays kept far from the surface have areas (squared
    // reach) hundreds of times a surface sample's and normals that say nothing; in the flux that
    // decides a component's sign they outweighed the torus, which came out inside out.
    PointCloud points = sample_shape(Shape::Torus, {.count = 100000, .strays = 0.01});
    points.normals.clear();
    points.radii.clear();
    const SurfelsFromSamples out = surfels_from_samples(points, {});
    std::size_t on = 0;
    std::size_t outward = 0;
    for (std::size_t i = 0; i < out.surfels.size(); ++i)
    {
        const Vec3f& p = out.surfels.positions[i];
        const Vec3f ring = Vec3f(p.x(), p.y(), 0.0F).normalized();
        const Vec3f across = p - ring;
        if (std::abs(across.norm() - 0.35F) > 0.005F)
            continue;
        ++on;
        outward += out.surfels.normals[i].dot(across) > 0.0F ? 1 : 0;
    }
    EXPECT_GT(on, 99000U);
    EXPECT_GT(outward, on - on / 1000) << outward << " of " << on << " face outward";
}

// Stray returns near a surface (here 60, 4-8 sample spacings off a sphere: the nearer as near as
// the reach of a surface sample, so not isolated) are left out, whether the normals are
// estimated or given, and counted; where they are estimated, the other samples' are made
// without them: every one within 5° of the sphere's (with the strays among their nearest, the
// neighbours of a stray tilt by up to tens of degrees).
TEST(SurfelsFromSamples, StraysNearTheSurfaceAreLeftOut)
{
    PointCloud points = sample_shape(Shape::Sphere, {.count = 20000, .seed = 26});
    points.radii.clear();
    std::mt19937 random(27);
    std::normal_distribution<float> gauss;
    std::uniform_real_distribution<float> off(1.1F, 1.2F);
    for (int i = 0; i < 60; ++i)
    {
        const Vec3f direction = Vec3f(gauss(random), gauss(random), gauss(random)).normalized();
        points.positions.push_back(direction * off(random));
        points.normals.push_back(direction);
    }
    for (const bool estimate : {true, false})
    {
        const SurfelsFromSamples out = surfels_from_samples(points, {.reestimate = estimate});
        // The farther ones are isolated (their reach over twice their nearest's), and counted so.
        EXPECT_GT(out.off_surface, 10U) << "estimated " << estimate;
        EXPECT_GE(out.isolated + out.off_surface, 57U) << "estimated " << estimate;
        std::size_t kept_off = 0;
        for (std::size_t i = 0; i < out.surfels.size(); ++i)
            kept_off += out.surfels.positions[i].norm() > 1.01F ? 1 : 0;
        EXPECT_EQ(kept_off + out.isolated + out.off_surface, 60U) << "estimated " << estimate;
        if (estimate)
        {
            std::size_t tilted = 0;
            for (std::size_t i = 0; i < out.surfels.size(); ++i)
                if (out.surfels.positions[i].norm() < 1.01F)
                    tilted += out.surfels.normals[i].dot(out.surfels.positions[i].normalized()) <
                                      std::cos(5.0F * std::numbers::pi_v<float> / 180.0F)
                                  ? 1
                                  : 0;
            EXPECT_EQ(tilted, 0U);
        }
    }
    // Kept when asked.
    const SurfelsFromSamples kept = surfels_from_samples(points, {.keep_off_surface = true});
    EXPECT_EQ(kept.off_surface, 0U);
    EXPECT_EQ(kept.surfels.size() + kept.isolated, points.size());
    // compute_surfels() names them (they keep surfels there) when asked, and by default does not.
    PointCloud raw = points;
    raw.normals.clear();
    const SurfelResult named = compute_surfels(raw, {.off_surface = true});
    EXPECT_EQ(named.surfels.size(), points.size());
    EXPECT_GT(named.off_surface.size(), 20U);
    EXPECT_TRUE(std::all_of(named.off_surface.begin(), named.off_surface.end(),
                            [](std::uint32_t i) { return i >= 20000; }));
    EXPECT_TRUE(compute_surfels(raw).off_surface.empty());
    // The same whatever the thread count, the rows that held strays refilled in parallel.
    const auto runs = test::at_thread_counts(
        [&] { return compute_surfels(raw, {.off_surface = true}); }, {.min_multi_block_loops = 4});
    for (std::size_t i = 1; i < runs.size(); ++i)
    {
        EXPECT_EQ(runs[0].off_surface, runs[i].off_surface) << "run " << i;
        EXPECT_EQ(runs[0].surfels.normals, runs[i].surfels.normals) << "run " << i;
        EXPECT_EQ(runs[0].surfels.radii, runs[i].surfels.radii) << "run " << i;
    }
}

// A field has one surfel a place: copies of samples (here every sample twice, and one 40
// times) are left out and counted, whether the normals are estimated or given.
TEST(SurfelsFromSamples, CopiesAreOneSurfel)
{
    PointCloud points = sample_shape(Shape::Sphere, {.count = 5000, .seed = 25});
    points.radii.clear();
    const std::size_t distinct = points.size();
    for (std::size_t i = 0; i < distinct; ++i)
    {
        points.positions.push_back(points.positions[i]);
        points.normals.push_back(points.normals[i]);
    }
    points.positions.insert(points.positions.end(), 39, points.positions[17]);
    points.normals.insert(points.normals.end(), 39, points.normals[17]);
    for (const bool estimate : {true, false})
    {
        const SurfelsFromSamples out = surfels_from_samples(points, {.reestimate = estimate});
        EXPECT_EQ(out.copies, distinct + 39) << "estimated " << estimate;
        EXPECT_EQ(out.isolated, 0U);
        ASSERT_EQ(out.surfels.size(), distinct);
        for (std::size_t i = 0; i < distinct; ++i)
        {
            ASSERT_EQ(out.surfels.positions[i], points.positions[i]) << i;
            ASSERT_GT(out.surfels.radii[i], 0.0F) << i;
        }
    }
}

TEST(SurfelsFromSamples, RawPointsGetOrientedNormalsAndFieldRadii)
{
    PointCloud points = sample_shape(Shape::Sphere, {.count = 5000, .seed = 21});
    points.normals.clear();
    const SurfelsFromSamples out = surfels_from_samples(points);
    EXPECT_TRUE(out.estimated_normals);
    EXPECT_TRUE(out.estimated_radii);
    EXPECT_EQ(out.components, 1U);
    EXPECT_EQ(out.unoriented, 0U);
    ASSERT_EQ(out.surfels.size(), points.size());
    EXPECT_GT(outward_share(out.surfels, 10.0), 0.99);
    // The field's radius scale: 1.5 times compute_surfels()' radius at its default of 1.
    const SurfelResult plain = compute_surfels(points);
    for (std::size_t i = 0; i < points.size(); i += 97)
        EXPECT_FLOAT_EQ(out.surfels.radii[i],
                        static_cast<float>(default_field_radius_scale) * plain.surfels.radii[i]);
}

TEST(SurfelsFromSamples, GivenNormalsAreKeptAndRadiiComputedOnlyWhenMissing)
{
    const PointCloud oriented = sample_shape(Shape::Sphere, {.count = 3000, .seed = 22});
    const SurfelsFromSamples out = surfels_from_samples(oriented, {.radius_scale = 2.0});
    EXPECT_FALSE(out.estimated_normals);
    EXPECT_TRUE(out.estimated_radii);
    EXPECT_EQ(out.surfels.normals, oriented.normals);
    ASSERT_EQ(out.surfels.radii.size(), oriented.size());
    for (const float r : out.surfels.radii)
        EXPECT_GT(r, 0.0F);

    PointCloud with_radii = oriented;
    with_radii.radii.assign(with_radii.size(), 0.125F);
    const SurfelsFromSamples kept = surfels_from_samples(with_radii);
    EXPECT_FALSE(kept.estimated_radii);
    EXPECT_EQ(kept.surfels.radii, with_radii.radii);

    // reestimate: the given (here inverted) normals play no part.
    PointCloud inverted = oriented;
    for (auto& n : inverted.normals)
        n = -n;
    const SurfelsFromSamples again = surfels_from_samples(inverted, {.reestimate = true});
    EXPECT_TRUE(again.estimated_normals);
    EXPECT_GT(outward_share(again.surfels, 10.0), 0.99);
}

TEST(SurfelsFromSamples, EstimatedNormalsTakeTheOrientationAsked)
{
    PointCloud points = sample_shape(Shape::Sphere, {.count = 4000, .seed = 23});
    points.normals.clear();
    const SurfelsFromSamples inward = surfels_from_samples(points, {.orient = OrientMode::Flip});
    EXPECT_LT(outward_share(inward.surfels, 170.0), 0.01);
    const SurfelsFromSamples down = surfels_from_samples(
        points, {.orient = OrientMode::Along, .orient_target = Vec3d(0.0, 0.0, -2.0)});
    for (const Vec3f& n : down.surfels.normals)
        EXPECT_LE(n.z(), 0.0F);
    // Towards a viewpoint inside: inward, as the flip.
    const SurfelsFromSamples towards = surfels_from_samples(
        points, {.orient = OrientMode::Towards, .orient_target = Vec3d(0.1, 0.0, 0.0)});
    EXPECT_EQ(towards.surfels.normals, inward.surfels.normals);
    // Given normals keep their signs whatever the mode.
    const PointCloud oriented = sample_shape(Shape::Sphere, {.count = 3000, .seed = 22});
    EXPECT_EQ(surfels_from_samples(oriented, {.orient = OrientMode::Flip}).surfels.normals,
              oriented.normals);
    // A target that is no direction or no place is refused before any work.
    EXPECT_THROW(static_cast<void>(surfels_from_samples(
                     points, {.orient = OrientMode::Along, .orient_target = Vec3d::Zero()})),
                 InvalidInput);
    EXPECT_THROW(
        static_cast<void>(surfels_from_samples(
            points, {.orient = OrientMode::Towards,
                     .orient_target = Vec3d(std::numeric_limits<double>::quiet_NaN(), 0.0, 0.0)})),
        InvalidInput);
}

TEST(ParseOrient, ReadsEveryModeAndRefusesTheRest)
{
    EXPECT_EQ(parse_orient("auto").mode, OrientMode::Auto);
    EXPECT_EQ(parse_orient("mst").mode, OrientMode::Mst);
    EXPECT_EQ(parse_orient("none").mode, OrientMode::None);
    EXPECT_EQ(parse_orient("flip").mode, OrientMode::Flip);
    const OrientChoice towards = parse_orient("towards:1.5, -2e3 ,+0.25");
    EXPECT_EQ(towards.mode, OrientMode::Towards);
    EXPECT_EQ(towards.target, Vec3d(1.5, -2000.0, 0.25));
    const OrientChoice along = parse_orient("along:0,0,1");
    EXPECT_EQ(along.mode, OrientMode::Along);
    EXPECT_EQ(along.target, Vec3d::UnitZ());
    for (const char* bad :
         {"", "sideways", "MST", "auto:1,2,3", "flip:", "towards", "towards:", "along:0,0",
          "along:0,0,1,2", "along:0,,1", "along:0,0,x", "along:0,0,1x", "along:nan,0,1",
          "towards:inf,0,0", "along:0,0,0", "along:+-1,0,0", "along:1e999,0,0"})
        EXPECT_THROW(static_cast<void>(parse_orient(bad)), InvalidInput) << bad;
}

TEST(SurfelsFromSamples, UnusableNormalsAreDroppedAndCounted)
{
    PointCloud cloud = sample_shape(Shape::Sphere, {.count = 2000, .seed = 23});
    cloud.colors.assign(cloud.size(), Color{1, 2, 3});
    cloud.normals[5] = Vec3f::Zero();
    cloud.normals[17] = Vec3f(std::numeric_limits<float>::quiet_NaN(), 0.0F, 1.0F);
    cloud.normals[900] = Vec3f(std::numeric_limits<float>::infinity(), 0.0F, 0.0F);
    const Vec3f after = cloud.positions[6];
    const SurfelsFromSamples out = surfels_from_samples(cloud);
    EXPECT_EQ(out.unoriented, 3U);
    ASSERT_EQ(out.surfels.size(), cloud.size() - 3);
    EXPECT_EQ(out.surfels.colors.size(), out.surfels.size());
    EXPECT_EQ(out.surfels.positions[5], after); // order kept, the bad one left out
    for (const Vec3f& n : out.surfels.normals)
        EXPECT_NEAR(n.norm(), 1.0F, 1e-5F);

    // Too few usable normals left for k.
    for (std::size_t i = 10; i < cloud.size(); ++i)
        cloud.normals[i] = Vec3f::Zero();
    EXPECT_THROW((void)surfels_from_samples(cloud), InvalidInput);
    EXPECT_THROW((void)surfels_from_samples(sample_shape(Shape::Sphere, {.count = 100}),
                                            {.radius_scale = 0.0}),
                 InvalidInput);
}

TEST(SurfelsFromMesh, VerticesThenAreaSamplesWithOutwardNormals)
{
    const TriMesh sphere = test::icosphere(3);
    const SurfelsFromMesh out =
        surfels_from_mesh(sphere, {.samples = 4000, .seed = 5, .radius_scale = 1.5});
    EXPECT_EQ(out.vertex_surfels, sphere.vertex_count());
    EXPECT_EQ(out.area_surfels, 4000U);
    ASSERT_EQ(out.surfels.size(), sphere.vertex_count() + 4000U);
    ASSERT_EQ(out.surfels.radii.size(), out.surfels.size());
    for (std::size_t v = 0; v < sphere.vertex_count(); ++v)
        EXPECT_EQ(out.surfels.positions[v], sphere.vertices.positions[v]);
    EXPECT_GT(outward_share(out.surfels, 6.0), 0.999);
    for (const float r : out.surfels.radii)
        EXPECT_GT(r, 0.0F);
    // Deterministic, and the default count is the vertex count.
    EXPECT_EQ(surfels_from_mesh(sphere, {.samples = 4000, .seed = 5}).surfels.positions,
              out.surfels.positions);
    EXPECT_EQ(surfels_from_mesh(sphere).area_surfels, sphere.vertex_count());
}

TEST(SurfelsFromMesh, RejectsWhatCarriesNoSurface)
{
    EXPECT_THROW((void)surfels_from_mesh(TriMesh{}), InvalidInput);
    TriMesh flat = test::icosphere(1);
    for (auto& p : flat.vertices.positions)
        p = Vec3f::Zero();
    EXPECT_THROW((void)surfels_from_mesh(flat), InvalidInput);
    // One triangle: 3 vertices and 3 samples are too few for k = 16.
    TriMesh one;
    one.vertices.positions = {Vec3f(0, 0, 0), Vec3f(1, 0, 0), Vec3f(0, 1, 0)};
    one.triangles = {{0, 1, 2}};
    EXPECT_THROW((void)surfels_from_mesh(one), InvalidInput);
    EXPECT_THROW((void)surfels_from_mesh(test::icosphere(2), {.k = 2}), InvalidInput);
}

} // namespace
} // namespace pointform
