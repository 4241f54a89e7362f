// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// Details in local frames (§5.3): analysis and synthesis are inverses, a rigid motion of a
// coarse level carries every finer level along, and the details of a surface's relief are
// normal offsets.

#include "pointform/multires/details.h"

#include "pointform/core/error.h"
#include "pointform/core/parallel.h"
#include "pointform/geometry/level_topology.h"
#include "pointform/multires/level_of_detail.h"

#include "multires_fixtures.h"
#include "support/thread_counts.h"

#include <gtest/gtest.h>

namespace pointform {
namespace {

Vec3d apply(const Eigen::Matrix4d& m, const Vec3d& x)
{
    return m.topLeftCorner<3, 3>() * x + m.topRightCorner<3, 1>();
}

class DetailsByPredictor : public ::testing::TestWithParam<Predictor>
{};

TEST_P(DetailsByPredictor, SynthesisOfAnalysisGivesTheHierarchyBack)
{
    for (const bool closed : {true, false})
    {
        SCOPED_TRACE(closed ? "sphere" : "plate");
        const MultiresMesh original =
            closed ? test::relief_sphere(4, GetParam()) : test::relief_plate(4, GetParam());
        const MultiresDetails details = analyze_details(original);
        ASSERT_EQ(details.coefficients.size(), original.vertex_count() - original.vertex_count(0));
        MultiresMesh rebuilt = original;
        // Scramble every vertex above the base: synthesis must rebuild them from the details.
        for (std::size_t v = original.vertex_count(0); v < original.vertex_count(); ++v)
            rebuilt.mutable_positions()[v] = Vec3d(7.0, -3.0, 1.0);
        synthesize_details(rebuilt, details, 0);
        EXPECT_LE(test::largest_difference(original, rebuilt), 1e-12 * test::diagonal(original));
    }
}

TEST_P(DetailsByPredictor, RigidMotionOfALevelMovesEveryFinerLevelAlike)
{
    const MultiresMesh original = test::relief_sphere(4, GetParam());
    const MultiresDetails details = analyze_details(original);
    const Eigen::Matrix4d motion = test::rigid_motion();
    for (const std::size_t level : {std::size_t{0}, std::size_t{2}})
    {
        SCOPED_TRACE("level " + std::to_string(level));
        MultiresMesh moved = original;
        const std::span<Vec3d> x = moved.mutable_positions();
        for (std::uint32_t v = 0; v < original.vertex_count(level); ++v)
            x[v] = apply(motion, original.world(v)) - original.origin();
        synthesize_details(moved, details, level);
        double worst = 0.0;
        for (std::uint32_t v = 0; v < original.vertex_count(); ++v)
            worst = std::max(worst, (moved.world(v) - apply(motion, original.world(v))).norm());
        EXPECT_LE(worst, 1e-9 * test::diagonal(original));
    }
}

INSTANTIATE_TEST_SUITE_P(Predictors, DetailsByPredictor,
                         ::testing::Values(Predictor::Midpoint, Predictor::Butterfly),
                         [](const auto& param_info) {
                             return std::string(to_string(param_info.param));
                         });

TEST(Details, ReliefOfASurfaceIsNormalOffsets)
{
    // Each new vertex sits on the bumpy sphere along its parent edge's normal from the edge's
    // midpoint, as the refinement projects: its detail is along the frame's normal.
    const MultiresDetails details = analyze_details(test::relief_sphere_along_normals(4));
    const std::vector<DetailLevelStats> stats = detail_statistics(details);
    ASSERT_EQ(stats.size(), 4U);
    for (const DetailLevelStats& level : stats)
    {
        SCOPED_TRACE("level " + std::to_string(level.level));
        EXPECT_GT(level.details, 0U);
        EXPECT_GE(level.normal_share, 0.99);
        EXPECT_GT(level.mean_normal, 100.0 * level.mean_tangent);
        EXPECT_LE(level.mean_length, level.max_length);
    }
    // Relief halves its chord error per level, roughly: the details shrink.
    EXPECT_LT(stats.back().mean_length, stats.front().mean_length);

    // The same hierarchy with every new vertex pushed along its parent edge: tangential details.
    MultiresMesh sheared = test::relief_sphere(2);
    for (std::uint32_t v = static_cast<std::uint32_t>(sheared.vertex_count(0));
         v < sheared.vertex_count(); ++v)
    {
        const ParentEdge e = sheared.parent_edge(v);
        sheared.mutable_positions()[v] +=
            0.3 * (sheared.positions()[e.b] - sheared.positions()[e.a]);
    }
    for (const DetailLevelStats& level : detail_statistics(analyze_details(sheared)))
        EXPECT_LE(level.normal_share, 0.1);
    EXPECT_THROW((void)detail_statistics(details, 1.5), InvalidInput);
}

TEST(Details, FramesAreOrthonormalAndTurnWithTheMesh)
{
    const Vec3d a(0, 0, 0);
    const Vec3d b(2, 0, 0);
    const Vec3d c(1, 1, 0);
    const Vec3d d(1, -1, 0);
    const LocalFrame f = local_frame(a, b, c, &d);
    EXPECT_NEAR((f.t - Vec3d::UnitX()).norm(), 0.0, 1e-15);
    EXPECT_NEAR((f.n - Vec3d::UnitZ()).norm(), 0.0, 1e-15);
    EXPECT_NEAR((f.b - f.n.cross(f.t)).norm(), 0.0, 1e-15);
    // Degenerate input still gets an orthonormal frame.
    const LocalFrame g = local_frame(a, a, a, nullptr);
    EXPECT_NEAR(g.t.dot(g.n), 0.0, 1e-15);
    EXPECT_NEAR(g.n.norm(), 1.0, 1e-15);
    EXPECT_NEAR(g.b.norm(), 1.0, 1e-15);
}

TEST(Details, ButterflyStencilsReproduceAffineMapsAndSumToOne)
{
    const MultiresMesh mesh = test::relief_plate(2, Predictor::Butterfly);
    for (std::size_t level = 0; level < mesh.finest_level(); ++level)
    {
        const LevelTopology topology = level_topology(mesh, level);
        std::vector<StencilTerm> stencil;
        std::vector<std::uint32_t> ring;
        for (std::size_t j = 0; j < topology.halfedges.size(); ++j)
        {
            prediction_stencil(topology, j, Predictor::Butterfly, stencil, ring);
            double sum = 0.0;
            for (const StencilTerm& term : stencil)
                sum += term.weight;
            EXPECT_NEAR(sum, 1.0, 1e-14);
        }
    }
}

TEST(Details, MismatchedShapesAreRefused)
{
    MultiresMesh four = test::relief_sphere(2);
    const MultiresDetails details = analyze_details(test::relief_sphere(3));
    EXPECT_THROW(synthesize_details(four, details, 0), InvalidInput);
    const MultiresDetails own = analyze_details(four);
    EXPECT_THROW(synthesize_details(four, own, 3), InvalidInput);
    MultiresMesh butterfly = test::relief_sphere(2, Predictor::Butterfly);
    EXPECT_THROW(synthesize_details(butterfly, own, 0), InvalidInput);
}

TEST(Details, SameBytesAtEveryThreadCount)
{
    const MultiresMesh original = test::relief_sphere(4, Predictor::Butterfly);
    const auto runs = test::at_thread_counts([&] {
        const MultiresDetails details = analyze_details(original);
        MultiresMesh moved = original;
        for (std::uint32_t v = 0; v < original.vertex_count(1); ++v)
            moved.mutable_positions()[v] *= 1.1;
        synthesize_details(moved, details, 1);
        return std::make_pair(details.coefficients, std::vector<Vec3d>(moved.positions().begin(),
                                                                       moved.positions().end()));
    });
    for (std::size_t i = 1; i < runs.size(); ++i)
        EXPECT_TRUE(runs[i] == runs[0]) << "run " << i;
}

TEST(LevelOfDetail, ExtractsALevelAndNamesTheLevelsThatExist)
{
    const MultiresMesh mesh = test::relief_sphere(2);
    const LevelOfDetail lod = extract_level(mesh, 1);
    EXPECT_EQ(lod.mesh.face_count(), mesh.face_count(1));
    EXPECT_EQ(lod.topology.euler_characteristic, 2);
    EXPECT_TRUE(lod.topology.is_oriented_manifold());
    try
    {
        (void)extract_level(mesh, 5);
        ADD_FAILURE() << "no error";
    }
    catch (const InvalidInput& e)
    {
        EXPECT_NE(std::string(e.what()).find("level 5 does not exist"), std::string::npos);
        EXPECT_NE(std::string(e.what()).find("(0 to 2)"), std::string::npos);
    }
}

} // namespace
} // namespace pointform
