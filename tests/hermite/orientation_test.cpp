// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/hermite/orientation.h"

#include "pointform/core/disjoint_sets.h"
#include "pointform/core/error.h"
#include "pointform/geometry/shapes.h"
#include "pointform/hermite/normals.h"
#include "pointform/hermite/surfels.h"
#include "pointform/io/io.h"
#include "pointform/spatial/kd_tree.h"

#include "support/test_support.h"
#include "support/thread_counts.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <numbers>
#include <numeric>
#include <random>
#include <set>
#include <string>
#include <tuple>
#include <utility>

namespace pointform {
namespace {

struct Prepared
{
    KnnTable table;
    Normals normals;
};

Prepared prepare(const PointCloud& cloud, std::size_t k)
{
    const KdTree tree(cloud.positions);
    Prepared p;
    p.table = knn_batch(tree, cloud.positions, k);
    p.normals = estimate_normals(cloud.positions, p.table);
    return p;
}

OrientedNormals orient(const PointCloud& cloud, std::size_t k, OrientationOptions options = {})
{
    const Prepared p = prepare(cloud, k);
    return orient_normals_mst(cloud.positions, p.normals.normals, p.table, options);
}

TEST(OrientNormalsMst, SphereOutward)
{
    const PointCloud sphere = sample_shape(Shape::Sphere, {.count = 20000, .seed = 1});
    const OrientedNormals result = orient(sphere, 16);
    EXPECT_EQ(result.components, 1U);
    EXPECT_TRUE(result.unoriented.empty());
    EXPECT_GE(test::oriented_fraction(result.normals, sphere.normals), 0.999);
}

TEST(OrientNormalsMst, TorusOutward)
{
    const PointCloud torus = sample_shape(Shape::Torus, {.count = 50000, .seed = 2});
    const OrientedNormals result = orient(torus, 16);
    EXPECT_EQ(result.components, 1U);
    EXPECT_GE(test::oriented_fraction(result.normals, torus.normals), 0.999);
}

TEST(OrientNormalsMst, TwoDisjointSpheresEachOutward)
{
    const PointCloud spheres = sample_shape(Shape::TwoSpheres, {.count = 30000, .seed = 3});
    const OrientedNormals result = orient(spheres, 16);
    EXPECT_EQ(result.components, 2U);
    // Check each sphere separately: a single-seed method orients only one of them.
    for (const double side : {-1.0, 1.0})
    {
        std::vector<Vec3f> est;
        std::vector<Vec3f> truth;
        for (std::size_t i = 0; i < spheres.size(); ++i)
            if (static_cast<double>(spheres.positions[i].x()) * side > 0.0)
            {
                est.push_back(result.normals[i]);
                truth.push_back(spheres.normals[i]);
            }
        EXPECT_GE(test::oriented_fraction(est, truth), 0.999) << "sphere at x = " << side;
    }
}

TEST(OrientNormalsMst, ThinPlateBothSidesOutward)
{
    // Sampling step ≈ 0.0145; k = 16 neighbourhoods reach about 0.033. A plate 0.04 thick (2.8
    // steps, 2% of its width) has its two sides in each other's 16-neighbourhoods at the rim and
    // in the 16-NN graph's reach, yet each side must come out facing away from the other.
    const double thickness = 0.04;
    const PointCloud plate =
        sample_shape(Shape::Plate, {.count = 40000, .seed = 4, .thickness = thickness});
    const OrientedNormals result = orient(plate, 16, {.k = 10});
    std::vector<Vec3f> est;
    std::vector<Vec3f> truth;
    for (std::size_t i = 0; i < plate.size(); ++i)
    {
        const Vec3f& p = plate.positions[i];
        // The two large faces, away from the rim where the normal turns through 90° in 2 steps.
        if (std::abs(p.x()) < 0.95F && std::abs(p.y()) < 0.95F)
        {
            est.push_back(result.normals[i]);
            truth.push_back(plate.normals[i]);
        }
    }
    EXPECT_GE(test::oriented_fraction(est, truth), 0.999);
}

TEST(OrientNormalsMst, ReflectionRuleOrientsPlateThinnerThanTheNeighbourhood)
{
    // Half a sampling step thick: Hoppe's rule crosses the wall and flips one side (about 50%).
    // Neighbourhood smoothing would average across a wall this thin (93%), so it is off here.
    const PointCloud plate =
        sample_shape(Shape::Plate, {.count = 40000, .seed = 4, .thickness = 0.01});
    const OrientedNormals result =
        orient(plate, 16, {.k = 10, .rule = OrientationRule::Reflection, .smoothing_sweeps = 0});
    std::vector<Vec3f> est;
    std::vector<Vec3f> truth;
    for (std::size_t i = 0; i < plate.size(); ++i)
        if (std::abs(plate.positions[i].x()) < 0.95F && std::abs(plate.positions[i].y()) < 0.95F)
        {
            est.push_back(result.normals[i]);
            truth.push_back(plate.normals[i]);
        }
    EXPECT_GE(test::oriented_fraction(est, truth), 0.99);
}

TEST(OrientNormalsMst, NoisySphereWithHoles)
{
    const PointCloud sphere =
        sample_shape(Shape::Sphere,
                     {.count = 40000, .seed = 5, .noise = 0.002, .holes = 10, .hole_radius = 0.06});
    ASSERT_LT(sphere.size(), 40000U);
    const OrientedNormals result = orient(sphere, 16);
    EXPECT_GE(test::oriented_fraction(result.normals, sphere.normals), 0.999);
}

/// Share of the samples of one face of a plate (true normal along ±z with the sign of `side`) whose
/// normal points the true way.
double face_oriented_fraction(const PointCloud& plate, std::span<const Vec3f> normals, float side)
{
    std::vector<Vec3f> est;
    std::vector<Vec3f> truth;
    for (std::size_t i = 0; i < plate.size(); ++i)
        if (plate.normals[i].z() * side > 0.9F)
        {
            est.push_back(normals[i]);
            truth.push_back(plate.normals[i]);
        }
    return test::oriented_fraction(est, truth);
}

TEST(OrientNormalsMst, NoisyThinPlateKeepsItsFacesApart)
{
    // Side 2, thickness T: the two faces are T apart, and Gaussian noise σ (a fraction of the
    // diagonal, 2.83) pushes some samples of each face far into the gap, where they are each
    // other's nearest neighbours. Their guide normals are parallel, so one such edge in a tree
    // passed one face's orientation to the other unturned: about half the samples came out
    // inside out (the whole bottom face) on every cloud below, the first one the benchmark's
    // noisy plate (RESULTS_reconstruct.md) at 60% of its density. Now neighbours off a sample's
    // sheet by more than 3 robust deviations pass no orientation.
    struct Case
    {
        double thickness;
        double noise;
        std::size_t holes;
        std::uint64_t seed;
    };
    for (const Case& c : {Case{0.05, 0.002, 8, 1},   // T = 8.8σ, holes through the plate
                          Case{0.04, 0.0015, 0, 2},  // T = 9.4σ
                          Case{0.06, 0.0025, 8, 2}}) // T = 8.5σ
    {
        const PointCloud plate = sample_shape(Shape::Plate, {.count = 60000,
                                                             .seed = c.seed,
                                                             .noise = c.noise,
                                                             .holes = c.holes,
                                                             .hole_radius = 0.04,
                                                             .thickness = c.thickness});
        const OrientedNormals result = orient(plate, 17, {.k = 10});
        EXPECT_EQ(result.components, 1U);
        EXPECT_GE(test::oriented_fraction(result.normals, plate.normals), 0.995)
            << "thickness " << c.thickness << ", noise " << c.noise;
        EXPECT_GE(face_oriented_fraction(plate, result.normals, 1.0F), 0.995);
        EXPECT_GE(face_oriented_fraction(plate, result.normals, -1.0F), 0.995);
    }
}

TEST(OrientNormalsMst, NoisyThinPlateSevenDeviationsThickKeepsItsFacesApart)
{
    // Faces 0.04 apart under noise σ = 0.002 of the diagonal (0.0057): 7σ, at the benchmark's
    // 100k samples. A sample pushed into the gap from one face and one pushed from the other lie
    // about 2σ inside each; the band of the one whose row holds the other is widened by the far
    // face, and the other's row does not hold it, so the edge was no jump and a tree carried one
    // face's orientation to the other unturned: the whole bottom face inside out on each seed
    // below. Each end's band now judges the other end where that end lies on its own sheet
    // (Guide::on_own_sheet()). At seeds 1 and 2 edges whose ends both lie within the other's band
    // still join the faces (99.5% of the bottom inside out), which no band can tell: the winding
    // check turns that face over once its band, 44% of the samples (the guides' wider scales
    // span both faces), has turned with it.
    for (const std::uint64_t seed : {1U, 2U, 3U, 5U})
    {
        const PointCloud plate = sample_shape(Shape::Plate, {.count = 100000,
                                                             .seed = seed,
                                                             .noise = 0.002,
                                                             .holes = 8,
                                                             .hole_radius = 0.04,
                                                             .thickness = 0.04});
        const OrientedNormals result = orient(plate, 17, {.k = 10});
        EXPECT_EQ(result.components, 1U);
        EXPECT_GE(face_oriented_fraction(plate, result.normals, 1.0F), 0.995) << "seed " << seed;
        EXPECT_GE(face_oriented_fraction(plate, result.normals, -1.0F), 0.995) << "seed " << seed;
    }
}

/// orient_normals_mst() of `plate` (17 neighbours, graph k = 10) at every thread count, with
/// more than one parallel block: expects the same normals and flips from each.
std::vector<OrientedNormals> oriented_at_thread_counts(const PointCloud& plate)
{
    const Prepared p = prepare(plate, 17);
    auto runs = test::at_thread_counts(
        [&] { return orient_normals_mst(plate.positions, p.normals.normals, p.table, {.k = 10}); },
        {.min_multi_block_loops = 2});
    for (const OrientedNormals& run : runs)
    {
        EXPECT_EQ(run.normals.size(), runs[0].normals.size());
        if (run.normals.size() == runs[0].normals.size())
        {
            EXPECT_EQ(std::memcmp(run.normals.data(), runs[0].normals.data(),
                                  run.normals.size() * sizeof(Vec3f)),
                      0);
        }
        EXPECT_EQ(run.flipped, runs[0].flipped);
    }
    return runs;
}

TEST(OrientNormalsMst, NoisyThinPlateTurnedWithItsBandIsTheSameWhateverTheThreadCount)
{
    // Seed 1 of the plate above: its bottom face turns over only once the band has turned with
    // it (the winding energy taken again, after the band's samples took their faces' planes).
    const PointCloud plate = sample_shape(Shape::Plate, {.count = 100000,
                                                         .seed = 1,
                                                         .noise = 0.002,
                                                         .holes = 8,
                                                         .hole_radius = 0.04,
                                                         .thickness = 0.04});
    const std::vector<OrientedNormals> runs = oriented_at_thread_counts(plate);
    ASSERT_FALSE(runs.empty());
    EXPECT_GE(face_oriented_fraction(plate, runs[0].normals, -1.0F), 0.995);
}

TEST(OrientNormalsMst, NoisyPlateThinnerThanItsNoiseFacesAwayFromItsMidplane)
{
    // Faces 0.02 apart under noise σ = 0.002 of the diagonal (0.0057): 3.5σ, the benchmark's
    // noisy thin plate at 100k samples, and 0.03 (5σ). Noise fills the gap: no band of a sample's
    // sheet tells the faces apart, every guide is parallel to every other, and the whole plate
    // came out with one orientation (a field of one sheet in the middle, half of it facing away
    // from the nearer face). The offsets over the widest guide neighbourhoods are two bands
    // there (kurtosis about 1.9 where one band scores 3), and the plate, undecided, faces away
    // from its midplane; samples that noise carried past the midplane face the other way.
    struct Case
    {
        double thickness;
        std::uint64_t seed;
        double share; // of each face's normals oriented
    };
    for (const Case& c : {Case{0.02, 1, 0.93}, Case{0.02, 5, 0.93}, Case{0.03, 1, 0.85}})
    {
        const PointCloud plate = sample_shape(Shape::Plate, {.count = 100000,
                                                             .seed = c.seed,
                                                             .noise = 0.002,
                                                             .holes = 8,
                                                             .hole_radius = 0.04,
                                                             .thickness = c.thickness});
        const SurfelResult result = compute_surfels(test::without_normals(plate));
        const std::vector<Vec3f>& normals = result.surfels.normals;
        EXPECT_GE(result.orientation.thin_parts, 1U) << "thickness " << c.thickness;
        EXPECT_GT(result.orientation.thin_part_turned, plate.size() / 4);
        EXPECT_GE(face_oriented_fraction(plate, normals, 1.0F), c.share)
            << "thickness " << c.thickness << ", seed " << c.seed;
        EXPECT_GE(face_oriented_fraction(plate, normals, -1.0F), c.share)
            << "thickness " << c.thickness << ", seed " << c.seed;
    }
}

/// compute_surfels() of a noisy plate `thickness` thick (100k samples, noise 0.2% of the
/// diagonal, 8 holes) at every thread count, with more than one parallel block: a thin part
/// faced, and the same normals from each.
void expect_faced_plate_at_thread_counts(double thickness, std::uint64_t seed)
{
    const PointCloud plate =
        test::without_normals(sample_shape(Shape::Plate, {.count = 100000,
                                                          .seed = seed,
                                                          .noise = 0.002,
                                                          .holes = 8,
                                                          .hole_radius = 0.04,
                                                          .thickness = thickness}));
    const auto runs = test::at_thread_counts([&] { return compute_surfels(plate); },
                                             {.min_multi_block_loops = 2});
    for (const SurfelResult& run : runs)
    {
        ASSERT_EQ(run.surfels.normals.size(), runs[0].surfels.normals.size());
        EXPECT_GE(run.orientation.thin_parts, 1U);
        EXPECT_EQ(run.orientation.thin_part_turned, runs[0].orientation.thin_part_turned);
        EXPECT_EQ(std::memcmp(run.surfels.normals.data(), runs[0].surfels.normals.data(),
                              run.surfels.normals.size() * sizeof(Vec3f)),
                  0);
    }
}

TEST(OrientNormalsMst, NoisyPlateThinnerThanItsNoiseIsTheSameWhateverTheThreadCount)
{
    expect_faced_plate_at_thread_counts(0.02, 1);
}

TEST(OrientNormalsMst, NoisyPlateSixDeviationsThickFacesAwayFromItsMidplane)
{
    // Faces 0.035 apart under noise σ = 0.002 of the diagonal: 6σ. The offsets over the widest
    // guide neighbourhoods are one band here (that neighbourhood, grown through the table, leans
    // to the sample's own face), and one region of the winding check holds both faces (joined by
    // samples that noise pushed into the gap): the whole bottom face came out inside out at each
    // seed below. Balls of nearest samples reach across the gap, and their heights dip in the
    // middle (ball_sides()): the plate, undecided, faces away from its midplane, and the samples
    // under holes in the other face, which no dipping ball holds, follow their own face.
    for (const std::uint64_t seed : {1U, 2U, 3U})
    {
        const PointCloud plate = sample_shape(Shape::Plate, {.count = 100000,
                                                             .seed = seed,
                                                             .noise = 0.002,
                                                             .holes = 8,
                                                             .hole_radius = 0.04,
                                                             .thickness = 0.035});
        const SurfelResult result = compute_surfels(test::without_normals(plate));
        const std::vector<Vec3f>& normals = result.surfels.normals;
        EXPECT_GE(result.orientation.thin_parts, 1U) << "seed " << seed;
        EXPECT_GE(face_oriented_fraction(plate, normals, 1.0F), 0.99) << "seed " << seed;
        EXPECT_GE(face_oriented_fraction(plate, normals, -1.0F), 0.99) << "seed " << seed;
    }
}

TEST(OrientNormalsMst, NoisyPlateSixDeviationsThickStandingOnItsEdgeFacesOutwards)
{
    // The plate above stood on its edge (turned 90° about x, its faces' normals along ±y): a
    // thin solid encloses too little volume for the flux test to judge, and the component's
    // root, its highest sample, lies on the rim, whose normal is about horizontal; turning the
    // root to face +z turned the faced plate inside out (98.7% of its normals facing away). A
    // component holding a faced thin part keeps the faces' outward normals.
    PointCloud plate = sample_shape(Shape::Plate, {.count = 100000,
                                                   .seed = 1,
                                                   .noise = 0.002,
                                                   .holes = 8,
                                                   .hole_radius = 0.04,
                                                   .thickness = 0.035});
    for (std::size_t i = 0; i < plate.size(); ++i)
    {
        const auto stand = [](const Vec3f& v) {
            return Vec3f(v.x(), -v.z(), v.y());
        };
        plate.positions[i] = stand(plate.positions[i]);
        plate.normals[i] = stand(plate.normals[i]);
    }
    const SurfelResult result = compute_surfels(test::without_normals(plate));
    const std::vector<Vec3f>& normals = result.surfels.normals;
    EXPECT_GE(result.orientation.thin_parts, 1U);
    std::size_t faces = 0;
    std::size_t outward = 0;
    for (std::size_t i = 0; i < plate.size(); ++i)
        if (std::abs(plate.normals[i].y()) > 0.9F)
        {
            ++faces;
            outward += normals[i].dot(plate.normals[i]) > 0.0F ? 1U : 0U;
        }
    EXPECT_GE(static_cast<double>(outward), 0.99 * static_cast<double>(faces));
}

TEST(OrientNormalsMst, NoisyPlateSixDeviationsThickIsTheSameWhateverTheThreadCount)
{
    expect_faced_plate_at_thread_counts(0.035, 2);
}

TEST(OrientNormalsMst, NoisyShapesOfOneSheetFindNoThinPart)
{
    // The same noise on shapes whose faces are far apart (a plate 0.05 thick, 8.8σ, whose
    // widest neighbourhoods keep to one face), with creases (the part, the cone's rim) and
    // curvature: their offsets are one band (kurtosis 2.5 to 3.2 at the 0.1st percentile), and no
    // normal turns.
    for (const Shape shape :
         {Shape::Plate, Shape::Part, Shape::Cone, Shape::Torus, Shape::Sphere, Shape::Blobby})
    {
        const PointCloud cloud = sample_shape(
            shape, {.count = 60000, .seed = 7, .noise = 0.002, .holes = 8, .hole_radius = 0.04});
        const SurfelResult result = compute_surfels(test::without_normals(cloud));
        EXPECT_EQ(result.orientation.thin_parts, 0U) << static_cast<int>(shape);
        EXPECT_EQ(result.orientation.thin_part_turned, 0U);
    }
}

TEST(OrientNormalsMst, NoisyThinPlateIsTheSameWhateverTheThreadCount)
{
    const PointCloud plate = sample_shape(
        Shape::Plate, {.count = 30000, .seed = 3, .noise = 0.002, .holes = 4, .hole_radius = 0.04});
    oriented_at_thread_counts(plate);
}

TEST(OrientNormalsMst, NoisyThinPlateStrayNormalsFollowTheirNeighbours)
{
    // Side 2, 60,000 samples about 0.0115 apart, noise σ = 0.0081 of the diagonal (0.023, twice
    // the sampling step, as on the benchmark's 1M-sample noisy plate) and faces 0.21 = 9σ apart.
    // Where every scale of a sample's neighbourhood is thick with noise its guide lies sideways
    // (a field through it tunnels across the plate): before the vote of the neighbours, 4% of the
    // faces' normals were more than 30° off, 1.8% more than 60°, and 0.3% inside out.
    for (const std::uint64_t seed : {1U, 2U})
    {
        const PointCloud plate = sample_shape(
            Shape::Plate, {.count = 60000, .seed = seed, .noise = 0.0081, .thickness = 0.21});
        const OrientedNormals result = orient(plate, 17, {.k = 10});
        std::size_t faces = 0;
        std::size_t off30 = 0;
        std::size_t off60 = 0;
        std::size_t inside_out = 0;
        for (std::size_t i = 0; i < plate.size(); ++i)
        {
            const Vec3f& p = plate.positions[i];
            if (std::abs(p.x()) >= 0.9F || std::abs(p.y()) >= 0.9F)
                continue; // the rims' sides are 0.21 wide: not the faces
            ++faces;
            const float c = result.normals[i].dot(plate.normals[i]);
            off30 += std::abs(c) < std::cos(std::numbers::pi_v<float> / 6.0F) ? 1U : 0U;
            off60 += std::abs(c) < 0.5F ? 1U : 0U;
            inside_out += c < 0.0F ? 1U : 0U;
        }
        const auto share = [&](std::size_t count) {
            return static_cast<double>(count) / static_cast<double>(faces);
        };
        EXPECT_LE(share(off30), 0.015) << "seed " << seed;
        EXPECT_LE(share(off60), 0.004) << "seed " << seed;
        EXPECT_LE(share(inside_out), 0.001) << "seed " << seed;
    }
}

/// Share of the samples whose estimated normal line is within 60° of the true normal (so that its
/// sign is not a matter of chance) that point outward.
double clear_oriented_fraction(std::span<const Vec3f> estimated, std::span<const Vec3f> truth)
{
    const float cos60 = 0.5F;
    std::size_t clear = 0;
    std::size_t right = 0;
    for (std::size_t i = 0; i < truth.size(); ++i)
    {
        const float c = estimated[i].dot(truth[i]);
        if (std::abs(c) < cos60 * estimated[i].norm() * truth[i].norm())
            continue;
        ++clear;
        right += c > 0.0F ? 1U : 0U;
    }
    return clear == 0 ? 0.0 : static_cast<double>(right) / static_cast<double>(clear);
}

TEST(OrientNormalsMst, NoisyTorusNoiseTwiceTheSamplingStep)
{
    // Torus area 4π²·1·0.35 ≈ 13.8: 30000 samples are 0.0215 apart; noise σ = 0.011 of the
    // diagonal (3.88) is 0.043, two sampling steps, as for the 1M-sample benchmark cloud. PCA over
    // 16 neighbours is then about 40° off, and a tangent-ish normal's sign is a coin toss for
    // propagation; but a normal within 60° of the true one has a clear sign, and with guide
    // normals at a coarser scale those come out outward, where plain propagation leaves about
    // 10% of them (scattered, and whole flipped patches) inward.
    const PointCloud torus = sample_shape(
        Shape::Torus, {.count = 30000, .seed = 9, .noise = 0.011, .holes = 4, .hole_radius = 0.05});
    const Prepared p = prepare(torus, 17);
    ASSERT_GT(test::line_angle_quantile_deg(p.normals.normals, torus.normals, 0.5), 25.0)
        << "the noise should leave the PCA normals poor";
    const OrientedNormals guided =
        orient_normals_mst(torus.positions, p.normals.normals, p.table, {.k = 10});
    EXPECT_EQ(guided.components, 1U);
    EXPECT_GE(clear_oriented_fraction(guided.normals, torus.normals), 0.995);
    EXPECT_GE(test::oriented_fraction(guided.normals, torus.normals), 0.95);
}

TEST(OrientNormalsMst, OpenSheetFacesUp)
{
    // A gently curved open height field (terrain-like): no enclosed volume, so the seed's +z wins.
    std::vector<Vec3f> points;
    for (int i = 0; i < 100; ++i)
        for (int j = 0; j < 100; ++j)
        {
            const float x = 0.02F * static_cast<float>(i) - 1.0F;
            const float y = 0.02F * static_cast<float>(j) - 1.0F;
            points.emplace_back(x, y, 0.1F * std::sin(3.0F * x) * std::cos(2.0F * y));
        }
    const KdTree tree(points);
    const KnnTable table = knn_batch(tree, points, 12);
    const Normals normals = estimate_normals(points, table);
    const OrientedNormals result = orient_normals_mst(points, normals.normals, table);
    for (const auto& n : result.normals)
        EXPECT_GT(n.z(), 0.0F);
}

/// A closed cone (apex `height` above a base disk of radius `radius`) with its true outward
/// normals: at the default proportions its rim is a crease sharper than a right angle (the base
/// meets the side at 76°, the normals turn by 104°).
PointCloud sampled_cone(std::size_t count, std::uint32_t seed, double height = 4.0,
                        double radius = 1.0)
{
    const double slant = std::hypot(height, radius);
    const double side_area = std::numbers::pi * radius * slant;
    const double base_area = std::numbers::pi * radius * radius;
    std::mt19937 random(seed);
    const auto uniform = [&random] {
        return static_cast<double>(random() >> 8U) * 0x1p-24;
    };
    PointCloud cone;
    for (std::size_t i = 0; i < count; ++i)
    {
        // Area-uniform: the distance from the apex (side) or the centre (base) as √u.
        const double t = std::sqrt(uniform());
        const double angle = 2.0 * std::numbers::pi * uniform();
        const double c = std::cos(angle);
        const double s = std::sin(angle);
        if (uniform() * (side_area + base_area) < side_area)
        {
            cone.positions.emplace_back(static_cast<float>(height * (1.0 - t)),
                                        static_cast<float>(radius * t * c),
                                        static_cast<float>(radius * t * s));
            cone.normals.emplace_back(static_cast<float>(radius / slant),
                                      static_cast<float>(height / slant * c),
                                      static_cast<float>(height / slant * s));
        }
        else
        {
            cone.positions.emplace_back(0.0F, static_cast<float>(radius * t * c),
                                        static_cast<float>(radius * t * s));
            cone.normals.emplace_back(-1.0F, 0.0F, 0.0F);
        }
    }
    return cone;
}

/// compute_surfels() of `shape`'s positions alone at each thread count (more than one parallel
/// block running), each run expected to give the first one's normals bit for bit.
std::vector<SurfelResult> surfels_at_thread_counts(const PointCloud& shape)
{
    PointCloud points;
    points.positions = shape.positions;
    auto runs = test::at_thread_counts([&] { return compute_surfels(points); },
                                       {.min_multi_block_loops = 4});
    for (const SurfelResult& result : runs)
    {
        EXPECT_EQ(result.surfels.normals.size(), shape.size());
        EXPECT_EQ(result.surfels.normals.size(), runs[0].surfels.normals.size());
        if (result.surfels.normals.size() == runs[0].surfels.normals.size())
        {
            EXPECT_EQ(std::memcmp(result.surfels.normals.data(), runs[0].surfels.normals.data(),
                                  result.surfels.normals.size() * sizeof(Vec3f)),
                      0);
        }
    }
    return runs;
}

/// Orients a sampled cone's positions through compute_surfels() at every thread count (the same
/// bytes at each) and expects one component, at least `oriented` of the samples outward and at
/// least `base_outward` of the base's (x = 0), which has more than `min_base` samples.
void expect_cone_outward(const PointCloud& cone, double oriented, double base_outward,
                         std::size_t min_base)
{
    for (const SurfelResult& result : surfels_at_thread_counts(cone))
    {
        ASSERT_EQ(result.surfels.normals.size(), cone.normals.size());
        EXPECT_EQ(result.orientation.components, 1U);
        EXPECT_GE(test::oriented_fraction(result.surfels.normals, cone.normals), oriented);
        std::size_t base = 0;
        std::size_t outward = 0;
        for (std::size_t i = 0; i < cone.positions.size(); ++i)
        {
            if (cone.positions[i].x() != 0.0F)
                continue;
            ++base;
            outward += result.surfels.normals[i].x() < 0.0F ? 1U : 0U;
        }
        ASSERT_GT(base, min_base);
        EXPECT_GE(static_cast<double>(outward), base_outward * static_cast<double>(base));
    }
}

/// Hoppe's rule cannot pass orientation across a crease sharper than a right angle: the normals
/// estimated near the cone's rim turn from the base's to the side's the short way round (by 76°,
/// as lines), so a chain of small steps through them hands the side the base's orientation
/// turned over. Through compute_surfels() (Morton order, so that a block of patches reaches
/// across the rim) a fifth of the base came out inside out at seed 4 (80.2% outward; of seeds
/// 1-40 the only one under 99%); samples whose neighbours' normals turn by more than a reliable
/// step now join no patch, and the edges between patches that turn that much vote by the
/// reflection rule (all 40 seeds at least 99.9% outward).
TEST(OrientNormalsMst, ACreaseSharperThanARightAngleKeepsBothFacesOutward)
{
    expect_cone_outward(sampled_cone(40000, 4), 0.995, 0.99, 5000);
}

/// A cone as wide as it is high: the base meets the side at 45° and the normals turn by 135°, so
/// that every estimated normal from the base's to the side's is within a reliable step of its
/// neighbours' and of both faces' (as lines), and no edge is creased by its own two ends. The
/// samples whose neighbours span the turn are creased, so are those next to them, and pairs of
/// samples across them vote by the tilt rule (across_vote()): at 9bfed08 the base came out
/// inside out on each of seeds 1-12 (58-59% of the samples outward), now about 99% (the rest
/// within the rim's blend). Seed 13 needs the ring next to the creased samples (a patch
/// chained round the rim without it). Of seeds 1-40 at heights 0.7, 0.9, 1 and 1.2 (rims of
/// 35°, 42°, 45° and 50°) all reach 97%; with the reflection rule across the creased samples
/// 16, 34, 39 and 39 did, and without the ring 22 at height 0.9 and 30 at height 1.
TEST(OrientNormalsMst, ACreaseAt45DegreesKeepsTheBaseOutward)
{
    for (const std::uint32_t seed : {1U, 2U, 13U})
        expect_cone_outward(sampled_cone(40000, seed, 1.0, 1.0), 0.98, 0.97, 10000);
}

/// The same crease under noise, where orientation follows the guide normals (guide_normals()):
/// near the rim every scale of a sample's neighbourhood spans the turn, so its guide is the axis
/// of the wedge between the two faces, and a chain of reliable steps through such guides joined
/// the base to the side inside out: 38% of the samples of `pointform sample cone` with noise 0.2%
/// of the diagonal came out wrong at 2db1240 (the whole base), on every seed tried. The band of
/// samples whose guide is thick at every scale now parts base and side, and the base turns over
/// because that brings the winding number of the oriented samples to about ½ on them; the rim's
/// samples then take the plane of a face (95% of the normals within 11° of the truth as lines
/// with the wedge's axes for normals at 9a33ba4, within 4.1° now).
TEST(OrientNormalsMst, ANoisyCreaseAt45DegreesKeepsTheBaseOutward)
{
    for (const std::uint64_t seed : {3U, 4U})
    {
        const PointCloud cone =
            sample_shape(Shape::Cone, {.count = 40000, .seed = seed, .noise = 0.002});
        for (const SurfelResult& result : surfels_at_thread_counts(cone))
        {
            ASSERT_EQ(result.surfels.normals.size(), cone.normals.size());
            EXPECT_EQ(result.orientation.components, 1U);
            EXPECT_GE(test::oriented_fraction(result.surfels.normals, cone.normals), 0.96)
                << "seed " << seed;
            EXPECT_LE(test::line_angle_quantile_deg(result.surfels.normals, cone.normals, 0.95),
                      6.0)
                << "seed " << seed;
            std::vector<Vec3f> base;
            std::vector<Vec3f> truth;
            for (std::size_t i = 0; i < cone.size(); ++i)
                if (cone.normals[i].z() < -0.9F)
                {
                    base.push_back(result.surfels.normals[i]);
                    truth.push_back(cone.normals[i]);
                }
            ASSERT_GT(base.size(), 10000U);
            EXPECT_GE(test::oriented_fraction(base, truth), 0.95) << "seed " << seed;
        }
    }
}

/// Light noise (0.1% of the diagonal, a third of a sampling step): the winding check turns the
/// side, and the samples that no round of planes reached (every edge of their row jumps between
/// sheets, outliers of the noise) kept their own sign against it: 44-45 single samples on the
/// smooth side of a 40k cone (162-164 of 100k) inside out, each a pit in the field, at 1c8f523.
TEST(OrientNormalsMst, OutliersOfLightNoiseFollowTheirTurnedSide)
{
    for (const std::uint64_t seed : {2U, 3U})
    {
        const PointCloud cone =
            sample_shape(Shape::Cone, {.count = 40000, .seed = seed, .noise = 0.001});
        for (const SurfelResult& result : surfels_at_thread_counts(cone))
        {
            ASSERT_EQ(result.surfels.normals.size(), cone.size());
            std::size_t side = 0;
            std::size_t inward = 0;
            for (std::size_t i = 0; i < cone.size(); ++i)
            {
                const Vec3f& p = cone.positions[i];
                // The smooth side, away from the rim and the apex.
                if (std::hypot(p.x(), p.y()) < 0.9F && p.z() > 0.1F && p.z() < 0.85F)
                {
                    ++side;
                    inward += result.surfels.normals[i].dot(cone.normals[i]) < 0.0F ? 1U : 0U;
                }
            }
            ASSERT_GT(side, 15000U);
            EXPECT_EQ(inward, 0U) << "seed " << seed;
        }
    }
}

/// The winding check sums its terms (each a ratio of lengths) in float: the same noisy cone in
/// units 10¹⁶ times smaller or larger, where a cube of a distance would underflow or
/// overflow float, still has its base turned outward.
TEST(OrientNormalsMst, TheWindingCheckTurnsTheSameAtAnyScale)
{
    const PointCloud cone = sample_shape(Shape::Cone, {.count = 40000, .seed = 3, .noise = 0.002});
    for (const float scale : {1e-16F, 1e16F})
    {
        PointCloud points;
        for (const Vec3f& p : cone.positions)
            points.positions.push_back(p * scale);
        const SurfelResult result = compute_surfels(points);
        ASSERT_EQ(result.surfels.normals.size(), cone.size());
        EXPECT_GE(test::oriented_fraction(result.surfels.normals, cone.normals), 0.96)
            << "scale " << scale;
    }
}

/// Noise of about two sampling steps (a cone of 40k samples with noise 0.63% of the diagonal;
/// 1M with 0.2% is the same): four rings of the guide left every scale of the faces about as thick
/// as the rim, no crease band formed and the base stayed inside out (41% of the samples wrong at
/// 14766a7, on both seeds). The guide now grows its rings until the faces are flat for their noise
/// (guide_target_flatness), and the band parts base and side.
TEST(OrientNormalsMst, TheGuideGrowsUntilANoisierCreaseShows)
{
    for (const std::uint64_t seed : {3U, 4U})
    {
        const PointCloud cone =
            sample_shape(Shape::Cone, {.count = 40000, .seed = seed, .noise = 0.0063});
        for (const SurfelResult& result : surfels_at_thread_counts(cone))
        {
            ASSERT_EQ(result.surfels.normals.size(), cone.normals.size());
            EXPECT_GE(test::oriented_fraction(result.surfels.normals, cone.normals), 0.95)
                << "seed " << seed;
        }
    }
}

/// The same noise on the bench's part, with holes: with the grown rings its 90° creases form a
/// band too, and the areas each sample stands for in the winding number, from its k-th
/// neighbour's distance, which noise of two steps puts farther off, made the winding number about
/// 0.8 on the rightly oriented samples, so that turning a face inside out brought the plain energy
/// Σ (w ∓ ½)² down by more than a fifth (22% of the samples wrong on both seeds). The energy now
/// takes the scale that fits w best and must not lose the plain one.
TEST(OrientNormalsMst, TheWindingCheckAllowsForTheNoiseInItsAreas)
{
    for (const std::uint64_t seed : {3U, 4U})
    {
        const PointCloud part = sample_shape(
            Shape::Part,
            {.count = 40000, .seed = seed, .noise = 0.008, .holes = 8, .hole_radius = 0.04});
        for (const SurfelResult& result : surfels_at_thread_counts(part))
        {
            ASSERT_EQ(result.surfels.normals.size(), part.normals.size());
            EXPECT_GE(test::oriented_fraction(result.surfels.normals, part.normals), 0.995)
                << "seed " << seed;
        }
    }
}

/// The winding check assumes a closed surface, on which the winding number is ½: on an open sheet
/// it is about 0 whatever the orientation, and turning regions of a noisy LiDAR terrain (open,
/// with roofs and walls: guided, and its band parts it into regions) lowered the energy enough to
/// turn 61% of its normals down (72% up at 2db1240, 15% with the check unbounded). The turns now
/// stand only where they leave a closed, consistently oriented surface (closed_energy).
TEST(OrientNormalsMst, TheWindingCheckLeavesAnOpenTerrainUp)
{
    PointCloud terrain = read_point_cloud(test::data_path("lidar/4_6_crop.las"));
    terrain.normals.clear();
    const SurfelResult result = compute_surfels(terrain);
    ASSERT_EQ(result.surfels.normals.size(), terrain.size());
    const auto up = std::count_if(result.surfels.normals.begin(), result.surfels.normals.end(),
                                  [](const Vec3f& n) { return n.z() > 0.0F; });
    EXPECT_GE(static_cast<double>(up), 0.7 * static_cast<double>(terrain.size()));
}

/// A closed prism whose cross-section is a triangle with a 30° corner at the origin (sides 4
/// long to x = 4, half-height h = 4 tan 15°), extruded along z over [0, 2], with its true
/// outward normals: a knife edge, where the two faces come closer than a neighbourhood.
PointCloud sampled_knife(std::size_t count, std::uint32_t seed)
{
    const double h = 4.0 * std::tan(std::numbers::pi / 12.0);
    const double side = std::hypot(4.0, h);
    const std::array<double, 5> area{2.0 * side, 2.0 * side, 4.0 * h, 4.0 * h, 4.0 * h};
    const double total = area[0] + area[1] + area[2] + area[3] + area[4];
    std::mt19937 random(seed);
    const auto uniform = [&random] {
        return static_cast<double>(random() >> 8U) * 0x1p-24;
    };
    PointCloud knife;
    for (std::size_t i = 0; i < count; ++i)
    {
        double pick = uniform() * total;
        std::size_t face = 0;
        while (face + 1 < area.size() && pick >= area[face])
            pick -= area[face++];
        const double u = uniform();
        const double v = uniform();
        const double z = 2.0 * v;
        if (face < 2) // the two long faces, from the edge at x = 0 to x = 4
        {
            const double sign = face == 0 ? 1.0 : -1.0;
            knife.positions.emplace_back(static_cast<float>(4.0 * u),
                                         static_cast<float>(sign * h * u), static_cast<float>(z));
            knife.normals.emplace_back(static_cast<float>(-h / side),
                                       static_cast<float>(sign * 4.0 / side), 0.0F);
        }
        else if (face == 2) // the back, x = 4
        {
            knife.positions.emplace_back(4.0F, static_cast<float>(h * (2.0 * u - 1.0)),
                                         static_cast<float>(z));
            knife.normals.emplace_back(1.0F, 0.0F, 0.0F);
        }
        else // the two triangular ends, z = 0 and z = 2
        {
            // Area-uniform in the triangle: x = 4 √u, y across at that x.
            const double x = 4.0 * std::sqrt(u);
            const double y = (2.0 * v - 1.0) * h * x / 4.0;
            const bool top = face == 4;
            knife.positions.emplace_back(static_cast<float>(x), static_cast<float>(y),
                                         top ? 2.0F : 0.0F);
            knife.normals.emplace_back(0.0F, 0.0F, top ? 1.0F : -1.0F);
        }
    }
    return knife;
}

/// At a knife edge the two faces lie within a neighbourhood of each other, as a thin plate's
/// do, and their estimated normals there are nearly parallel as lines: Hoppe's rule joined them
/// into one patch with one face turned over (84% of the samples outward; 92% with creased
/// samples kept out of patches). An edge whose ends Hoppe's rule and the reflection rule orient
/// differently now marks both ends as creased (they join no patch), and it votes by the
/// reflection rule. Within about a sampling step of the edge, where the two faces' samples
/// interleave, no rule can tell them apart: those are left out of the strict count.
TEST(OrientNormalsMst, AKnifeEdgeKeepsBothFacesOutward)
{
    const PointCloud knife = sampled_knife(40000, 3);
    PointCloud points;
    points.positions = knife.positions;
    const SurfelResult result = compute_surfels(points);
    EXPECT_EQ(result.orientation.components, 1U);
    EXPECT_GE(test::oriented_fraction(result.surfels.normals, knife.normals), 0.98);
    // Away from the edge (the faces 0.13 apart at x = 0.25, about six sampling steps).
    std::size_t away = 0;
    std::size_t outward = 0;
    for (std::size_t i = 0; i < knife.positions.size(); ++i)
    {
        if (knife.positions[i].x() < 0.25F)
            continue;
        ++away;
        outward += result.surfels.normals[i].dot(knife.normals[i]) > 0.0F ? 1U : 0U;
    }
    EXPECT_GE(static_cast<double>(outward), 0.999 * static_cast<double>(away));
}

/// A plate 0.02 thick (side 2, 100,000 samples: about two sampling steps): edges across it join
/// parallel normals steeply and pass nothing, and its rims are creases at which the faces turn
/// by 90° twice within a step, so the faces are oriented against each other only by votes
/// across creased samples. By the reflection rule a pair far apart along the plate votes for
/// the same orientation as Hoppe's rule (one face inside out, half the samples: seed 23 at
/// 9bfed08, seeds 22 and 23 at 2ac7d14); the tilt rule (across_vote()) orients both, but for
/// about 1% of the samples along the rims.
TEST(OrientNormalsMst, APlateTwoStepsThickKeepsBothFacesOutward)
{
    for (const std::uint32_t seed : {22U, 23U})
    {
        const PointCloud plate =
            sample_shape(Shape::Plate, {.count = 100000, .seed = seed, .thickness = 0.02});
        PointCloud points;
        points.positions = plate.positions;
        const SurfelResult result = compute_surfels(points);
        EXPECT_EQ(result.orientation.components, 1U);
        EXPECT_GE(test::oriented_fraction(result.surfels.normals, plate.normals), 0.98) << seed;
    }
}

TEST(OrientNormalsMst, DegenerateSamplesInheritAndAreCounted)
{
    PointCloud sphere = sample_shape(Shape::Sphere, {.count = 5000, .seed = 6});
    // 20 copies of one sample: the PCA neighbourhood of each copy is a single point.
    const Vec3f dup = sphere.positions[0];
    const Vec3f dup_normal = sphere.normals[0];
    for (int i = 0; i < 20; ++i)
    {
        sphere.positions.push_back(dup);
        sphere.normals.push_back(dup_normal);
    }
    const Prepared p = prepare(sphere, 16);
    EXPECT_GE(p.normals.degenerate.size(), 20U);
    const OrientedNormals result = orient_normals_mst(sphere.positions, p.normals.normals, p.table);
    EXPECT_GE(result.inherited, 20U);
    EXPECT_TRUE(result.unoriented.empty());
    EXPECT_GE(test::oriented_fraction(result.normals, sphere.normals), 0.999);
}

TEST(OrientNormalsMst, ComponentWithoutNormalsIsReportedUnoriented)
{
    PointCloud sphere = sample_shape(Shape::Sphere, {.count = 3000, .seed = 7});
    const std::size_t first_extra = sphere.size();
    // A far cluster of 20 coincident points: its own component, no usable normal.
    for (int i = 0; i < 20; ++i)
        sphere.positions.emplace_back(10.0F, 10.0F, 10.0F);
    const Prepared p = prepare(sphere, 16);
    const OrientedNormals result = orient_normals_mst(sphere.positions, p.normals.normals, p.table);
    EXPECT_EQ(result.components, 2U);
    ASSERT_EQ(result.unoriented.size(), 20U);
    EXPECT_EQ(result.unoriented.front(), first_extra);
    for (const auto i : result.unoriented)
        EXPECT_EQ(result.normals[i], Vec3f::Zero());
}

/// Kruskal over every edge of the symmetrised kNN graph, by brute force.
double brute_force_msf_weight(const PointCloud& cloud, const Prepared& p, std::size_t columns,
                              OrientationRule rule)
{
    const auto& n = p.normals.normals;
    std::set<std::pair<std::uint32_t, std::uint32_t>> edges;
    for (std::uint32_t i = 0; i < cloud.size(); ++i)
        for (const auto j : p.table.neighbors(i).first(columns))
            if (j != i)
                edges.emplace(std::min(i, j), std::max(i, j));
    std::vector<std::tuple<double, std::uint32_t, std::uint32_t>> weighted;
    for (const auto& [a, b] : edges)
    {
        Vec3d predicted = n[a].cast<double>();
        if (rule == OrientationRule::Reflection)
        {
            const Vec3d e = (cloud.positions[b] - cloud.positions[a]).cast<double>().normalized();
            predicted -= 2.0 * predicted.dot(e) * e;
        }
        const double w = 1.0 - std::abs(predicted.dot(n[b].cast<double>()));
        weighted.emplace_back(w, a, b);
    }
    std::sort(weighted.begin(), weighted.end());
    std::vector<std::uint32_t> parent(cloud.size());
    std::iota(parent.begin(), parent.end(), 0U);
    const auto find = [&](std::uint32_t x) {
        while (parent[x] != x)
            x = parent[x] = parent[parent[x]];
        return x;
    };
    double total = 0.0;
    for (const auto& [w, a, b] : weighted)
    {
        const auto ra = find(a);
        const auto rb = find(b);
        if (ra != rb)
        {
            parent[ra] = rb;
            total += w;
        }
    }
    return total;
}

TEST(RiemannianForest, WeightMatchesBruteForceKruskal)
{
    for (const auto rule : {OrientationRule::Hoppe, OrientationRule::Reflection})
        for (const std::uint64_t seed : {1, 2, 3})
        {
            const PointCloud cloud =
                sample_shape(Shape::TwoSpheres, {.count = 400, .seed = seed, .noise = 0.01});
            const Prepared p = prepare(cloud, 8);
            const RiemannianForest forest = riemannian_spanning_forest(
                cloud.positions, p.normals.normals, p.table, {.k = 6, .rule = rule});
            const double expected = brute_force_msf_weight(cloud, p, 6, rule);
            EXPECT_NEAR(forest.total_cost, expected, 1e-4 * std::max(1.0, expected))
                << "rule " << static_cast<int>(rule) << " seed " << seed;
            // A forest: N − components edges, every sample reached, parents before children.
            EXPECT_EQ(forest.order.size(), cloud.size());
            std::vector<bool> seen(cloud.size(), false);
            for (const auto v : forest.order)
            {
                EXPECT_TRUE(forest.parent[v] == v || seen[forest.parent[v]]);
                seen[v] = true;
            }
        }
}

/// The tree edges {parent, child} of a forest, each as (smaller, larger).
std::set<std::pair<std::uint32_t, std::uint32_t>> tree_edges_of(const RiemannianForest& forest)
{
    std::set<std::pair<std::uint32_t, std::uint32_t>> edges;
    for (std::uint32_t v = 0; v < forest.parent.size(); ++v)
        if (forest.parent[v] != v && forest.parent[v] != RiemannianForest::none)
            edges.emplace(std::min(v, forest.parent[v]), std::max(v, forest.parent[v]));
    return edges;
}

TEST(RiemannianForest, IsKruskalsInTheTablesEdgeOrderWhateverTheThreadCount)
{
    // A flat grid (every PCA normal the same: every cost 0, so only the tie order decides) and a
    // noisy torus, large enough for many parallel blocks.
    PointCloud grid;
    for (int y = 0; y < 150; ++y)
        for (int x = 0; x < 150; ++x)
            grid.positions.emplace_back(0.01F * static_cast<float>(x),
                                        0.01F * static_cast<float>(y), 0.0F);
    const PointCloud torus =
        sample_shape(Shape::Torus, {.count = 30000, .seed = 4, .noise = 0.002});
    for (const PointCloud* cloud : {static_cast<const PointCloud*>(&grid), &torus})
    {
        const Prepared p = prepare(*cloud, 11);
        const std::size_t columns = 10;
        // Kruskal over the edges in the table's order ({i, j} from row i unless row j lists i
        // and j < i), stably sorted by the float cost.
        const auto& n = p.normals.normals;
        std::vector<std::tuple<float, std::size_t, std::uint32_t, std::uint32_t>> edges;
        for (std::uint32_t i = 0; i < cloud->size(); ++i)
        {
            const auto row = p.table.neighbors(i).first(columns);
            for (std::size_t c = 0; c < columns; ++c)
            {
                const std::uint32_t j = row[c];
                const auto other = p.table.neighbors(j).first(columns);
                if (j == i || (j < i && std::find(other.begin(), other.end(), i) != other.end()))
                    continue;
                const float cost = std::max(0.0F, 1.0F - std::abs(n[i].dot(n[j])));
                edges.emplace_back(cost, edges.size(), i, j);
            }
        }
        std::sort(edges.begin(), edges.end());
        DisjointSets sets(cloud->size());
        std::set<std::pair<std::uint32_t, std::uint32_t>> expected;
        for (const auto& [cost, order, a, b] : edges)
            if (sets.unite(a, b))
                expected.emplace(std::min(a, b), std::max(a, b));

        const auto forests = test::at_thread_counts(
            [&] {
                return riemannian_spanning_forest(cloud->positions, n, p.table, {.k = columns});
            },
            {.min_multi_block_loops = 2});
        for (const RiemannianForest& forest : forests)
        {
            EXPECT_EQ(tree_edges_of(forest), expected);
            EXPECT_EQ(forest.parent, forests[0].parent);
            EXPECT_EQ(forest.order, forests[0].order);
            EXPECT_EQ(std::bit_cast<std::uint64_t>(forest.total_cost),
                      std::bit_cast<std::uint64_t>(forests[0].total_cost));
        }
    }
}

TEST(SimpleOrientations, TowardsAlongAndFlip)
{
    const PointCloud sphere = sample_shape(Shape::Sphere, {.count = 2000, .seed = 8});
    std::vector<Vec3f> scrambled = sphere.normals;
    for (std::size_t i = 0; i < scrambled.size(); i += 2)
        scrambled[i] = -scrambled[i];

    const OrientedNormals inward =
        orient_normals_towards(sphere.positions, scrambled, Vec3d::Zero());
    EXPECT_EQ(test::oriented_fraction(inward.normals, sphere.normals), 0.0);
    EXPECT_EQ(inward.flipped, sphere.size() - (sphere.size() + 1) / 2);

    const OrientedNormals up = orient_normals_along(scrambled, Vec3d::UnitZ());
    for (const auto& n : up.normals)
        EXPECT_GE(n.z(), 0.0F);
    EXPECT_THROW((void)orient_normals_along(scrambled, Vec3d::Zero()), InvalidInput);

    const OrientedNormals flipped = flip_normals(sphere.normals);
    EXPECT_EQ(test::oriented_fraction(flipped.normals, sphere.normals), 0.0);
    EXPECT_EQ(flipped.flipped, sphere.size());
}

} // namespace
} // namespace pointform

namespace pointform {
namespace {

/// Clean clouds are oriented by patches (OrientationOptions::patches) and must come out as
/// the whole graph orients them: creases (blobby, part), a plate 2.8 sampling steps thick, two
/// components, and the bunny's thin ears (before edges off the sheet passed no orientation, the
/// earlier subsample scheme turned one whole ear inside out: 294 of 8904 samples). The samples
/// are in random order here, so a block's patches are scattered (compute_surfels() sorts them
/// first): the scheme must hold either way. At most one sample in 4,000 may take the other
/// sign, and at most one in 4,000 more of them be against the truth: at the plate's corners,
/// where the normal turns through 90° twice within a step, and at the part's, the votes across
/// creased samples (across_vote()) turn a few samples otherwise than the whole graph (9 and 5
/// of 40,000, all against the truth), where they orient plates 2 sampling steps thick and
/// cones whose rims the whole graph and the earlier votes turned inside out.
TEST(OrientNormalsMst, PatchesOrientCleanCloudsAsTheWholeGraph)
{
    std::vector<std::pair<std::string, PointCloud>> clouds;
    clouds.emplace_back("blobby", sample_shape(Shape::Blobby, {.count = 40000, .seed = 11}));
    clouds.emplace_back("part", sample_shape(Shape::Part, {.count = 40000, .seed = 12}));
    clouds.emplace_back("plate",
                        sample_shape(Shape::Plate, {.count = 40000, .seed = 4, .thickness = 0.04}));
    clouds.emplace_back("two spheres",
                        sample_shape(Shape::TwoSpheres, {.count = 20000, .seed = 13}));
    clouds.emplace_back("bunny", read_point_cloud(test::data_path("meshes/bunny_uniform.off")));
    for (const auto& [name, cloud] : clouds)
    {
        const Prepared p = prepare(cloud, 17);
        const OrientedNormals whole = orient_normals_mst(cloud.positions, p.normals.normals,
                                                         p.table, {.k = 10, .patches = false});
        const auto runs = test::at_thread_counts(
            [&] {
                return orient_normals_mst(cloud.positions, p.normals.normals, p.table,
                                          {.k = 10, .patches = true});
            },
            {.min_multi_block_loops = 4});
        for (const OrientedNormals& sub : runs)
        {
            ASSERT_EQ(sub.normals.size(), whole.normals.size()) << name;
            std::size_t differ = 0;
            for (std::size_t i = 0; i < sub.normals.size(); ++i)
                differ += sub.normals[i].dot(whole.normals[i]) < 0.0F ? 1U : 0U;
            EXPECT_LE(differ, sub.normals.size() / 4000) << name;
            EXPECT_EQ(sub.components, whole.components) << name;
            if (!cloud.normals.empty())
            {
                EXPECT_GE(test::oriented_fraction(sub.normals, cloud.normals),
                          test::oriented_fraction(whole.normals, cloud.normals) - 2.5e-4)
                    << name;
            }
            EXPECT_EQ(std::memcmp(sub.normals.data(), runs[0].normals.data(),
                                  sub.normals.size() * sizeof(Vec3f)),
                      0)
                << name << ": not the same bytes at every thread count";
        }
    }
}

} // namespace
} // namespace pointform
