// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/implicit/scans.h"

#include "pointform/core/error.h"
#include "pointform/geometry/shapes.h"
#include "pointform/implicit/scene.h"
#include "pointform/io/io.h"

#include "support/test_support.h"

#include <gtest/gtest.h>

#include <array>
#include <fstream>
#include <string>

namespace pointform {
namespace {

TEST(ScanLoading, LoadsEachFileOnceForTheSceneParser)
{
    test::TempDir dir;
    PointCloud raw = sample_shape(Shape::Sphere, {.count = 4000, .seed = 31});
    raw.normals.clear();
    write_point_cloud(dir / "ball.xyz", raw);

    ScanLoading scans({.surfels = {.k = 12}});
    // Two spellings of one file are one scan, loaded once.
    const Scene scene = parse_scene("union(scan(\"" + (dir / "ball.xyz").string() + "\"), scan(\"" +
                                        (dir / "." / "ball.xyz").string() + "\"))",
                                    {.load_scan = scans.loader()});
    ASSERT_EQ(scans.scans().size(), 1U);
    const LoadedScan& scan = scans.scans().front();
    EXPECT_EQ(scan.samples, raw.size());
    EXPECT_TRUE(scan.estimated_normals);
    EXPECT_EQ(scan.unoriented, 0U);
    EXPECT_EQ(scans.load((dir / "ball.xyz").string()), scan.field);

    // The field is the sphere's: negative inside, positive outside, near zero on it.
    const std::array<Vec3d, 3> at = {Vec3d(0, 0, 0.8), Vec3d(0, 0, 1.0), Vec3d(0, 0, 1.2)};
    std::array<FieldSample, 3> values{};
    scene.field->evaluate(at, values);
    EXPECT_LT(values[0].value, 0.0);
    EXPECT_NEAR(values[1].value, 0.0, 0.01);
    EXPECT_GT(values[2].value, 0.0);
}

TEST(ScanLoading, ReportsFileErrorsAndBadSamples)
{
    test::TempDir dir;
    ScanLoading scans;
    EXPECT_THROW((void)scans.load((dir / "missing.ply").string()), IoError);
    PointCloud few = sample_shape(Shape::Sphere, {.count = 10, .seed = 32});
    write_point_cloud(dir / "few.xyz", few);
    EXPECT_THROW((void)scans.load((dir / "few.xyz").string()), InvalidInput);
    EXPECT_TRUE(scans.scans().empty());
}

TEST(ScanLoading, SceneArgumentsAreScansSceneFilesOrExpressions)
{
    test::TempDir dir;
    write_point_cloud(dir / "ball.ply", sample_shape(Shape::Sphere, {.count = 3000, .seed = 33}));
    {
        std::ofstream scene(dir / "cut.pf");
        scene << "let b = scan(\"ball.ply\")   # relative to this file\n"
                 "difference(b, sphere([0, 0, 1], 0.5))\n";
    }
    ScanLoading scans;
    const LoadedScene scan = load_scene_argument((dir / "ball.ply").string(), scans);
    EXPECT_EQ(scan.kind, SceneArgumentKind::Scan);
    const LoadedScene file = load_scene_argument((dir / "cut.pf").string(), scans);
    EXPECT_EQ(file.kind, SceneArgumentKind::SceneFile);
    EXPECT_EQ(scans.scans().size(), 1U); // the scene file's scan is the same file
    const LoadedScene expression = load_scene_argument("sphere([0, 0, 0], 2)", scans);
    EXPECT_EQ(expression.kind, SceneArgumentKind::Expression);
    EXPECT_EQ(to_string(SceneArgumentKind::SceneFile), "scene file");
    // Inside the ball but in the cut away part: outside the scene.
    EXPECT_LT(scan.field->evaluate(Vec3d(0, 0, 0.8)).value, 0.0);
    EXPECT_GT(file.field->evaluate(Vec3d(0, 0, 0.8)).value, 0.0);
    EXPECT_NEAR(expression.field->evaluate(Vec3d(0, 0, 0)).value, -2.0, 1e-12);
    try
    {
        (void)load_scene_argument("sphre([0, 0, 0], 1)", scans);
        FAIL() << "a misspelt function was accepted";
    }
    catch (const InvalidInput& e)
    {
        EXPECT_NE(std::string(e.what()).find("expression:1:1:"), std::string::npos) << e.what();
    }
}

} // namespace
} // namespace pointform
