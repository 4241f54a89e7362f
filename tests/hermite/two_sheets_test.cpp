// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// The balls that find the two faces of a thin part a few noise deviations thick
// (src/hermite/two_sheets.h, ball_sides()): on analytic clouds, which samples they give a side,
// whether it is their face's, and that one sheet (curved, creased, with holes) gets none.

#include "two_sheets.h"

#include "pointform/geometry/shapes.h"

#include "support/thread_counts.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

namespace pointform::detail {
namespace {

/// ball_sides() of `cloud` with guides along `guide` (the true normals where it is empty).
std::vector<std::int8_t> sides_of(const PointCloud& cloud, std::vector<Vec3f> guide = {})
{
    std::vector<std::int8_t> sides(cloud.size(), 0);
    if (guide.empty())
        guide = cloud.normals;
    ball_sides(cloud.positions, guide, sides);
    return sides;
}

std::size_t sided(const std::vector<std::int8_t>& sides)
{
    std::size_t count = 0;
    for (const std::int8_t s : sides)
        count += s != 0 ? 1U : 0U;
    return count;
}

/// A noisy plate with 8 holes, as the bench's noisy+holes inputs.
PointCloud holed_plate(std::size_t count, std::uint64_t seed, double thickness)
{
    return sample_shape(Shape::Plate, {.count = count,
                                       .seed = seed,
                                       .noise = 0.002,
                                       .holes = 8,
                                       .hole_radius = 0.04,
                                       .thickness = thickness});
}

/// The true normals of `plate`, with every seventh on a face turned into the plane at its own
/// angle (as noise turns the guides grown between close faces).
std::vector<Vec3f> turned_guides(const PointCloud& plate)
{
    std::vector<Vec3f> guide = plate.normals;
    for (std::size_t i = 0; i < plate.size(); i += 7)
        if (std::abs(plate.normals[i].z()) > 0.9F)
        {
            const float angle = 2.39996F * static_cast<float>(i); // the golden angle
            guide[i] = Vec3f(std::cos(angle), std::sin(angle), 0.0F);
        }
    return guide;
}

/// Of the samples on the faces of `plate` away from its rim: how many have a side (`found`),
/// and how many of those the side of their own face, + on the top one (`right`).
struct FaceSides
{
    std::size_t faces = 0;
    std::size_t found = 0;
    std::size_t right = 0;
};

FaceSides face_sides(const PointCloud& plate, const std::vector<std::int8_t>& sides)
{
    FaceSides count;
    for (std::size_t i = 0; i < plate.size(); ++i)
    {
        const Vec3f& p = plate.positions[i];
        if (std::abs(plate.normals[i].z()) < 0.9F || std::abs(p.x()) > 0.9F ||
            std::abs(p.y()) > 0.9F)
            continue;
        ++count.faces;
        if (sides[i] == 0)
            continue;
        EXPECT_EQ(std::abs(sides[i]), ball_side);
        ++count.found;
        count.right += (sides[i] > 0) == (plate.normals[i].z() > 0.0F) ? 1U : 0U;
    }
    return count;
}

TEST(BallSides, PlateSixDeviationsThickHasItsFacesFound)
{
    // Faces 0.035 apart under noise σ = 0.002 of the diagonal (2.83): 6σ, so that noise fills
    // the gap and no neighbourhood grown through the neighbour table reaches the far face. The
    // guides are the faces' normals, one sign for both faces (+z): each sample's side is then
    // + on the top face and - on the bottom one.
    const PointCloud plate = sample_shape(
        Shape::Plate, {.count = 100000, .seed = 2, .noise = 0.002, .thickness = 0.035});
    const FaceSides count =
        face_sides(plate, sides_of(plate, std::vector<Vec3f>(plate.size(), Vec3f::UnitZ())));
    // Measured: 92% found (the balls along the rim hold its wall too), 99.4% of them right
    // (noise carries a few past the midplane).
    EXPECT_GE(static_cast<double>(count.found), 0.9 * static_cast<double>(count.faces));
    EXPECT_GE(static_cast<double>(count.right), 0.99 * static_cast<double>(count.found))
        << count.right << " of " << count.found;
}

TEST(BallSides, BallsOfALargerCloudAreAsWide)
{
    // 250k samples of the same plate: the balls are made of every second sample, so that they
    // reach across it as at 100k (the 256 nearest of all the samples reach two thirds as far),
    // and every sample within a counted ball's reach takes its side.
    const PointCloud plate = sample_shape(
        Shape::Plate, {.count = 250000, .seed = 2, .noise = 0.002, .thickness = 0.035});
    const FaceSides count =
        face_sides(plate, sides_of(plate, std::vector<Vec3f>(plate.size(), Vec3f::UnitZ())));
    // Measured: 88.7% found.
    EXPECT_GE(static_cast<double>(count.found), 0.85 * static_cast<double>(count.faces));
    EXPECT_GE(static_cast<double>(count.right), 0.99 * static_cast<double>(count.found));
}

TEST(BallSides, CloseFacesOfALargerCloudDipShallowlyButSurely)
{
    // 400k samples of a plate 0.02 thick under the same noise: faces 3.5σ apart, whose heights
    // dip only shallowly. The balls' heights are those of all the samples within their reach
    // (about 1,000 a ball), and balls that dip shallowly but surely count beside those that dip
    // deeply.
    const PointCloud plate =
        sample_shape(Shape::Plate, {.count = 400000, .seed = 2, .noise = 0.002, .thickness = 0.02});
    const FaceSides count =
        face_sides(plate, sides_of(plate, std::vector<Vec3f>(plate.size(), Vec3f::UnitZ())));
    // Measured: 86.6% found, 95.9% of them right (noise carries 4% past the midplane at 1.75σ).
    EXPECT_GE(static_cast<double>(count.found), 0.8 * static_cast<double>(count.faces));
    EXPECT_GE(static_cast<double>(count.right), 0.94 * static_cast<double>(count.found))
        << count.right << " of " << count.found;
}

TEST(BallSides, GuidesThatNoiseTurnedTakeTheAxisWhereFacesAreClose)
{
    // The same plate, with every seventh guide turned into the plane at its own angle (as noise
    // turns the guides grown between faces this close): those samples take the axis and their
    // band. On a plate 0.05 thick (8.7σ) a guide across the axis is kept, and so are the rim's
    // guides (across the rim, at the balls' edge).
    for (const float thickness : {0.02F, 0.05F})
    {
        const PointCloud plate = sample_shape(
            Shape::Plate, {.count = 400000, .seed = 4, .noise = 0.002, .thickness = thickness});
        std::vector<Vec3f> guide = turned_guides(plate);
        const std::vector<Vec3f> before = guide;
        std::vector<std::int8_t> sides(plate.size(), 0);
        ball_sides(plate.positions, guide, sides);
        std::size_t turned = 0;
        std::size_t taken = 0;
        std::size_t right = 0;
        std::size_t rim_changed = 0;
        std::size_t rim = 0;
        for (std::size_t i = 0; i < plate.size(); ++i)
        {
            const Vec3f& p = plate.positions[i];
            if (std::abs(plate.normals[i].z()) < 0.9F)
            {
                ++rim;
                rim_changed += guide[i] != before[i] ? 1U : 0U;
                continue;
            }
            if (i % 7 != 0 || std::abs(p.x()) > 0.9F || std::abs(p.y()) > 0.9F)
                continue;
            ++turned;
            if (std::abs(guide[i].z()) < 0.99F || sides[i] == 0)
                continue;
            ++taken;
            right += ((sides[i] > 0) == (guide[i].z() > 0.0F)) == (plate.normals[i].z() > 0.0F)
                         ? 1U
                         : 0U;
        }
        if (thickness < 0.03F)
        {
            // Measured: 87.2% taken, 95.8% of them right; 147 of the rim's 7,823 guides (1.9%)
            // taken too, where a rim 3.5σ wide is noise.
            EXPECT_GE(static_cast<double>(taken), 0.8 * static_cast<double>(turned));
            EXPECT_GE(static_cast<double>(right), 0.94 * static_cast<double>(taken));
            EXPECT_LE(static_cast<double>(rim_changed), 0.05 * static_cast<double>(rim));
        }
        else
        {
            EXPECT_EQ(taken, 0U);
            EXPECT_EQ(rim_changed, 0U);
        }
    }
}

TEST(BallSides, SideFollowsTheGuide)
{
    // The same plate with the bottom face's guides pointing down: every side is then + (each
    // sample lies away from the midplane along its guide).
    const PointCloud plate = sample_shape(
        Shape::Plate, {.count = 100000, .seed = 3, .noise = 0.002, .thickness = 0.035});
    const std::vector<std::int8_t> sides = sides_of(plate);
    std::size_t found = 0;
    std::size_t along = 0;
    for (std::size_t i = 0; i < plate.size(); ++i)
        if (sides[i] != 0 && std::abs(plate.normals[i].z()) > 0.9F)
        {
            ++found;
            along += sides[i] > 0 ? 1U : 0U;
        }
    EXPECT_GT(found, plate.size() / 2);
    EXPECT_GE(static_cast<double>(along), 0.99 * static_cast<double>(found));
}

TEST(BallSides, OneSheetHasNoSides)
{
    // The same noise on one sheet: curved (a sphere, whose cap heights are spread evenly, and a
    // torus), creased (the part, the cone's rim, the blobby's concave creases), a plate 0.1 thick
    // whose balls keep to one face, each with holes, which take the middle heights of a curved
    // cap away.
    for (const Shape shape :
         {Shape::Sphere, Shape::Torus, Shape::Part, Shape::Cone, Shape::Blobby, Shape::Plate})
    {
        const PointCloud cloud = sample_shape(shape, {.count = 100000,
                                                      .seed = 7,
                                                      .noise = 0.002,
                                                      .holes = 8,
                                                      .hole_radius = 0.04,
                                                      .thickness = 0.1});
        EXPECT_EQ(sided(sides_of(cloud)), 0U) << static_cast<int>(shape);
    }
}

TEST(BallSides, GuidesAcrossTheAxisTakeNoSide)
{
    // Guides lying in the plate's plane say nothing of which way its faces look.
    const PointCloud plate = sample_shape(
        Shape::Plate, {.count = 100000, .seed = 2, .noise = 0.002, .thickness = 0.035});
    EXPECT_EQ(sided(sides_of(plate, std::vector<Vec3f>(plate.size(), Vec3f::UnitX()))), 0U);
}

TEST(BallSides, SmallOrMismatchedInputIsLeftAlone)
{
    const PointCloud plate =
        sample_shape(Shape::Plate, {.count = 400, .seed = 2, .noise = 0.002, .thickness = 0.035});
    EXPECT_EQ(sided(sides_of(plate)), 0U); // fewer samples than two balls
    std::vector<std::int8_t> short_sides(3, 0);
    std::vector<Vec3f> guide = plate.normals;
    ball_sides(plate.positions, guide, short_sides);
    EXPECT_EQ(sided(short_sides), 0U);
}

TEST(BallSides, SameSidesWhateverTheThreadCount)
{
    const PointCloud plate = holed_plate(100000, 1, 0.035);
    const auto runs =
        test::at_thread_counts([&] { return sides_of(plate); }, {.min_multi_block_loops = 2});
    ASSERT_FALSE(runs.empty());
    EXPECT_GT(sided(runs[0]), plate.size() / 2);
    for (const auto& run : runs)
        EXPECT_EQ(run, runs[0]);
}

TEST(BallSides, SameSidesAndGuidesWhateverTheThreadCountAboveTheSubsample)
{
    // Balls found in the subsample and measured over all the samples, shallow dips counted
    // beside deep ones, and guides turned across the axis taking it: a plate 0.02 thick at 400k
    // with every seventh guide turned into the plane.
    const PointCloud plate = holed_plate(400000, 5, 0.02);
    const std::vector<Vec3f> turned = turned_guides(plate);
    const auto runs = test::at_thread_counts(
        [&] {
            std::vector<Vec3f> guide = turned;
            std::vector<std::int8_t> sides(plate.size(), 0);
            ball_sides(plate.positions, guide, sides);
            return std::make_pair(sides, guide);
        },
        {.min_multi_block_loops = 2});
    ASSERT_FALSE(runs.empty());
    EXPECT_GT(sided(runs[0].first), plate.size() / 2);
    EXPECT_NE(runs[0].second, turned); // some guides took their ball's axis
    for (const auto& run : runs)
    {
        EXPECT_EQ(run.first, runs[0].first);
        EXPECT_EQ(run.second, runs[0].second);
    }
}

} // namespace
} // namespace pointform::detail
