// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/implicit/point_field.h"

#include "pointform/core/error.h"
#include "pointform/core/parallel.h"
#include "pointform/geometry/shapes.h"
#include "pointform/hermite/surfels.h"
#include "pointform/spatial/spatial_sort.h"

#include "support/thread_counts.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <numeric>
#include <optional>
#include <random>
#include <vector>

namespace pointform {
namespace {

/// A unit sphere sampled exactly, with its true normals and a fixed radius.
PointCloud sphere_surfels(std::size_t count, float radius, Vec3d origin = Vec3d::Zero())
{
    PointCloud cloud = sample_shape(Shape::Sphere, {.count = count, .seed = 3});
    cloud.normals.resize(cloud.size());
    for (std::size_t i = 0; i < cloud.size(); ++i)
    {
        cloud.normals[i] = cloud.positions[i].normalized();
    }
    cloud.radii.assign(cloud.size(), radius);
    // Move the whole cloud far away, as georeferenced scans are.
    cloud.origin += origin;
    return cloud;
}

/// A square patch of the plane z = 0.5 sampled on a jittered grid, normals +z.
PointCloud plane_surfels(int side, double spacing, float radius)
{
    PointCloud cloud;
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> jitter(-0.3 * spacing, 0.3 * spacing);
    for (int i = 0; i < side; ++i)
    {
        for (int j = 0; j < side; ++j)
        {
            cloud.positions.emplace_back(static_cast<float>(i * spacing + jitter(rng)),
                                         static_cast<float>(j * spacing + jitter(rng)), 0.5F);
            cloud.normals.emplace_back(0.0F, 0.0F, 1.0F);
        }
    }
    cloud.radii.assign(cloud.size(), radius);
    return cloud;
}

TEST(PointField, RawFieldIsSignedDistanceToTheNearestTangentPlane)
{
    const PointCloud surfels = sphere_surfels(4000, 0.2F);
    const PointField field(surfels, {.fit = PlaneFit::Raw});
    for (std::size_t i = 0; i < surfels.size(); i += 97)
    {
        const Vec3d s = surfels.world(i);
        const Vec3d n = surfels.normals[i].cast<double>();
        for (const double d : {-0.004, 0.0, 0.003})
        {
            // Just above or below a sample, that sample is the nearest one.
            const FieldSample f = field.evaluate(s + d * n);
            ASSERT_TRUE(f.defined);
            EXPECT_NEAR(f.value, d, 1e-6);
            EXPECT_NEAR((f.gradient - n).norm(), 0.0, 1e-6);
        }
    }
}

TEST(PointField, MatchesTheTrueSignedDistanceNearTheSurface)
{
    // Exact samples of the unit sphere: near the surface every plane choice is within a small
    // fraction of the sample spacing of |p| − 1, and has its sign.
    const std::size_t count = 20000;
    const double spacing = std::sqrt(4.0 * std::numbers::pi / static_cast<double>(count));
    const PointCloud surfels = sphere_surfels(count, static_cast<float>(3.0 * spacing));
    std::mt19937_64 rng(17);
    std::normal_distribution<double> gauss;
    std::uniform_real_distribution<double> offset(-spacing, spacing);
    for (const PlaneFit fit : {PlaneFit::Raw, PlaneFit::Centroid, PlaneFit::Blend})
    {
        const PointField field(surfels, {.fit = fit});
        double worst = 0.0;
        for (int i = 0; i < 2000; ++i)
        {
            const Vec3d p =
                Vec3d(gauss(rng), gauss(rng), gauss(rng)).normalized() * (1.0 + offset(rng));
            const FieldSample f = field.evaluate(p);
            ASSERT_TRUE(f.defined);
            worst = std::max(worst, std::abs(f.value - (p.norm() - 1.0)));
            EXPECT_GT(f.gradient.dot(p.normalized()), 0.95);
        }
        RecordProperty(std::string("worst_") + std::string(to_string(fit)), std::to_string(worst));
        // Curvature: a plane through a sample ½ spacing away is off by about d²/2R.
        EXPECT_LT(worst, 0.1 * spacing) << to_string(fit);
    }
}

TEST(PointField, UndefinedBeyondTheRadiusButKeepsItsSign)
{
    const PointCloud surfels = sphere_surfels(4000, 0.1F);
    for (const PlaneFit fit : {PlaneFit::Raw, PlaneFit::Centroid, PlaneFit::Blend})
    {
        const PointField field(surfels, {.fit = fit});
        const FieldSample centre = field.evaluate(Vec3d::Zero());
        EXPECT_FALSE(centre.defined);
        EXPECT_LT(centre.value, -0.8); // deep inside: about minus the distance to the samples
        const FieldSample far = field.evaluate(Vec3d(3.0, 1.0, -2.0));
        EXPECT_FALSE(far.defined);
        EXPECT_GT(far.value, 2.0);
        const FieldSample near = field.evaluate(Vec3d(0.0, 0.0, 1.02));
        EXPECT_TRUE(near.defined);
        EXPECT_NEAR(near.value, 0.02, 0.01);
    }
}

TEST(PointField, BlendIsExactOnAPlaneAndItsGradientIsTheNormal)
{
    const PointCloud surfels = plane_surfels(40, 0.025, 0.08F);
    for (const PlaneFit fit : {PlaneFit::Centroid, PlaneFit::Blend})
    {
        const PointField field(surfels, {.fit = fit});
        std::mt19937_64 rng(11);
        std::uniform_real_distribution<double> xy(0.2, 0.8);
        std::uniform_real_distribution<double> z(0.44, 0.56);
        for (int i = 0; i < 200; ++i)
        {
            const Vec3d p(xy(rng), xy(rng), z(rng));
            const FieldSample f = field.evaluate(p);
            ASSERT_TRUE(f.defined);
            EXPECT_NEAR(f.value, p.z() - 0.5, 1e-5);
            EXPECT_NEAR((f.gradient - Vec3d::UnitZ()).norm(), 0.0, 1e-4);
        }
    }
}

TEST(PointField, BlendGradientMatchesFiniteDifferences)
{
    // A curved surface, so that the blended planes disagree and the weights matter.
    const PointCloud surfels = sphere_surfels(3000, 0.25F);
    const PointField field(surfels, {.fit = PlaneFit::Blend});
    std::mt19937_64 rng(5);
    std::normal_distribution<double> gauss;
    const double h = 1e-6;
    for (int i = 0; i < 100; ++i)
    {
        const Vec3d dir = Vec3d(gauss(rng), gauss(rng), gauss(rng)).normalized();
        const Vec3d p = dir * (1.0 + 0.02 * gauss(rng));
        const FieldSample f = field.evaluate(p);
        Vec3d numeric;
        for (int a = 0; a < 3; ++a)
        {
            const Vec3d e = Vec3d::Unit(a) * h;
            const FieldSample fp = field.evaluate(p + e);
            const FieldSample fm = field.evaluate(p - e);
            numeric[a] = (fp.value - fm.value) / (2.0 * h);
        }
        // The bandwidth's own derivative is left out, so allow a small difference.
        EXPECT_NEAR((f.gradient - numeric).norm(), 0.0, 0.05) << "at " << p.transpose();
        EXPECT_GT(f.gradient.dot(dir), 0.9);
    }
}

TEST(PointField, FarFromTheOriginKeepsPrecision)
{
    const PointCloud surfels = sphere_surfels(4000, 0.2F, Vec3d(6.0e5, 4.2e6, 120.0));
    const PointField field(surfels, {.fit = PlaneFit::Raw});
    const Vec3d s = surfels.world(10);
    const Vec3d n = surfels.normals[10].cast<double>();
    EXPECT_NEAR(field.evaluate(s + 0.001 * n).value, 0.001, 1e-6);
}

TEST(PointField, BatchEqualsSingleWhateverTheThreadCount)
{
    const PointCloud surfels = sphere_surfels(5000, 0.15F);
    const PointField field(surfels);
    std::vector<Vec3d> points;
    std::mt19937_64 rng(9);
    std::uniform_real_distribution<double> u(-1.3, 1.3);
    for (int i = 0; i < 5000; ++i)
    {
        points.emplace_back(u(rng), u(rng), u(rng));
    }
    const auto runs = test::at_thread_counts([&] {
        std::vector<FieldSample> out(points.size());
        field.evaluate(points, out);
        return out;
    });
    const std::vector<FieldSample>& one = runs[0];
    for (std::size_t i = 0; i < points.size(); ++i)
    {
        const FieldSample single = field.evaluate(points[i]);
        ASSERT_EQ(one[i].value, single.value);
        ASSERT_EQ(runs[1][i].value, single.value);
        ASSERT_EQ(runs[2][i].value, single.value);
        ASSERT_EQ(runs[1][i].defined, single.defined);
        ASSERT_EQ(runs[2][i].defined, single.defined);
        ASSERT_EQ(runs[1][i].gradient, single.gradient);
        ASSERT_EQ(runs[2][i].gradient, single.gradient);
    }
}

TEST(PointField, KeepsItsSamplesInMortonOrderAndIsTheSameForAnyOrder)
{
    const PointCloud surfels = sphere_surfels(6000, 0.15F);
    PointCloud shuffled = surfels;
    std::vector<std::uint32_t> order(surfels.size());
    std::iota(order.begin(), order.end(), 0U);
    std::shuffle(order.begin(), order.end(), std::mt19937(5));
    reorder_points(shuffled, order);
    ASSERT_NE(shuffled.positions, surfels.positions);
    const PointField a(surfels);
    const PointField b(shuffled);

    // Both hold the samples along the Morton curve: the same samples in the same order.
    const std::vector<std::uint32_t> again = spatial_order(a.surfels().positions);
    for (std::size_t j = 0; j < again.size(); ++j)
        ASSERT_EQ(again[j], j);
    EXPECT_EQ(a.surfels().positions, b.surfels().positions);
    EXPECT_EQ(a.surfels().normals, b.surfels().normals);
    EXPECT_EQ(a.surfels().radii, b.surfels().radii);

    std::vector<Vec3d> points;
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> u(-1.4, 1.4);
    for (int i = 0; i < 3000; ++i)
        points.emplace_back(u(rng), u(rng), u(rng));
    std::vector<FieldSample> va(points.size());
    std::vector<FieldSample> vb(points.size());
    a.evaluate(points, va);
    b.evaluate(points, vb);
    for (std::size_t i = 0; i < points.size(); ++i)
    {
        ASSERT_EQ(va[i].value, vb[i].value);
        ASSERT_EQ(va[i].gradient, vb[i].gradient);
        ASSERT_EQ(va[i].defined, vb[i].defined);
    }
    EXPECT_EQ(a.median_radius(), b.median_radius());
}

TEST(PointField, StraysAreNoSeeds)
{
    // A sphere's 8,000 samples and 150 points sprayed through the cube of side 6 around it,
    // with normals and radii estimated as for a scan.
    PointCloud points = sample_shape(Shape::Sphere, {.count = 8000, .seed = 3});
    points.normals.clear();
    std::mt19937 random(12);
    std::uniform_real_distribution<float> side(-3.0F, 3.0F);
    for (int i = 0; i < 150; ++i)
        points.positions.emplace_back(side(random), side(random), side(random));
    const PointField field(compute_surfels(points).surfels);
    const std::span<const std::uint32_t> strays = field.stray_samples();
    EXPECT_GE(strays.size(), 135U);
    EXPECT_LE(strays.size(), 150U);
    std::vector<Vec3d> seeds;
    field.append_seeds(seeds);
    ASSERT_EQ(seeds.size(), field.surfels().size() - strays.size());
    // The seeds are the other samples, in order.
    std::size_t next = 0;
    std::size_t seed = 0;
    for (std::size_t i = 0; i < field.surfels().size(); ++i)
    {
        if (next < strays.size() && strays[next] == i)
        {
            EXPECT_GT(std::abs(field.surfels().world(i).norm() - 1.0), 0.05)
                << "a sample of the sphere";
            ++next;
            continue;
        }
        ASSERT_EQ(seeds[seed++], field.surfels().world(i));
    }
    // A clean sphere has none.
    const PointField clean(sphere_surfels(6000, 0.15F));
    EXPECT_TRUE(clean.stray_samples().empty());
}

TEST(PointField, SuccessiveEvaluationsAreTheBatchsBitForBit)
{
    // One by one, an evaluation near the one before takes its neighbours from it when they are
    // provably the same (a projection's samples along its line, regula falsi's steps, where
    // the point grid turns them down and the kd-tree answers); the batch searches for every
    // point. Both must give the same bits: along lines through a part with creases (quadric
    // fits and their crease data) and over a sparse patch beside it (the grid's cells follow
    // the dense part, so the kd-tree answers there) in steps from 1e-6 to 0.05, with samples
    // duplicated (ties in every distance), through a hole and far outside, and alternating
    // with a second field on the same thread.
    PointCloud raw = sample_shape(Shape::Part, {.count = 12000, .seed = 5});
    PointCloud samples;
    samples.origin = raw.origin;
    for (std::size_t i = 0; i < raw.size(); ++i)
    {
        const Vec3d p = raw.origin + raw.positions[i].cast<double>();
        if ((p - Vec3d(0.5, 0.5, 0.0)).norm() < 0.25)
            continue; // a hole
        samples.positions.push_back(raw.positions[i]);
        if (i % 7 == 0)
            samples.positions.push_back(raw.positions[i]); // a duplicate
    }
    const Vec3d sparse_corner(-1.5, -1.5, -2.5);
    constexpr double sparse_spacing = 0.15;
    std::mt19937_64 jitter_rng(4);
    std::uniform_real_distribution<double> jitter(-0.2 * sparse_spacing, 0.2 * sparse_spacing);
    for (int a = 0; a < 20; ++a)
        for (int b = 0; b < 20; ++b)
            samples.positions.push_back((sparse_corner +
                                         Vec3d(a * sparse_spacing + jitter(jitter_rng),
                                               b * sparse_spacing + jitter(jitter_rng), 0.0) -
                                         samples.origin)
                                            .cast<float>());
    const PointField field(compute_surfels(samples).surfels);
    const PointField other(sphere_surfels(3000, 0.15F));
    std::vector<Vec3d> points;
    std::mt19937_64 rng(31);
    std::uniform_real_distribution<double> u(-1.4, 1.4);
    std::normal_distribution<double> gauss;
    for (const double step : {1e-6, 1e-4, 3e-3, 5e-2})
    {
        for (int line = 0; line < 40; ++line)
        {
            // Most lines from near a sample, the rest from anywhere around the part.
            const std::size_t near = (static_cast<std::size_t>(line) * 263) % samples.size();
            const Vec3d start =
                line % 4 != 0 ? Vec3d(samples.origin + samples.positions[near].cast<double>() +
                                      0.03 * Vec3d(gauss(rng), gauss(rng), gauss(rng)))
                              : Vec3d(u(rng), u(rng), u(rng));
            const Vec3d direction = Vec3d(gauss(rng), gauss(rng), gauss(rng)).normalized();
            for (int i = 0; i < 60; ++i)
                points.push_back(start + (i * step) * direction);
        }
    }
    // Over the sparse patch, near its plane.
    std::uniform_real_distribution<double> across(0.3, 2.5);
    for (const double step : {1e-6, 1e-4, 3e-3})
        for (int line = 0; line < 20; ++line)
        {
            const Vec3d start = sparse_corner + Vec3d(across(rng), across(rng), 0.05 * gauss(rng));
            const Vec3d direction = Vec3d(gauss(rng), gauss(rng), gauss(rng)).normalized();
            for (int i = 0; i < 60; ++i)
                points.push_back(start + (i * step) * direction);
        }
    // Back and forth on one short segment, as regula falsi closes a bracket.
    for (int i = 0; i < 200; ++i)
        points.push_back(Vec3d(0.3, -0.2, 0.1) +
                         (i % 2 == 0 ? 1e-3 : -1e-3) / (1 + i) * Vec3d(0.6, 0.0, 0.8));
    std::vector<FieldSample> batch(points.size());
    field.evaluate(points, batch);
    std::vector<FieldSample> other_batch(points.size());
    other.evaluate(points, other_batch);
    std::size_t defined = 0;
    for (std::size_t i = 0; i < points.size(); ++i)
    {
        const FieldSample single = field.evaluate(points[i]);
        ASSERT_EQ(single.defined, batch[i].defined) << i;
        ASSERT_EQ(single.value, batch[i].value) << i;
        ASSERT_EQ(single.gradient, batch[i].gradient) << i;
        defined += single.defined ? 1 : 0;
        if (i % 5 == 0)
        {
            const FieldSample sphere = other.evaluate(points[i]);
            ASSERT_EQ(sphere.value, other_batch[i].value) << i;
            ASSERT_EQ(sphere.gradient, other_batch[i].gradient) << i;
        }
    }
    // Most lines run near the surface, some far from it.
    EXPECT_GT(defined, points.size() / 3);
    EXPECT_LT(defined, points.size());
}

/// RMS of the field over points of the true unit sphere: how far the zero set lies from it.
double rms_on_true_sphere(const PointField& field)
{
    std::mt19937_64 rng(21);
    std::normal_distribution<double> gauss;
    double sum = 0.0;
    int count = 0;
    for (int i = 0; i < 4000; ++i)
    {
        const Vec3d p = Vec3d(gauss(rng), gauss(rng), gauss(rng)).normalized();
        const FieldSample f = field.evaluate(p);
        if (f.defined)
        {
            sum += f.value * f.value;
            ++count;
        }
    }
    EXPECT_GT(count, 3900);
    return std::sqrt(sum / count);
}

TEST(PointField, SmoothPlanesAreMoreAccurateOnNoisyScans)
{
    // Noise of σ = 0.1% of the diagonal (about a third of the sample spacing), through the
    // whole pipeline: PCA normals, MST orientation, automatic radii.
    const PointCloud noisy =
        sample_shape(Shape::Sphere, {.count = 30000, .seed = 4, .noise = 0.001});
    const PointCloud surfels = compute_surfels(noisy).surfels;
    const double sigma = 0.001 * 2.0 * std::sqrt(3.0);
    const double raw = rms_on_true_sphere(PointField(surfels, {.fit = PlaneFit::Raw}));
    const double centroid = rms_on_true_sphere(PointField(surfels, {.fit = PlaneFit::Centroid}));
    const double blend = rms_on_true_sphere(PointField(surfels, {.fit = PlaneFit::Blend}));
    const double quadric = rms_on_true_sphere(PointField(surfels, {.fit = PlaneFit::Quadric}));
    RecordProperty("rms_raw", std::to_string(raw));
    RecordProperty("rms_centroid", std::to_string(centroid));
    RecordProperty("rms_blend", std::to_string(blend));
    RecordProperty("rms_quadric", std::to_string(quadric));
    // The raw planes carry the noise; averaging over a neighbourhood removes most of it.
    EXPECT_GT(raw, 0.7 * sigma);
    EXPECT_LT(centroid, 0.6 * raw);
    EXPECT_LT(blend, 0.6 * raw);
    EXPECT_LE(blend, centroid * 1.05);
    // The quadrics' wider neighbourhood averages the noise as well as the blended planes do:
    // with the guide normals at the noise's own scale (orientation.h) both land within 1% of
    // each other (0.000968 and 0.000963 here; with the fine PCA normals the quadrics were ahead).
    // The narrow quadric (PointFieldOptions::quadric_narrow_k) replaces the wide one wherever
    // their heights differ by more than twice their noise, which noise alone does at a few
    // percent of the samples: 0.000983 here.
    EXPECT_LE(quadric, 1.03 * blend);
    const double wide_only =
        rms_on_true_sphere(PointField(surfels, {.fit = PlaneFit::Quadric, .quadric_narrow_k = 0}));
    EXPECT_LE(quadric, 1.03 * wide_only);
}

/// Mean |f| over points of the true surface (where f is defined): the field's own error.
double mean_on_truth(const PointField& field, const PointCloud& truth)
{
    double sum = 0.0;
    std::size_t count = 0;
    for (std::size_t i = 0; i < truth.size(); ++i)
    {
        const FieldSample f = field.evaluate(truth.world(i));
        if (f.defined)
        {
            sum += std::abs(f.value);
            ++count;
        }
    }
    EXPECT_GT(count, truth.size() * 99 / 100);
    return sum / static_cast<double>(count);
}

TEST(PointField, NarrowQuadricsFollowCleanCreases)
{
    // Exact samples of the union of six spheres, whose concave creases a quadric over 48
    // neighbours rounds off; the narrow fit, taken where the two disagree beyond the (here
    // tiny) noise, follows them. On a noisy sphere (above) it costs little.
    const PointCloud clean = sample_shape(Shape::Blobby, {.count = 30000, .seed = 3});
    const PointCloud surfels = compute_surfels(clean).surfels;
    const PointCloud truth = sample_shape(Shape::Blobby, {.count = 20000, .seed = 9});
    const double wide = mean_on_truth(
        PointField(surfels, {.fit = PlaneFit::Quadric, .quadric_narrow_k = 0}), truth);
    const double narrow = mean_on_truth(PointField(surfels, {.fit = PlaneFit::Quadric}), truth);
    RecordProperty("mean_wide", std::to_string(wide));
    RecordProperty("mean_narrow", std::to_string(narrow));
    EXPECT_LT(narrow, 0.9 * wide) << "narrow " << narrow << ", wide " << wide;
    EXPECT_THROW((void)PointField(surfels, {.quadric_narrow_k = 9}), InvalidInput);
    EXPECT_THROW((void)PointField(surfels, {.quadric_k = 20, .quadric_narrow_k = 21}),
                 InvalidInput);
}

TEST(PointField, CreaseFitsMeetTheFacesAtCreasesAndLeaveSmoothSurfacesAlone)
{
    // Raw points (normals estimated, so tilted toward the other face at creases) of the
    // machined part (convex and concave 90° edges) and of the union of six spheres (concave
    // creases of 82° to 95°): with each sample's surface fitted to its own face, the field on
    // the true surface is closer to zero (measured: 10% and 14% at 40k samples). On a smooth
    // sphere a few samples find outliers (the tails of their residuals), and the field on the
    // truth is within 1%. And the same values at any thread count.
    const auto raw_surfels = [](Shape shape, std::size_t count) {
        PointCloud raw = sample_shape(shape, {.count = count, .seed = 5});
        raw.normals.clear();
        return compute_surfels(raw).surfels;
    };
    const auto field_error = [&](Shape shape, bool crease_fit, std::size_t count = 40000) {
        const PointCloud truth = sample_shape(shape, {.count = 20000, .seed = 9});
        return mean_on_truth(PointField(raw_surfels(shape, count), {.crease_fit = crease_fit}),
                             truth);
    };
    for (const Shape shape : {Shape::Part, Shape::Blobby})
    {
        const double without = field_error(shape, false);
        const double with = field_error(shape, true);
        EXPECT_LT(with, 0.95 * without) << "shape " << static_cast<int>(shape);
    }
    EXPECT_LT(field_error(Shape::Sphere, true, 20000),
              1.01 * field_error(Shape::Sphere, false, 20000));

    const PointCloud surfels = raw_surfels(Shape::Part, 20000);
    const PointCloud truth = sample_shape(Shape::Part, {.count = 2000, .seed = 9});
    const auto runs = test::at_thread_counts([&] {
        const PointField field(surfels);
        std::vector<double> values;
        for (std::size_t i = 0; i < truth.size(); ++i)
            values.push_back(field.evaluate(truth.world(i)).value);
        return values;
    });
    EXPECT_EQ(runs[0], runs[1]);
    EXPECT_EQ(runs[0], runs[2]);
}

/// Turns each of `normals` to the side of `truth`'s (one per normal); returns how many it turned.
std::size_t turn_to_the_truth(std::vector<Vec3f>& normals, const std::vector<Vec3f>& truth)
{
    std::size_t flipped = 0;
    for (std::size_t i = 0; i < normals.size(); ++i)
    {
        if (normals[i].dot(truth[i]) < 0.0F)
        {
            normals[i] = -normals[i];
            ++flipped;
        }
    }
    return flipped;
}

/// The surfels of raw points (normals estimated), each normal turned to the side of `truth`'s
/// (the solid's outward normals, one per raw point): the orientation must have agreed with it
/// everywhere or nowhere. Unturned if the surfels are not one per point (the caller asserts it).
PointCloud oriented_as_the_solid(const PointCloud& raw, const std::vector<Vec3f>& truth,
                                 const SurfelOptions& options)
{
    PointCloud surfels = compute_surfels(raw, options).surfels;
    if (surfels.size() != truth.size())
        return surfels;
    const std::size_t flipped = turn_to_the_truth(surfels.normals, truth);
    EXPECT_TRUE(flipped == 0 || flipped == surfels.size()) << flipped << " flipped";
    return surfels;
}

TEST(PointField, ConcaveCreasesAreNotFilled)
{
    // The inner corner of an L (a floor z = 0 for x >= 0 and a wall x = 0 for z >= 0, the solid
    // behind both), sampled uniformly with normals estimated (tilted toward the other face next
    // to the crease) and oriented as the solid's. Along the bisector of the corner the field's
    // zero stays within a fraction of the sample spacing of the crease: the samples next to the
    // crease fit their own face (from their neighbours' normals, where the principal normal lies
    // between the faces) and count as the union of their face and the other's. Before, the
    // zero filled the groove by 0.39 spacings at the median and 0.79 at most here.
    constexpr int per_face = 10000;
    constexpr double side = 0.5;
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> u(0.0, side);
    PointCloud raw;
    std::vector<Vec3f> truth;
    for (int i = 0; i < per_face; ++i)
    {
        raw.positions.emplace_back(static_cast<float>(u(rng)), static_cast<float>(u(rng) - 0.25),
                                   0.0F);
        truth.emplace_back(0.0F, 0.0F, 1.0F);
        raw.positions.emplace_back(0.0F, static_cast<float>(u(rng) - 0.25),
                                   static_cast<float>(u(rng)));
        truth.emplace_back(1.0F, 0.0F, 0.0F);
    }
    const PointCloud surfels = oriented_as_the_solid(raw, truth, {});
    ASSERT_EQ(surfels.size(), raw.size());
    const PointField field(surfels);
    const double spacing = side / std::sqrt(static_cast<double>(per_face));
    const Vec3d bisector = Vec3d(1.0, 0.0, 1.0).normalized();
    std::vector<double> offsets;
    for (int k = -20; k <= 20; ++k)
    {
        const Vec3d on_crease(0.0, 0.005 * k, 0.0);
        // The crossing nearest the crease along the bisector, within 6 spacings.
        double best = std::numeric_limits<double>::infinity();
        double previous = field.evaluate(on_crease - 6.0 * spacing * bisector).value;
        for (int step = -119; step <= 120; ++step)
        {
            const double t0 = 0.05 * (step - 1) * spacing;
            const double t1 = 0.05 * step * spacing;
            const double value = field.evaluate(on_crease + t1 * bisector).value;
            if ((previous < 0.0) != (value < 0.0))
            {
                const double t = t0 + (t1 - t0) * previous / (previous - value);
                if (std::abs(t) < std::abs(best))
                    best = t;
            }
            previous = value;
        }
        ASSERT_TRUE(std::isfinite(best)) << "no zero near the crease at y = " << on_crease.y();
        offsets.push_back(best);
    }
    std::sort(offsets.begin(), offsets.end());
    EXPECT_LT(std::abs(offsets[offsets.size() / 2]), 0.3 * spacing);
    EXPECT_LT(std::max(std::abs(offsets.front()), std::abs(offsets.back())), 0.6 * spacing);
}

/// Two faces of an edge along y, each `width` wide and `length` long, sampled uniformly at
/// random at one sample per h² (the faces alternating): place(a, y, top) gives the sample a from
/// the edge on the top face or the other one, and its face's outward normal.
template <typename Place>
std::pair<PointCloud, std::vector<Vec3f>> two_faces_of_an_edge(double h, double width,
                                                               double length, std::uint64_t seed,
                                                               Place place)
{
    const auto count = static_cast<std::size_t>(2.0 * width * length / (h * h));
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> across(0.0, width);
    std::uniform_real_distribution<double> along(0.0, length);
    PointCloud raw;
    std::vector<Vec3f> truth;
    for (std::size_t i = 0; i < count; ++i)
    {
        const double a = across(rng);
        const double y = along(rng);
        const auto [position, normal] = place(a, y, i % 2 == 0);
        raw.positions.push_back(position);
        truth.push_back(normal);
    }
    return {std::move(raw), std::move(truth)};
}

/// Where the field's sign is wrong across an edge along y of the given length: probes every 2h
/// from 0.1 to 0.9 of the length, on a grid of h/2 from -6h to 3h in x and z; of those where the
/// field is defined and the truth t(x, z) (signed, outside positive) is farther than `skip` from
/// the surface, how many the field takes for the other side.
struct SignErrors
{
    std::size_t wrong = 0;
    std::size_t checked = 0;
};

template <typename Truth>
SignErrors sign_errors_across_an_edge(const PointField& field, double h, double length, double skip,
                                      Truth truth)
{
    SignErrors errors;
    for (double y = 0.1 * length; y < 0.9 * length; y += 2.0 * h)
        for (int i = -12; i <= 6; ++i)
            for (int k = -12; k <= 6; ++k)
            {
                const double x = 0.5 * h * i;
                const double z = 0.5 * h * k;
                const double t = truth(x, z);
                const FieldSample s = field.evaluate(Vec3d(x, y, z));
                if (std::abs(t) <= skip || !s.defined)
                    continue;
                ++errors.checked;
                errors.wrong += (s.value > 0.0) != (t > 0.0) ? 1U : 0U;
            }
    return errors;
}

TEST(PointField, NoPocketInsideTheSolidAtAConcaveCrease)
{
    // The clean blobby's raw points, as `pointform reconstruct` turns them into a field. Along
    // each crease circle where two of its balls meet (outside the others), lines along the two
    // faces' mean normal, through the crease and beside it, cross the field's zero once. One sample
    // of a face next to the crease that carried the blend, with no plane of the other face, made a
    // pocket of "outside" 0.006 thick inside the other ball (three crossings, at seed 31), and a
    // vertex of the mesh on it.
    PointCloud raw = sample_shape(Shape::Blobby, {.count = 100000, .seed = 31});
    raw.normals.clear();
    const PointField field(surfels_from_samples(raw).surfels);
    const auto balls = blobby_spheres();
    const auto inside_another = [&](const Vec3d& p, std::size_t a, std::size_t b) {
        for (std::size_t c = 0; c < balls.size(); ++c)
            if (c != a && c != b && (p - balls[c].center).norm() < balls[c].radius + 0.05)
                return true;
        return false;
    };
    std::size_t lines = 0;
    std::size_t pockets = 0;
    for (std::size_t a = 0; a < balls.size(); ++a)
        for (std::size_t b = a + 1; b < balls.size(); ++b)
        {
            const Vec3d axis = balls[b].center - balls[a].center;
            const double d = axis.norm();
            const double ra = balls[a].radius;
            const double rb = balls[b].radius;
            if (d >= ra + rb || d <= std::abs(ra - rb))
                continue;
            // The circle where the spheres meet: centre, radius, and two axes in its plane.
            const Vec3d e = axis / d;
            const double along = (d * d + ra * ra - rb * rb) / (2.0 * d);
            const Vec3d centre = balls[a].center + along * e;
            const double radius = std::sqrt(ra * ra - along * along);
            const Vec3d u = e.unitOrthogonal();
            const Vec3d v = e.cross(u);
            for (int k = 0; k < 720; ++k)
            {
                const double angle = 2.0 * std::numbers::pi * k / 720.0;
                const Vec3d on = centre + radius * (std::cos(angle) * u + std::sin(angle) * v);
                if (inside_another(on, a, b))
                    continue;
                const Vec3d n =
                    ((on - balls[a].center).normalized() + (on - balls[b].center).normalized())
                        .normalized();
                // Lines across the crease and beside it, 0.008 toward either ball.
                for (int side = -1; side <= 1; ++side)
                {
                    const Vec3d p = on + 0.008 * side * e;
                    int crossings = 0;
                    double before = field.evaluate(p - 0.04 * n).value;
                    for (int step = -39; step <= 40; ++step)
                    {
                        const double now = field.evaluate(p + 0.001 * step * n).value;
                        crossings += (before < 0.0) != (now < 0.0) ? 1 : 0;
                        before = now;
                    }
                    ++lines;
                    pockets += crossings != 1 ? 1U : 0U;
                }
            }
        }
    EXPECT_GT(lines, 1000U);
    EXPECT_EQ(pockets, 0U);
}

TEST(PointField, ConvexEdgeKeepsBothFacesUpToTheEdge)
{
    // The outer edge of the solid x < 0, z < 0: a top face z = 0 and a wall x = 0, each 12
    // spacings h wide and 500 long, sampled uniformly at random (one sample per h², the faces
    // alternating), normals estimated and oriented as the solid's. On both faces, 2 to 3 h from
    // the edge, the field is the distance to the face (0) to a quarter of h but at a few
    // places, where quadrics fitted across the edge (crease_fit off) round it off: 3 of the
    // 9,600 probes off by more than h/4 (the worst 0.28 h) against 59 (0.61 h). Across the
    // edge, where the field is defined and the true distance is over 0.3 h, its sign is the
    // truth's but at 5 of 59,714 points: a dent over a spacing deep into the edge at one place
    // and a bump half a spacing over the top face beside the edge at two others (random gaps of
    // the sampling, left for later work on the crease lines).
    constexpr double h = 0.01;
    constexpr double width = 12.0 * h;
    constexpr double length = 500.0 * h;
    const auto [raw, truth] =
        two_faces_of_an_edge(h, width, length, 11, [](double a, double y, bool top) {
            return std::pair(Vec3f(static_cast<float>(top ? -a : 0.0), static_cast<float>(y),
                                   static_cast<float>(top ? 0.0 : -a)),
                             top ? Vec3f(Vec3f::UnitZ()) : Vec3f(Vec3f::UnitX()));
        });
    const PointCloud surfels =
        oriented_as_the_solid(raw, truth, {.radius_scale = default_field_radius_scale});
    ASSERT_EQ(surfels.size(), raw.size());
    struct Off
    {
        std::size_t count = 0;
        std::size_t probes = 0;
        double worst = 0.0;
    };
    const auto on_faces = [&](const PointField& field) {
        Off off;
        for (double y = 0.1 * length; y < 0.9 * length; y += 0.25 * h)
            for (const double depth : {2.0 * h, 2.5 * h, 3.0 * h})
                for (const Vec3d& p : {Vec3d(0.0, y, -depth), Vec3d(-depth, y, 0.0)})
                {
                    const double value = std::abs(field.evaluate(p).value);
                    off.count += value > 0.25 * h ? 1U : 0U;
                    off.worst = std::max(off.worst, value);
                    ++off.probes;
                }
        return off;
    };
    const PointField field(surfels);
    const Off fitted = on_faces(field);
    const Off rounded = on_faces(PointField(surfels, {.crease_fit = false}));
    EXPECT_LT(static_cast<double>(fitted.count), 0.002 * static_cast<double>(fitted.probes))
        << fitted.count << " of " << fitted.probes;
    EXPECT_LT(fitted.worst, 0.5 * h);
    EXPECT_GT(rounded.count, 5 * fitted.count);
    const auto [wrong, checked] =
        sign_errors_across_an_edge(field, h, length, 0.3 * h, [](double x, double z) {
            return x < 0.0 && z < 0.0 ? std::max(x, z)
                                      : std::hypot(std::max(x, 0.0), std::max(z, 0.0));
        });
    EXPECT_GT(checked, 50000U);
    EXPECT_LE(wrong, checked / 5000) << wrong << " of " << checked;
}

TEST(PointField, WedgeEdgeIsACreaseNotTheTwoSidesOfAWall)
{
    // The edge of a 45° wedge, the solid z < 0, z > x: a top face z = 0 and a face z = x below
    // it, each 12 spacings h wide and 300 long, sampled uniformly at random, normals estimated
    // and oriented as the solid's. Their normals turn by 135°, more than a thin wall's sides
    // are allowed; taken for a wall, neither face bounded the other and their planes ran on
    // past the edge: the top face's over the lower face's side (inside above it, past the
    // edge) and the lower face's under the top's, sheets of inside beside the edge (the cone's
    // rim, `pointform sample cone`). Where the field is defined and the truth is over a spacing
    // from the surface, its sign is the truth's at all but 1 in 150 probes (100 of 21,687 wrong;
    // taken for a wall, 811 of 19,650, the field defined at fewer probes past the edge).
    constexpr double h = 0.01;
    constexpr double width = 12.0 * h;
    constexpr double length = 300.0 * h;
    const Vec3f lower = Vec3f(1.0F, 0.0F, -1.0F).normalized();
    // The lower face's samples at a uniform distance from the edge along it.
    const auto [raw, truth] =
        two_faces_of_an_edge(h, width, length, 5, [&](double a, double y, bool top) {
            const double b = a / std::numbers::sqrt2;
            return top ? std::pair(Vec3f(static_cast<float>(-a), static_cast<float>(y), 0.0F),
                                   Vec3f(Vec3f::UnitZ()))
                       : std::pair(Vec3f(static_cast<float>(-b), static_cast<float>(y),
                                         static_cast<float>(-b)),
                                   lower);
        });
    // Estimated normals, turned to the solid's side (the orientation of an open strip this
    // sharp is not this test's: some 300 of its 7,200 samples come out the other way).
    PointCloud surfels = compute_surfels(raw, {.radius_scale = default_field_radius_scale}).surfels;
    ASSERT_EQ(surfels.size(), raw.size());
    turn_to_the_truth(surfels.normals, truth);
    const PointField field(surfels);
    // The larger of the two faces' signed distances: the truth's sign, and outside no more
    // than its distance.
    const auto [wrong, checked] = sign_errors_across_an_edge(
        field, h, length, h,
        [](double x, double z) { return std::max(z, (x - z) / std::numbers::sqrt2); });
    EXPECT_GT(checked, 15000U);
    EXPECT_LE(wrong, checked / 150) << wrong << " of " << checked;
}

TEST(PointField, EndsSoonAfterARimAndSpansHolesWhereRadiiAreRaised)
{
    // A plane sampled on a jittered grid (step 0.02) with a round hole of radius 0.2 at c. The
    // field reaches a quarter of an automatic radius past the hole's rim (rim_reach), where the
    // paper's field reaches a whole radius and extrapolates the rim's surfaces into the hole.
    constexpr double step = 0.02;
    const Vec3d c(0.6, 0.6, 0.5);
    PointCloud samples;
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> jitter(-0.3 * step, 0.3 * step);
    for (int i = 0; i < 60; ++i)
        for (int j = 0; j < 60; ++j)
        {
            const Vec3d p(i * step + jitter(rng), j * step + jitter(rng), 0.5);
            if ((p - c).norm() >= 0.2)
                samples.positions.push_back(p.cast<float>());
        }
    const PointCloud surfels =
        compute_surfels(samples, {.radius_scale = default_field_radius_scale}).surfels;
    const PointField field(surfels);
    const PointField paper(surfels, {.rim_reach = 1.0});
    const double r = field.median_radius();
    ASSERT_GT(r, 2.0 * step);
    for (int a = 0; a < 36; ++a)
    {
        const double angle = a * std::numbers::pi / 18.0;
        const Vec3d direction(std::cos(angle), std::sin(angle), 0.0);
        const Vec3d on_rim = c + (0.2 + step) * direction;
        EXPECT_TRUE(field.evaluate(on_rim).defined) << "angle " << a * 10;
        EXPECT_LT(std::abs(field.evaluate(on_rim).value), 1e-3);
        const Vec3d into = c + (0.2 - 0.6 * r) * direction;
        EXPECT_FALSE(field.evaluate(into).defined) << "angle " << a * 10;
        EXPECT_TRUE(paper.evaluate(into).defined) << "angle " << a * 10;
    }
    EXPECT_FALSE(field.evaluate(c).defined);
    // Radii raised to span the hole (§4.1) still span it.
    PointCloud raised = surfels;
    for (float& radius : raised.radii)
        radius *= 4.0F;
    const PointField spanning(std::move(raised));
    EXPECT_TRUE(spanning.evaluate(c).defined);
    EXPECT_NEAR(spanning.evaluate(c).value, 0.0, 1e-3);
    EXPECT_THROW((void)PointField(surfels, {.rim_reach = 0.0}), InvalidInput);
    EXPECT_THROW((void)PointField(surfels, {.rim_reach = 1.5}), InvalidInput);
}

TEST(PointField, CreasesAreNotRims)
{
    // Outside the convex 90° edges of a machined part's block, diagonally, the field is defined
    // as far as the paper's is: the other face's samples balance a crease sample's neighbours.
    const PointCloud part = sample_shape(Shape::Part, {.count = 40000, .seed = 5});
    const PointCloud surfels =
        compute_surfels(part, {.radius_scale = default_field_radius_scale}).surfels;
    const PointField field(surfels);
    const PointField paper(surfels, {.rim_reach = 1.0});
    const double d = 0.5 * field.median_radius() / std::sqrt(2.0);
    std::size_t defined = 0;
    std::size_t paper_defined = 0;
    std::size_t total = 0;
    for (int i = -18; i <= 18; ++i)
    {
        const double x = 0.05 * i;
        for (const Vec3d& p : {Vec3d(x, 0.6 + d, 0.3 + d), Vec3d(x, -0.6 - d, 0.3 + d),
                               Vec3d(x, 0.6 + d, -0.3 - d), Vec3d(x, -0.6 - d, -0.3 - d)})
        {
            defined += field.evaluate(p).defined ? 1U : 0U;
            paper_defined += paper.evaluate(p).defined ? 1U : 0U;
            ++total;
        }
    }
    EXPECT_EQ(paper_defined, total);
    EXPECT_EQ(defined, total);
}

TEST(PointField, NoisyFitsDoNotTurnTheFieldInsideOut)
{
    // Tori of 100k samples with noise σ = 0.2% of the diagonal (about the sampling step), as
    // bench/peers' noisy torus. A few σ outside the true surface the field must be positive, as
    // far inside negative. A quadric fitted to 16 noisy neighbours can rise at 60-70° from the
    // sample's plane; taken as a narrow fit, it put bubbles of inside 0.03 above the tube (3 and
    // 4 points on the wrong side here before plausible fits were asked for).
    const PointCloud truth = sample_shape(Shape::Torus, {.count = 30000, .seed = 9});
    for (const auto& [seed, sigmas] : {std::pair{1U, 4.0}, std::pair{3U, 3.0}})
    {
        const PointCloud noisy =
            sample_shape(Shape::Torus, {.count = 100000, .seed = seed, .noise = 0.002});
        const PointField field(
            compute_surfels(noisy, {.radius_scale = default_field_radius_scale}).surfels);
        const double offset = sigmas * 0.002 * noisy.bounds().diagonal();
        std::size_t wrong = 0;
        for (std::size_t i = 0; i < truth.size(); ++i)
        {
            const Vec3d p = truth.world(i);
            const Vec3d axis = Vec3d(p.x(), p.y(), 0.0).normalized();
            const Vec3d n = (p - axis).normalized();
            wrong += field.evaluate(p + offset * n).value > 0.0 ? 0U : 1U;
            wrong += field.evaluate(p - offset * n).value < 0.0 ? 0U : 1U;
        }
        EXPECT_EQ(wrong, 0U) << "seed " << seed << ", " << sigmas << " σ off the torus";
    }
}

TEST(PointField, NoisyThinPlateIsInsideBetweenItsFacesOnly)
{
    // The whole pipeline on a plate of side 2 and thickness 0.05 with noise σ = 0.2% of the
    // diagonal (T = 8.8σ), as the benchmark's noisy plate: between the faces the field must be
    // negative, beyond each face positive. With one face's normals turned inward (orientation
    // passed from face to face across the gap), the field was inside below the bottom face too.
    const PointCloud plate =
        sample_shape(Shape::Plate, {.count = 60000, .seed = 1, .noise = 0.002});
    const PointField field(compute_surfels(plate).surfels);
    std::size_t wrong = 0;
    std::size_t total = 0;
    for (int i = -8; i <= 8; ++i)
    {
        for (int j = -8; j <= 8; ++j)
        {
            const double x = 0.1 * i;
            const double y = 0.1 * j;
            for (const double z : {-0.045, 0.0, 0.045})
            {
                const double value = field.evaluate(Vec3d(x, y, z)).value;
                const bool inside = z == 0.0;
                wrong += (value < 0.0) != inside ? 1U : 0U;
                ++total;
            }
        }
    }
    RecordProperty("wrong_sides", std::to_string(wrong));
    EXPECT_LE(static_cast<double>(wrong), 0.01 * static_cast<double>(total))
        << wrong << " of " << total << " points on the wrong side";
}

/// Points of the height field z = a sin(2πx/λ) sin(2πy/λ) over [0, 1]², on a jittered grid of
/// `side` × `side` (spacing 1 / side), lifted by noise of `sigma` along z, with the true normals.
PointCloud wavy_patch(int side, double amplitude, double wavelength, double sigma,
                      std::uint64_t seed)
{
    const double spacing = 1.0 / side;
    const double k = 2.0 * std::numbers::pi / wavelength;
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> jitter(-0.3 * spacing, 0.3 * spacing);
    std::normal_distribution<double> noise(0.0, sigma > 0.0 ? sigma : 1.0);
    PointCloud cloud;
    for (int i = 0; i < side; ++i)
        for (int j = 0; j < side; ++j)
        {
            const double x = (i + 0.5) * spacing + jitter(rng);
            const double y = (j + 0.5) * spacing + jitter(rng);
            const double z =
                amplitude * std::sin(k * x) * std::sin(k * y) + (sigma > 0.0 ? noise(rng) : 0.0);
            const Vec3d n(-amplitude * k * std::cos(k * x) * std::sin(k * y),
                          -amplitude * k * std::sin(k * x) * std::cos(k * y), 1.0);
            cloud.positions.emplace_back(static_cast<float>(x), static_cast<float>(y),
                                         static_cast<float>(z));
            cloud.normals.push_back(n.normalized().cast<float>());
        }
    return cloud;
}

/// Mean |f| over the points of `truth` at least `margin` from the patch's sides.
double mean_on_patch(const PointField& field, const PointCloud& truth, double margin)
{
    double sum = 0.0;
    std::size_t count = 0;
    for (std::size_t i = 0; i < truth.size(); ++i)
    {
        const Vec3d p = truth.world(i);
        if (std::min({p.x(), p.y(), 1.0 - p.x(), 1.0 - p.y()}) < margin)
            continue;
        const FieldSample f = field.evaluate(p);
        EXPECT_TRUE(f.defined) << p.transpose();
        sum += std::abs(f.value);
        ++count;
    }
    EXPECT_GT(count, truth.size() / 2);
    return sum / static_cast<double>(count);
}

TEST(PointField, NarrowQuadricsFollowFineDetailOfCleanScansAndNotNoise)
{
    // A wavy patch (wavelength 12 spacings, amplitude one spacing) that a quadric over 48
    // neighbours flattens and one over 16 follows. With noise of 3% of the spacing (a clean
    // real scan: the shipped bunny's fits leave residuals of about that), each sample's own
    // two fits differ by about what their noise explains, so the sample-by-sample test rarely
    // takes the narrow one; the differences of the neighbourhood together are far beyond
    // noise, and the narrow fits are taken. With noise of half a spacing the two fits differ
    // by noise alone and the wide one must stay.
    constexpr int side = 160;
    constexpr double spacing = 1.0 / side;
    const PointCloud truth = wavy_patch(120, spacing, 12.0 * spacing, 0.0, 9);
    const auto field_error = [&](double sigma, std::size_t narrow_k) {
        PointCloud samples = wavy_patch(side, spacing, 12.0 * spacing, sigma, 4);
        samples.radii.assign(samples.size(), static_cast<float>(3.0 * spacing));
        return mean_on_patch(PointField(samples, {.quadric_narrow_k = narrow_k}), truth,
                             6.0 * spacing);
    };
    const double clean_wide = field_error(0.03 * spacing, 0);
    const double clean = field_error(0.03 * spacing, 16);
    const double noisy_wide = field_error(0.5 * spacing, 0);
    const double noisy = field_error(0.5 * spacing, 16);
    RecordProperty("clean_wide", std::to_string(clean_wide / spacing));
    RecordProperty("clean", std::to_string(clean / spacing));
    RecordProperty("noisy_wide", std::to_string(noisy_wide / spacing));
    RecordProperty("noisy", std::to_string(noisy / spacing));
    // 0.018 against 0.069 spacings here; the sample-by-sample test alone gave 0.043. Under
    // noise the neighbourhood's test is not asked (narrow_pool_clean): the same field as the
    // sample-by-sample test, 0.1349 against the wide fit's 0.1350.
    EXPECT_LT(clean, 0.4 * clean_wide);
    EXPECT_LE(noisy, 1.03 * noisy_wide);
}

TEST(PointField, QuadricsFollowCurvatureThatPlanesCutThrough)
{
    // Exact samples of the unit sphere: the centroid planes sit inside the curved surface by
    // about ρ²/4R (ρ the neighbourhood's radius), the local quadrics follow it.
    const PointCloud exact = sample_shape(Shape::Sphere, {.count = 30000, .seed = 4});
    const PointCloud surfels = compute_surfels(exact).surfels;
    const double spacing = std::sqrt(4.0 * std::numbers::pi / 30000.0);
    const double blend = rms_on_true_sphere(PointField(surfels, {.fit = PlaneFit::Blend}));
    const double quadric = rms_on_true_sphere(PointField(surfels, {.fit = PlaneFit::Quadric}));
    RecordProperty("rms_blend", std::to_string(blend));
    RecordProperty("rms_quadric", std::to_string(quadric));
    EXPECT_GT(blend, 0.02 * spacing);
    EXPECT_LT(quadric, 1e-3 * spacing);
}

TEST(PointField, SparseAndDenseScansTogetherFitAsAlone)
{
    // A dense sphere sets the grids' cells; the samples of a sparse one far away find their
    // fits' neighbours beyond those cells (through the kd-tree). Each sample's neighbours are
    // on its own sphere, so the field near either sphere is the one it has alone, bit for bit.
    const PointCloud dense = sphere_surfels(20000, 0.05F);
    PointCloud sparse = sample_shape(Shape::Sphere, {.count = 1000, .seed = 5});
    sparse.normals.resize(sparse.size());
    sparse.radii.assign(sparse.size(), 0.4F);
    const Vec3f shift(6.0F, 0.0F, 0.0F);
    for (std::size_t i = 0; i < sparse.size(); ++i)
    {
        sparse.normals[i] = sparse.positions[i].normalized();
        sparse.positions[i] += shift;
    }
    PointCloud both = dense;
    both.positions.insert(both.positions.end(), sparse.positions.begin(), sparse.positions.end());
    both.normals.insert(both.normals.end(), sparse.normals.begin(), sparse.normals.end());
    both.radii.insert(both.radii.end(), sparse.radii.begin(), sparse.radii.end());
    const PointField together(both);
    const PointField dense_alone(dense);
    const PointField sparse_alone(sparse);
    std::mt19937_64 rng(8);
    std::normal_distribution<double> gauss;
    std::uniform_real_distribution<double> shell(0.97, 1.03);
    double worst = 0.0;
    for (int i = 0; i < 500; ++i)
    {
        const Vec3d p = Vec3d(gauss(rng), gauss(rng), gauss(rng)).normalized() * shell(rng);
        const FieldSample a = together.evaluate(p);
        const FieldSample b = dense_alone.evaluate(p);
        ASSERT_TRUE(a.defined);
        ASSERT_EQ(a.value, b.value);
        ASSERT_EQ(a.gradient, b.gradient);
        const Vec3d q = p + shift.cast<double>();
        const FieldSample c = together.evaluate(q);
        const FieldSample d = sparse_alone.evaluate(q);
        ASSERT_TRUE(c.defined);
        ASSERT_EQ(c.value, d.value);
        ASSERT_EQ(c.gradient, d.gradient);
        // On the true sphere the quadrics follow it to within a small part of the sampling
        // step (about 0.11) even so; a quadric over the cap of 48 neighbours (about 25° wide)
        // departs from it by about ρ⁴/8 ≈ 0.005.
        const double on_sphere = together.evaluate(p.normalized() + shift.cast<double>()).value;
        EXPECT_LT(std::abs(on_sphere), 0.01);
        worst = std::max(worst, std::abs(on_sphere));
    }
    RecordProperty("worst_on_sparse_sphere", std::to_string(worst));
}

TEST(PointField, RejectsSurfelsItCannotUse)
{
    PointCloud cloud = sphere_surfels(100, 0.2F);
    PointCloud no_normals = cloud;
    no_normals.normals.clear();
    EXPECT_THROW(PointField{no_normals}, InvalidInput);
    PointCloud no_radii = cloud;
    no_radii.radii.clear();
    EXPECT_THROW(PointField{no_radii}, InvalidInput);
    PointCloud zero_radius = cloud;
    zero_radius.radii[5] = 0.0F;
    EXPECT_THROW(PointField{zero_radius}, InvalidInput);
    PointCloud nan_position = cloud;
    nan_position.positions[3].x() = std::nanf("");
    EXPECT_THROW(PointField{nan_position}, InvalidInput);
    EXPECT_THROW(PointField{PointCloud{}}, InvalidInput);
    EXPECT_THROW(PointField(cloud, {.fit = PlaneFit::Blend, .blend_k = 1}), InvalidInput);
    EXPECT_THROW((void)parse_plane_fit("smooth"), InvalidInput);
    EXPECT_EQ(parse_plane_fit("centroid"), PlaneFit::Centroid);
}

/// Raw points of a plate 0.06 thick under noise of 0.0063 of the diagonal (0.018, 2 sampling
/// steps at 100k samples): its faces 3.4 noise deviations apart merge into one slab of samples
/// as thick as a fit's neighbourhood, and their normals into one sheet.
PointCloud noisy_slab_surfels()
{
    const PointCloud drawn = sample_shape(
        Shape::Plate, {.count = 100000, .seed = 2, .noise = 0.0063, .thickness = 0.06});
    PointCloud raw;
    raw.origin = drawn.origin;
    raw.positions = drawn.positions;
    return surfels_from_samples(raw).surfels;
}

/// The share of vertical lines through the slab's inside (400 of them, x in [x0, x1], |y| under
/// 0.8) whose field, where it is defined, changes sign exactly once.
double share_crossed_once(const PointField& field, const Vec3d& origin, double x0 = -0.8,
                          double x1 = 0.8)
{
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> along(x0, x1);
    std::uniform_real_distribution<double> across(-0.8, 0.8);
    constexpr int lines = 400;
    constexpr int steps = 161;
    int once = 0;
    std::vector<Vec3d> points(steps);
    std::vector<FieldSample> values(steps);
    for (int line = 0; line < lines; ++line)
    {
        const double x = along(rng);
        const double y = across(rng);
        for (int z = 0; z < steps; ++z)
            points[z] = Vec3d(x, y, -0.08 + 0.16 * z / (steps - 1)) - origin;
        field.evaluate(points, values);
        int changes = 0;
        std::optional<bool> last;
        for (const FieldSample& f : values)
        {
            if (!f.defined)
                continue;
            if (last && *last != (f.value > 0.0))
                ++changes;
            last = f.value > 0.0;
        }
        once += changes == 1 ? 1 : 0;
    }
    return static_cast<double>(once) / lines;
}

TEST(PointField, NoiseScaleFitsMakeOneSheetOfANoisySlab)
{
    // Fits over the 48 nearest (a ball about as wide as the slab is thick) follow their own
    // samples, and the blend of them is about zero through the whole slab: a sponge. Fitted
    // again over coarser subsamples until their noise is a fifth of their reach, they all find
    // the slab's middle.
    const PointCloud surfels = noisy_slab_surfels();
    const PointField fine(surfels, {});
    ASSERT_TRUE(fine.noisy());
    const PointField scaled(surfels, {.noise_scale = true});
    const double fine_once = share_crossed_once(fine, surfels.origin);
    const double scaled_once = share_crossed_once(scaled, surfels.origin);
    RecordProperty("fine_once", std::to_string(fine_once));
    RecordProperty("scaled_once", std::to_string(scaled_once));
    EXPECT_LT(fine_once, 0.8); // the input shows what the option is for
    EXPECT_GT(scaled_once, 0.95);
    // Only where asked: fits made again in the cells of x < 0 (cells of 0.1), not beyond.
    NoiseScaleRegion half{.size = 0.1};
    for (std::int32_t x = -12; x < 0; ++x)
        for (std::int32_t y = -12; y < 12; ++y)
            for (std::int32_t z = -2; z < 2; ++z)
                half.cells.push_back({x, y, z});
    std::sort(half.cells.begin(), half.cells.end());
    const PointField halved(surfels, {.noise_scale = true, .noise_scale_region = half});
    EXPECT_GT(share_crossed_once(halved, surfels.origin, -0.8, -0.1), 0.95);
    EXPECT_LT(share_crossed_once(halved, surfels.origin, 0.1, 0.8), 0.8);
    EXPECT_TRUE(half.contains(Vec3d(-0.05, 0.5, 0.01)));
    EXPECT_FALSE(half.contains(Vec3d(0.05, 0.5, 0.01)));
    EXPECT_FALSE(NoiseScaleRegion{}.contains(Vec3d::Zero()));
    // A clean cloud keeps its fits: the same field.
    const PointCloud sphere =
        surfels_from_samples(sample_shape(Shape::Sphere, {.count = 20000})).surfels;
    const PointField plain(sphere, {});
    const PointField asked(sphere, {.noise_scale = true});
    ASSERT_FALSE(plain.noisy());
    for (const Vec3d& p : {Vec3d(0.0, 0.0, 0.99), Vec3d(0.3, -0.5, 0.8), Vec3d(-1.01, 0.0, 0.0)})
        EXPECT_EQ(plain.evaluate(p).value, asked.evaluate(p).value);
}

TEST(PointField, NoiseScaleFitsAreTheSameForAnyThreadCount)
{
    // The refits run in blocks of the samples still too noisy, level by level: the same field
    // bit for bit at 1, 2 and 3 threads.
    const PointCloud surfels = noisy_slab_surfels();
    std::vector<Vec3d> points;
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> across(-0.9, 0.9);
    std::uniform_real_distribution<double> up(-0.06, 0.06);
    for (int i = 0; i < 2000; ++i)
        points.push_back(Vec3d(across(rng), across(rng), up(rng)) - surfels.origin);
    const auto runs = test::at_thread_counts([&] {
        const PointField field(surfels, {.noise_scale = true});
        std::vector<FieldSample> out(points.size());
        field.evaluate(points, out);
        return out;
    });
    for (std::size_t i = 0; i < points.size(); ++i)
        for (std::size_t r = 1; r < runs.size(); ++r)
        {
            ASSERT_EQ(runs[r][i].value, runs[0][i].value) << i;
            ASSERT_EQ(runs[r][i].defined, runs[0][i].defined) << i;
        }
}

} // namespace
} // namespace pointform
