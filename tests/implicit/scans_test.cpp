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

} // namespace
} // namespace pointform
