// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// Multiresolution deformation (§5.3, Fig. 11): an edit of level j by a bi-Laplacian solve, the
// finer levels following by their details.

#include "pointform/multires/deformation.h"

#include "pointform/core/error.h"
#include "pointform/multires/details.h"
#include "pointform/multires/level_of_detail.h"

#include "multires_fixtures.h"
#include "support/thread_counts.h"

#include <gtest/gtest.h>

#include <set>

namespace pointform {
namespace {

std::vector<std::uint32_t> all_vertices(const MultiresMesh& mesh, std::size_t level)
{
    std::vector<std::uint32_t> out(mesh.vertex_count(level));
    for (std::uint32_t v = 0; v < out.size(); ++v)
        out[v] = v;
    return out;
}

/// Area-weighted normal of vertex v over the faces of `level`.
Vec3d vertex_normal(const MultiresMesh& mesh, std::size_t level, std::uint32_t v)
{
    Vec3d n = Vec3d::Zero();
    for (const Triangle& t : mesh.faces(level))
        if (t[0] == v || t[1] == v || t[2] == v)
        {
            const Vec3d& a = mesh.positions()[t[0]];
            n += (mesh.positions()[t[1]] - a).cross(mesh.positions()[t[2]] - a);
        }
    return n.normalized();
}

bool same_bytes(const MultiresMesh& a, const MultiresMesh& b)
{
    return std::equal(a.positions().begin(), a.positions().end(), b.positions().begin(),
                      b.positions().end());
}

TEST(Deformation, IdentityEditGivesTheInputBack)
{
    const MultiresMesh original = test::relief_sphere(3);
    MultiresMesh mesh = original;
    MultiresEdit edit;
    edit.level = 1;
    edit.handles = {DeformHandle::translate({0, 5, 17}, Vec3d::Zero()),
                    DeformHandle::affine({40, 41}, Eigen::Matrix4d::Identity())};
    const DeformReport report = deform(mesh, edit);
    EXPECT_TRUE(same_bytes(mesh, original));
    EXPECT_EQ(report.largest_displacement, 0.0);
    for (const LevelMotion& motion : report.levels)
        EXPECT_EQ(motion.moved, 0U);
}

TEST(Deformation, RigidAndAffineEditsOfAWholeLevelMoveEveryLevelAlike)
{
    const MultiresMesh original = test::relief_sphere(3, Predictor::Butterfly);
    const Eigen::Matrix4d rigid = test::rigid_motion();
    for (const std::size_t level : {std::size_t{0}, std::size_t{1}})
    {
        SCOPED_TRACE("level " + std::to_string(level));
        MultiresMesh mesh = original;
        MultiresEdit edit{.level = level,
                          .handles = {DeformHandle::affine(all_vertices(original, level), rigid)}};
        (void)deform(mesh, edit);
        double worst = 0.0;
        for (std::uint32_t v = 0; v < original.vertex_count(); ++v)
        {
            const Vec3d expected =
                rigid.topLeftCorner<3, 3>() * original.world(v) + rigid.topRightCorner<3, 1>();
            worst = std::max(worst, (mesh.world(v) - expected).norm());
        }
        EXPECT_LE(worst, 1e-9 * test::diagonal(original));
        EXPECT_NO_THROW(mesh.validate());
    }
}

TEST(Deformation, BiLaplacianReproducesAnAffineFieldOnAPlane)
{
    // A flat grid whose two outer rings are handles under an affine map of the displacement:
    // the energy is zero for the affine field, so the free interior must follow it exactly.
    MultiresMesh mesh(test::square_grid(12));
    const MultiresMesh original = mesh;
    Eigen::Matrix4d map = Eigen::Matrix4d::Identity();
    map.topLeftCorner<3, 3>() << 1.1, 0.2, 0.0, -0.1, 0.9, 0.0, 0.3, 0.4, 1.0;
    map.topRightCorner<3, 1>() = Vec3d(0.5, -0.25, 0.125);
    std::vector<std::uint32_t> rings;
    for (std::uint32_t v = 0; v < mesh.vertex_count(); ++v)
    {
        const Vec3d x = mesh.world(v);
        if (std::max(std::abs(x.x()), std::abs(x.y())) > 1.0 - 2.0 * (2.0 / 12.0) + 1e-9)
            rings.push_back(v);
    }
    MultiresEdit edit{.level = 0, .handles = {DeformHandle::affine(rings, map)}};
    const DeformReport report = deform(mesh, edit);
    EXPECT_GT(report.free_vertices, 20U);
    for (std::uint32_t v = 0; v < mesh.vertex_count(); ++v)
    {
        const Vec3d expected =
            map.topLeftCorner<3, 3>() * original.world(v) + map.topRightCorner<3, 1>();
        EXPECT_LE((mesh.world(v) - expected).norm(), 1e-9) << "vertex " << v;
    }
}

TEST(Deformation, NothingOutsideTheRegionMovesAtAnyLevel)
{
    const MultiresMesh original = test::relief_sphere(4);
    const std::size_t level = 2;
    const std::uint32_t centre = 3; // a base vertex, so a vertex of every level
    const double radius = 0.3;
    MultiresMesh mesh = original;
    const Vec3d normal = vertex_normal(original, level, centre);
    MultiresEdit edit{.level = level,
                      .handles = {DeformHandle::translate({centre}, 0.1 * normal)},
                      .region = RegionOfInterest::ball(original.world(centre), radius)};
    const DeformReport report = deform(mesh, edit);
    EXPECT_GT(report.free_vertices, 5U);
    EXPECT_EQ(report.handle_vertices, 1U);
    EXPECT_NEAR((mesh.world(centre) - original.world(centre) - 0.1 * normal).norm(), 0.0, 1e-15);

    // Level 2's edges are about 0.15 long; synthesis reads at most two rings of the level
    // below: beyond the ball and three of level 2's edges nothing may move, bit for bit.
    std::size_t far = 0;
    for (std::uint32_t v = 0; v < original.vertex_count(); ++v)
        if ((original.world(v) - original.world(centre)).norm() > radius + 0.45)
        {
            ++far;
            EXPECT_EQ(mesh.positions()[v], original.positions()[v]) << "vertex " << v;
        }
    EXPECT_GT(far, original.vertex_count() / 2);
    // Levels coarser than 2 keep their own vertices' new positions: the hierarchy stays nested,
    // manifold and valid.
    EXPECT_NO_THROW(mesh.validate());
    for (std::size_t l = 0; l < mesh.level_count(); ++l)
        EXPECT_TRUE(extract_level(mesh, l).topology.is_oriented_manifold());
    std::size_t moved = 0;
    for (const LevelMotion& motion : report.levels)
        moved += motion.moved;
    EXPECT_GT(moved, 0U);
    EXPECT_NEAR(report.largest_displacement, 0.1, 0.02);
}

TEST(Deformation, ABumpRaisesTheFineLevelAndKeepsTheReliefHeight)
{
    const MultiresMesh original = test::relief_sphere(4);
    const std::uint32_t centre = 7;
    const double height = 0.08;
    const Vec3d normal = vertex_normal(original, 0, centre);
    MultiresMesh mesh = original;
    MultiresEdit edit{.level = 0,
                      .handles = {DeformHandle::translate({centre}, height * normal)},
                      .region = RegionOfInterest::ball(original.world(centre), 0.8)};
    (void)deform(mesh, edit);

    // Near the moved base vertex the finest level rises by about the same amount.
    std::size_t near = 0;
    for (std::uint32_t v = 0; v < original.vertex_count(); ++v)
        if ((original.world(v) - original.world(centre)).norm() < 0.08)
        {
            ++near;
            const double rise = (mesh.world(v) - original.world(v)).dot(normal);
            EXPECT_GT(rise, 0.8 * height) << "vertex " << v;
            EXPECT_LT(rise, 1.05 * height) << "vertex " << v;
        }
    EXPECT_GT(near, 5U);

    // The relief's height (the normal components of the details above level 0) is unchanged.
    const MultiresDetails before = analyze_details(original);
    const MultiresDetails after = analyze_details(mesh);
    double worst = 0.0;
    double largest = 0.0;
    for (std::size_t k = 0; k < before.coefficients.size(); ++k)
    {
        worst = std::max(worst, std::abs(after.coefficients[k].y() - before.coefficients[k].y()));
        largest = std::max(largest, std::abs(before.coefficients[k].y()));
    }
    EXPECT_GT(largest, 1e-3);
    EXPECT_LE(worst, 1e-12 * test::diagonal(original));
}

TEST(Deformation, ADeformerSolvesAgainForNewTargets)
{
    const MultiresMesh original = test::relief_plate(3, Predictor::Butterfly);
    // Level 1's vertices nearest to a few points of the plate.
    const auto nearest = [&](double x, double y) {
        std::uint32_t best = 0;
        for (std::uint32_t v = 1; v < original.vertex_count(1); ++v)
            if ((original.world(v) - Vec3d(x, y, 0)).head<2>().norm() <
                (original.world(best) - Vec3d(x, y, 0)).head<2>().norm())
                best = v;
        return best;
    };
    const std::uint32_t a = nearest(0.0, 0.0);
    const std::uint32_t b = nearest(0.5, 0.25);
    const std::uint32_t c = nearest(-0.25, 0.5);
    MultiresEdit edit{.level = 1,
                      .handles = {DeformHandle::translate({a}, Vec3d(0, 0, 0.2)),
                                  DeformHandle::translate({b, c}, Vec3d(0, 0, -0.1))},
                      .region = RegionOfInterest::box(Vec3d(-0.8, -0.8, -1), Vec3d(0.8, 0.8, 1))};
    const MultiresDeformer deformer(original, edit);
    EXPECT_EQ(std::vector<std::uint32_t>(deformer.handle_vertices().begin(),
                                         deformer.handle_vertices().end()),
              (std::vector<std::uint32_t>{a, b, c}));
    MultiresMesh mesh = original;
    (void)deformer.apply(mesh, edit.handles);
    // A second target: the same as a one-off edit with it, bit for bit.
    edit.handles[0] = DeformHandle::translate({a}, Vec3d(0.05, 0, 0.3));
    (void)deformer.apply(mesh, edit.handles);
    MultiresMesh fresh = original;
    (void)deform(fresh, edit);
    EXPECT_TRUE(same_bytes(mesh, fresh));
    // Back to the rest targets: the input again.
    std::vector<Vec3d> rest_targets;
    for (const std::uint32_t v : deformer.handle_vertices())
        rest_targets.push_back(original.world(v));
    (void)deformer.apply(mesh, rest_targets);
    EXPECT_TRUE(same_bytes(mesh, original));
}

TEST(Deformation, HandlesChosenByPlaceAreTheVerticesThere)
{
    const MultiresMesh original = test::relief_plate(3, Predictor::Butterfly);
    const std::size_t n = original.vertex_count(1);
    // Level 1's vertices in a ball and a box, listed by hand.
    const Vec3d center(0.1, -0.2, 0.0);
    const double radius = 0.3;
    const Vec3d lo(-0.7, 0.25, -1.0);
    const Vec3d hi(-0.15, 0.75, 1.0);
    std::vector<std::uint32_t> in_ball;
    std::vector<std::uint32_t> in_box;
    for (std::uint32_t v = 0; v < n; ++v)
    {
        const Vec3d x = original.world(v);
        if ((x - center).norm() <= radius)
            in_ball.push_back(v);
        if ((x.array() >= lo.array()).all() && (x.array() <= hi.array()).all())
            in_box.push_back(v);
    }
    ASSERT_GE(in_ball.size(), 3U);
    ASSERT_GE(in_box.size(), 3U);
    const RegionOfInterest region =
        RegionOfInterest::box(Vec3d(-0.8, -0.8, -1), Vec3d(0.8, 0.8, 1));
    Eigen::Matrix4d up = Eigen::Matrix4d::Identity();
    up(2, 3) = 0.2;
    Eigen::Matrix4d down = Eigen::Matrix4d::Identity();
    down(2, 3) = -0.1;
    const MultiresEdit by_place{
        .level = 1,
        .handles = {DeformHandle::within(RegionOfInterest::ball(center, radius), up),
                    DeformHandle::within(RegionOfInterest::box(lo, hi), down)},
        .region = region};
    const MultiresEdit by_id{
        .level = 1,
        .handles = {DeformHandle::affine(in_ball, up), DeformHandle::affine(in_box, down)},
        .region = region};
    const MultiresDeformer deformer(original, by_place);
    std::vector<std::uint32_t> both = in_ball;
    both.insert(both.end(), in_box.begin(), in_box.end());
    EXPECT_EQ(std::vector<std::uint32_t>(deformer.handle_vertices().begin(),
                                         deformer.handle_vertices().end()),
              both);
    MultiresMesh placed = original;
    const DeformReport report = deformer.apply(placed, by_place.handles);
    EXPECT_EQ(report.handle_vertices, both.size());
    MultiresMesh listed = original;
    (void)deform(listed, by_id);
    EXPECT_TRUE(same_bytes(placed, listed));
    EXPECT_NEAR(placed.world(in_ball[0]).z(), original.world(in_ball[0]).z() + 0.2, 1e-12);
    // Another ball than the deformer was made with is refused; one holding no vertex too.
    EXPECT_THROW(
        (void)deformer.apply(placed,
                             std::vector<DeformHandle>{
                                 DeformHandle::within(RegionOfInterest::ball(center, 0.25), up),
                                 by_place.handles[1]}),
        InvalidInput);
    MultiresMesh mesh = original;
    const MultiresEdit empty{
        .level = 1,
        .handles = {DeformHandle::within(RegionOfInterest::ball(Vec3d(5, 5, 5), 0.1), up)},
        .region = RegionOfInterest::whole()};
    EXPECT_THROW((void)deform(mesh, empty), InvalidInput);
    const MultiresEdit flat{
        .level = 1,
        .handles = {DeformHandle::within(RegionOfInterest::ball(center, -1.0), up)},
        .region = RegionOfInterest::whole()};
    EXPECT_THROW((void)deform(mesh, flat), InvalidInput);
}

TEST(Deformation, BadEditsAreRefused)
{
    MultiresMesh mesh = test::relief_sphere(2);
    const MultiresMesh original = mesh;
    const auto refused = [&](const MultiresEdit& edit, const std::string& says) {
        try
        {
            (void)deform(mesh, edit);
            ADD_FAILURE() << "no error (expected '" << says << "')";
        }
        catch (const InvalidInput& e)
        {
            EXPECT_NE(std::string(e.what()).find(says), std::string::npos) << e.what();
        }
        EXPECT_TRUE(same_bytes(mesh, original));
    };
    refused({.level = 3, .handles = {DeformHandle::translate({0}, Vec3d::UnitX())}},
            "level 3 does not exist");
    refused({.level = 0, .handles = {DeformHandle::translate({42}, Vec3d::UnitX())}},
            "vertex 42 is not a vertex of level 0");
    refused({.level = 0,
             .handles = {DeformHandle::translate({1, 2}, Vec3d::UnitX()),
                         DeformHandle::translate({2}, Vec3d::UnitX())}},
            "named twice");
    refused({.level = 0,
             .handles = {DeformHandle::translate({0}, Vec3d::UnitX())},
             .region = RegionOfInterest::of_vertices({1, 2, 3})},
            "outside the region");
    refused({.level = 0, .handles = {DeformHandle::translate({0}, Vec3d(std::nan(""), 0, 0))}},
            "not finite");
    Eigen::Matrix4d projective = Eigen::Matrix4d::Identity();
    projective(3, 0) = 0.5;
    refused({.level = 0, .handles = {DeformHandle::affine({0}, projective)}}, "last row");
    refused({.level = 0,
             .handles = {DeformHandle::translate({0}, Vec3d::UnitX())},
             .region = RegionOfInterest::ball(Vec3d::Zero(), -1.0)},
            "radius");
    refused({.level = 0,
             .handles = {DeformHandle::translate({0}, Vec3d::UnitX())},
             .region = RegionOfInterest::box(Vec3d::Ones(), Vec3d::Zero())},
            "min <= max");
    refused({.level = 0, .handles = {DeformHandle::translate({}, Vec3d::UnitX())}}, "no vertices");
    refused({.level = 0,
             .handles = {DeformHandle::translate({0}, Vec3d::UnitX())},
             .region = RegionOfInterest::of_vertices({0, 99})},
            "region vertex 99");
}

TEST(Deformation, UnconstrainedPartsOfTheRegionStayPut)
{
    // The whole level as the region and one handle: the part is anchored by the handle alone,
    // so it moves rigidly with it (the bi-Laplacian's null space); nothing is left undefined.
    const MultiresMesh original = test::relief_sphere(2);
    MultiresMesh mesh = original;
    const DeformReport report =
        deform(mesh, {.level = 0, .handles = {DeformHandle::translate({5}, Vec3d(0, 0, 0.25))}});
    EXPECT_EQ(report.unconstrained_vertices, 0U);
    for (std::uint32_t v = 0; v < mesh.vertex_count(); ++v)
        EXPECT_LE((mesh.world(v) - original.world(v) - Vec3d(0, 0, 0.25)).norm(), 1e-9);
    // No handle at all: nothing constrains the level, nothing moves.
    MultiresMesh still = original;
    const DeformReport none = deform(still, {.level = 1});
    EXPECT_EQ(none.unconstrained_vertices, original.vertex_count(1));
    EXPECT_TRUE(same_bytes(still, original));
}

TEST(Deformation, SameBytesAtEveryThreadCount)
{
    const MultiresMesh original = test::relief_sphere(4, Predictor::Butterfly);
    MultiresEdit edit{.level = 0,
                      .handles = {DeformHandle::translate({3, 9}, Vec3d(0.05, 0.1, -0.2))},
                      .region = RegionOfInterest::ball(original.world(3), 1.2)};
    const auto runs = test::at_thread_counts([&] {
        MultiresMesh mesh = original;
        (void)deform(mesh, edit);
        return std::vector<Vec3d>(mesh.positions().begin(), mesh.positions().end());
    });
    for (std::size_t i = 1; i < runs.size(); ++i)
        EXPECT_TRUE(runs[i] == runs[0]) << "run " << i;
}

} // namespace
} // namespace pointform
