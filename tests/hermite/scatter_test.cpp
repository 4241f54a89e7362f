// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/hermite/scatter.h"

#include "pointform/core/error.h"
#include "pointform/geometry/shapes.h"
#include "pointform/spatial/neighborhoods.h"

#include "support/thread_counts.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <numeric>
#include <random>
#include <utility>
#include <vector>

namespace pointform {
namespace {

/// Every sample a candidate.
std::vector<std::uint32_t> all_of(std::size_t n)
{
    std::vector<std::uint32_t> all(n);
    std::iota(all.begin(), all.end(), 0U);
    return all;
}

std::vector<std::uint32_t> strays_of(const std::vector<Vec3f>& positions)
{
    const KdTree tree(positions);
    return find_strays(tree, positions, scatter_test(tree, positions), all_of(positions.size()))
        .samples;
}

/// 10k samples of the unit sphere, then `sprayed` points spread evenly through the cube of
/// side 6 around it.
std::vector<Vec3f> sphere_with_spray(std::size_t sprayed, unsigned seed)
{
    std::vector<Vec3f> positions =
        sample_shape(Shape::Sphere, {.count = 10000, .seed = 2}).positions;
    std::mt19937 random(seed);
    std::uniform_real_distribution<float> side(-3.0F, 3.0F);
    for (std::size_t i = 0; i < sprayed; ++i)
        positions.emplace_back(side(random), side(random), side(random));
    return positions;
}

/// 25,000 points spread evenly over the unit square of the plane z = 0, then 1,000 over the
/// square beside it from x = `from` to 2 (25 times more sparsely over a unit side), every
/// 200th of those lifted `lift` off the plane.
std::vector<Vec3f> half_sparse_plane(float from, float lift)
{
    std::vector<Vec3f> plane;
    std::mt19937 random(7);
    std::uniform_real_distribution<float> unit(0.0F, 1.0F);
    for (int i = 0; i < 25000; ++i)
        plane.emplace_back(unit(random), unit(random), 0.0F);
    for (int i = 0; i < 1000; ++i)
        plane.emplace_back(from + (2.0F - from) * unit(random), unit(random),
                           i % 200 == 0 ? lift : 0.0F);
    return plane;
}

TEST(Scatter, ASprayIsStrayAndTheSurfaceIsNot)
{
    for (const unsigned seed : {1U, 2U, 3U})
    {
        const std::vector<Vec3f> positions = sphere_with_spray(200, seed);
        const std::vector<std::uint32_t> strays = strays_of(positions);
        EXPECT_TRUE(std::is_sorted(strays.begin(), strays.end()));
        // None of the sphere's; nearly all of the spray (a few lie beside the sphere, their
        // nearest its samples, a reach like theirs).
        EXPECT_TRUE(
            std::all_of(strays.begin(), strays.end(), [](std::uint32_t i) { return i >= 10000; }))
            << "seed " << seed;
        EXPECT_GE(strays.size(), 180U) << "seed " << seed;
    }
}

TEST(Scatter, StraysBesideASurfaceAreFound)
{
    // 60 returns 0.4-0.8 off the sphere (its median reach about 0.08): their nearest are the
    // sphere's, on a sheet, but they stand off it. (Nearer ones reach no farther than the
    // limit: the field's fit takes them.)
    std::vector<Vec3f> positions =
        sample_shape(Shape::Sphere, {.count = 10000, .seed = 2}).positions;
    std::mt19937 random(4);
    std::normal_distribution<float> gauss;
    std::uniform_real_distribution<float> off(1.4F, 1.8F);
    for (int i = 0; i < 60; ++i)
        positions.push_back(Vec3f(gauss(random), gauss(random), gauss(random)).normalized() *
                            off(random));
    const std::vector<std::uint32_t> strays = strays_of(positions);
    EXPECT_TRUE(
        std::all_of(strays.begin(), strays.end(), [](std::uint32_t i) { return i >= 10000; }));
    EXPECT_EQ(strays.size(), 60U);
}

TEST(Scatter, SparseSurfacesAreNotStray)
{
    // A second sphere 3.5 away sampled 40 times more sparsely (250 points: reach six times the
    // median, but on a sheet, among its own), and a plane whose far half is sampled 25 times
    // more sparsely than its near half: no strays.
    std::vector<Vec3f> spheres = sample_shape(Shape::Sphere, {.count = 10000, .seed = 2}).positions;
    for (const Vec3f& p : sample_shape(Shape::Sphere, {.count = 250, .seed = 5}).positions)
        spheres.push_back(p + Vec3f(3.5F, 0.0F, 0.0F));
    EXPECT_TRUE(strays_of(spheres).empty());

    EXPECT_TRUE(strays_of(half_sparse_plane(1.0F, 0.0F)).empty());
}

TEST(Scatter, SprayedAreTheStraysOfGroupsMostlyStray)
{
    // The spray's strays are nearly all in sprays (groups mostly strays).
    const std::vector<Vec3f> positions = sphere_with_spray(200, 1);
    const KdTree tree(positions);
    const Strays spray =
        find_strays(tree, positions, scatter_test(tree, positions), all_of(positions.size()));
    EXPECT_GE(spray.sprayed.size(), 180U);
    EXPECT_TRUE(std::includes(spray.samples.begin(), spray.samples.end(), spray.sprayed.begin(),
                              spray.sprayed.end()));
    // A plane whose far half is sampled 25 times more sparsely (its reach five times the
    // median), with five of that half's samples lifted 0.05 off it (about 0.7 of their reach):
    // those five are strays (and a few beside them), but among a thousand samples past the
    // limit that are not, so in no spray.
    const std::vector<Vec3f> plane = half_sparse_plane(1.1F, 0.05F);
    const KdTree plane_tree(plane);
    const Strays lifted =
        find_strays(plane_tree, plane, scatter_test(plane_tree, plane), all_of(plane.size()));
    // (A few beside them lean toward them: their neighbours' plane tilts.)
    std::size_t lifted_strays = 0;
    for (const std::uint32_t i : lifted.samples)
        lifted_strays += plane[i].z() == 0.05F ? 1 : 0;
    EXPECT_EQ(lifted_strays, 5U);
    EXPECT_LE(lifted.samples.size(), 20U);
    EXPECT_TRUE(lifted.sprayed.empty());
}

TEST(Scatter, SmallCloudsAndTheLimit)
{
    // Fewer than 17 samples: no neighbourhood to judge, no strays.
    const std::vector<Vec3f> few = {Vec3f(0, 0, 0), Vec3f(1, 0, 0), Vec3f(0, 5, 0)};
    const KdTree tree(few);
    EXPECT_TRUE(
        find_strays(tree, few, scatter_test(tree, few), all_of(few.size())).samples.empty());
    // The limit is scattered_reach² times the median squared reach.
    std::vector<Vec3f> grid;
    for (int x = 0; x < 20; ++x)
        for (int y = 0; y < 20; ++y)
            grid.emplace_back(static_cast<float>(x), static_cast<float>(y), 0.0F);
    const KdTree grid_tree(grid);
    const ScatterTest test = scatter_test(grid_tree, grid);
    // Inside a unit grid the 16th nearest other point is √5 away (4 at 1, 4 at √2, 4 at 2, then
    // 8 at √5), and most points are inside.
    EXPECT_NEAR(test.limit2, scattered_reach * scattered_reach * 5.0, 1e-3);
    EXPECT_TRUE(strays_of(grid).empty());
    // A cloud of copies (each place 20 times) has no spacing to judge by: no strays.
    std::vector<Vec3f> copies;
    for (const Vec3f& p : grid)
        for (int c = 0; c < 20; ++c)
            copies.push_back(p);
    copies.emplace_back(100.0F, 100.0F, 100.0F);
    const KdTree copies_tree(copies);
    EXPECT_TRUE(std::isinf(scatter_test(copies_tree, copies).limit2));
    EXPECT_TRUE(strays_of(copies).empty());
    // Only candidates are tested.
    const std::vector<Vec3f> sprayed = sphere_with_spray(200, 1);
    const KdTree sprayed_tree(sprayed);
    EXPECT_TRUE(find_strays(sprayed_tree, sprayed, scatter_test(sprayed_tree, sprayed), {})
                    .samples.empty());
}

TEST(Scatter, TheSameStraysWhateverTheThreadCount)
{
    const std::vector<Vec3f> positions = sphere_with_spray(2000, 6);
    const auto runs = test::at_thread_counts([&] { return strays_of(positions); });
    EXPECT_GT(runs[0].size(), 1000U);
    for (std::size_t i = 1; i < runs.size(); ++i)
        EXPECT_EQ(runs[i], runs[0]) << i + 1 << " threads";
}

std::vector<std::uint32_t> off_surface_of(const std::vector<Vec3f>& positions)
{
    const KdTree tree(positions);
    return off_surface_samples(positions, knn_batch(tree, positions, 17));
}

TEST(OffSurface, StraysNearASurfaceAreFound)
{
    // 20k samples of the unit sphere (spacing about 0.025) and 50 returns 4-8 spacings off it,
    // as near as a reach or two: no longer than a surface sample's reach, so no scatter test
    // takes them; they stand off the plane of their nearest.
    std::vector<Vec3f> positions =
        sample_shape(Shape::Sphere, {.count = 20000, .seed = 3}).positions;
    std::mt19937 random(5);
    std::normal_distribution<float> gauss;
    std::uniform_real_distribution<float> off(1.1F, 1.2F);
    for (int i = 0; i < 50; ++i)
        positions.push_back(Vec3f(gauss(random), gauss(random), gauss(random)).normalized() *
                            off(random));
    const std::vector<std::uint32_t> found = off_surface_of(positions);
    EXPECT_TRUE(std::is_sorted(found.begin(), found.end()));
    EXPECT_TRUE(
        std::all_of(found.begin(), found.end(), [](std::uint32_t i) { return i >= 20000; }));
    EXPECT_GE(found.size(), 48U);
}

TEST(OffSurface, StraysAmongStraysAreFoundInRounds)
{
    // A dense grid (spacing 1) and four strays 6 above it: A, and B, C and D 4 from A around it
    // (6.9 apart). Every plane sample within about 6.4 of a stray is among its 16 nearest, so
    // A's hold B, C and D, off the plane beside it and on one plane with it (as its own face's
    // samples would be at a crease: kept by the first pass), while B's, C's and D's hold A alone
    // (found). The next round tests A without them: alone off the plane, found.
    std::vector<Vec3f> positions;
    for (int x = 0; x < 60; ++x)
        for (int y = 0; y < 60; ++y)
            positions.emplace_back(static_cast<float>(x), static_cast<float>(y), 0.0F);
    const auto a = static_cast<std::uint32_t>(positions.size());
    const Vec3f centre(30.3F, 30.2F, 6.0F);
    positions.push_back(centre);
    for (int k = 0; k < 3; ++k)
    {
        const double angle = 2.0 * std::numbers::pi * k / 3.0;
        positions.push_back(centre + 4.0F * Vec3f(static_cast<float>(std::cos(angle)),
                                                  static_cast<float>(std::sin(angle)), 0.0F));
    }
    const std::vector<std::uint32_t> found = off_surface_of(positions);
    EXPECT_EQ(found, (std::vector<std::uint32_t>{a, a + 1, a + 2, a + 3}));
    // Five samples 0.7 apart on one plane 6 above the grid: each has the four others off the
    // plane beside it and on one plane with it, a face of its own: kept.
    positions.resize(a);
    for (const auto& [dx, dy] :
         {std::pair{0.0F, 0.0F}, std::pair{0.7F, 0.0F}, std::pair{-0.7F, 0.0F},
          std::pair{0.0F, 0.7F}, std::pair{0.0F, -0.7F}})
        positions.push_back(centre + Vec3f(dx, dy, 0.0F));
    EXPECT_TRUE(off_surface_of(positions).empty());
}

TEST(OffSurface, CreasesCornersThinPartsAndNoiseAreNot)
{
    // Clean shapes with creases and corners (the part, the cone's apex and rim, the blobby's
    // concave creases) and a plate 2.2 spacings thick: none.
    for (const auto& [shape, thickness] :
         {std::pair{Shape::Part, 0.05}, std::pair{Shape::Cone, 0.05},
          std::pair{Shape::Blobby, 0.05}, std::pair{Shape::Plate, 0.02}})
    {
        const std::vector<Vec3f> positions =
            sample_shape(shape, {.count = 100000, .seed = 4, .thickness = thickness}).positions;
        EXPECT_TRUE(off_surface_of(positions).empty()) << static_cast<int>(shape);
    }
    // A noisy surface: a sample stands off it by the noise, which the test measures (a few of
    // the farthest noise are taken, one in several thousand).
    const std::vector<Vec3f> noisy =
        sample_shape(Shape::Part, {.count = 100000, .seed = 4, .noise = 0.003}).positions;
    EXPECT_LE(off_surface_of(noisy).size(), 30U);
}

TEST(OffSurface, ASparseFarFaceIsASheet)
{
    // A thin plate scanned from one side: a dense face, and its far face 0.1 away sampled 100
    // times more sparsely, whose nearest are all the dense face's. Each far sample stands off
    // that face, but the far samples lie on a plane together: none is taken.
    std::mt19937 random(8);
    std::uniform_real_distribution<float> side(0.0F, 2.0F);
    std::vector<Vec3f> positions;
    for (int i = 0; i < 40000; ++i)
        positions.emplace_back(side(random), side(random), 0.0F);
    for (int i = 0; i < 400; ++i)
        positions.emplace_back(side(random), side(random), 0.1F);
    EXPECT_TRUE(off_surface_of(positions).empty());
    // Strays scattered through the space above it (0.04-0.3, 4-30 spacings of the dense face) do
    // not lie on a plane: all 40 taken here (one with three others of them among its nearest on
    // one plane with it would stay, as a sample of a face at a crease does). (Strays spread over
    // a wide area within a band much thinner than their own spacing would: they are kept, as a
    // sparse face is.)
    std::uniform_real_distribution<float> height(0.04F, 0.3F);
    positions.resize(40000);
    for (int i = 0; i < 40; ++i)
        positions.emplace_back(side(random), side(random), height(random));
    const std::vector<std::uint32_t> found = off_surface_of(positions);
    EXPECT_GE(found.size(), 38U);
    EXPECT_TRUE(
        std::all_of(found.begin(), found.end(), [](std::uint32_t i) { return i >= 40000; }));
}

TEST(OffSurface, TheSameWhateverTheThreadCountAndRefusesABadTable)
{
    std::vector<Vec3f> positions =
        sample_shape(Shape::Torus, {.count = 50000, .seed = 6}).positions;
    std::mt19937 random(9);
    std::uniform_real_distribution<float> box(-1.5F, 1.5F);
    for (int i = 0; i < 2000; ++i)
        positions.emplace_back(box(random), box(random), 0.5F * box(random));
    const KdTree tree(positions);
    const KnnTable table = knn_batch(tree, positions, 17);
    const auto runs = test::at_thread_counts([&] { return off_surface_samples(positions, table); },
                                             {.min_multi_block_loops = 2});
    EXPECT_GT(runs[0].size(), 200U);
    for (std::size_t i = 1; i < runs.size(); ++i)
        EXPECT_EQ(runs[i], runs[0]) << i + 1 << " threads";
    const std::vector<Vec3f> fewer(positions.begin(), positions.begin() + 1000);
    EXPECT_THROW((void)off_surface_samples(fewer, table), InvalidInput);
}

} // namespace
} // namespace pointform
