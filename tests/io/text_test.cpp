// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "io_test_util.h"
#include "support/test_support.h"

#include <gtest/gtest.h>

namespace pointform::test {
namespace {

TEST(XyzRoundTrip, PositionsAndNormalsExact)
{
    TempDir dir;
    const auto path = dir / "cloud.xyz";
    const PointCloud cloud = make_cloud(1000, true, false, false);
    write_point_cloud(path, cloud);
    const ReadResult result = read_geometry(path);
    EXPECT_EQ(result.format, FileFormat::Xyz);
    EXPECT_NE(result.description.find("6 columns"), std::string::npos);
    expect_same_cloud(cloud, result.points, 0.0);
}

TEST(XyzRoundTrip, PositionsOnly)
{
    TempDir dir;
    const auto path = dir / "plain.xyz";
    const PointCloud cloud = make_cloud(100, false, false, false);
    write_point_cloud(path, cloud);
    expect_same_cloud(cloud, read_point_cloud(path), 0.0);
}

TEST(XyzRoundTrip, GeoreferencedOriginKeepsPrecision)
{
    TempDir dir;
    const auto path = dir / "geo.xyz";
    const Vec3d origin(500000.0, 4000000.0, 250.0);
    const PointCloud cloud = make_cloud(300, true, false, false, origin, 30.0);
    write_point_cloud(path, cloud);
    const PointCloud back = read_point_cloud(path);
    ASSERT_EQ(back.size(), cloud.size());
    for (std::size_t i = 0; i < cloud.size(); ++i)
        ASSERT_LT((back.world(i) - cloud.world(i)).norm(), 1e-4) << i;
}

TEST(XyzRoundTrip, PrecisionOptionLimitsDigits)
{
    TempDir dir;
    const auto path = dir / "short.xyz";
    PointCloud cloud;
    cloud.positions = {Vec3f(0.123456789F, 1.0F / 3.0F, -2.0F)};
    write_point_cloud(path, cloud, {.precision = 4});
    EXPECT_EQ(read_file(path), "0.1235 0.3333 -2\n");
    const PointCloud back = read_point_cloud(path);
    EXPECT_NEAR(back.positions[0].x(), 0.1235F, 1e-7F);
}

TEST(XyzRoundTrip, OtherTextExtensions)
{
    TempDir dir;
    const PointCloud cloud = make_cloud(20, true, false, false);
    for (const char* name : {"a.pwn", "b.txt", "c.csv", "d.XYZ"})
    {
        write_point_cloud(dir / name, cloud);
        expect_same_cloud(cloud, read_point_cloud(dir / name), 0.0);
    }
}

TEST(XyzRead, CommentsBlankLinesSeparatorsAndCrlf)
{
    TempDir dir;
    const auto path = dir / "mixed.xyz";
    write_file(path,
               "# a comment\r\n// another comment\r\n\r\n1 2 3\r\n4,5,6\r\n"
               "  7\t8 ,  9  \r\n\r\n# trailing comment\r\n");
    const PointCloud cloud = read_point_cloud(path);
    ASSERT_EQ(cloud.size(), 3U);
    EXPECT_EQ(cloud.world(0), Vec3d(1, 2, 3));
    EXPECT_EQ(cloud.world(1), Vec3d(4, 5, 6));
    EXPECT_EQ(cloud.world(2), Vec3d(7, 8, 9));
    EXPECT_FALSE(cloud.has_normals());
}

TEST(XyzRead, CsvHeaderByName)
{
    TempDir dir;
    const auto path = dir / "named.csv";
    write_file(path, "nz,x,\"y\",z,nx,ny,intensity\n1,10,20,30,0,0,7\n0,11,21,31,2,0,7\n");
    const ReadResult result = read_geometry(path);
    const PointCloud& cloud = result.points;
    ASSERT_EQ(cloud.size(), 2U);
    EXPECT_EQ(cloud.world(0), Vec3d(10, 20, 30));
    ASSERT_TRUE(cloud.has_normals());
    EXPECT_EQ(cloud.normals[0], Vec3f(0, 0, 1));
    EXPECT_EQ(cloud.normals[1], Vec3f(1, 0, 0)); // normalized
    EXPECT_NE(result.description.find("header"), std::string::npos);
}

TEST(XyzRead, CsvHeaderWithColors)
{
    TempDir dir;
    const auto path = dir / "colors.csv";
    write_file(path, "X,Y,Z,Red,Green,Blue\n1,2,3,255,128,0\n");
    const PointCloud cloud = read_point_cloud(path);
    ASSERT_TRUE(cloud.has_colors());
    EXPECT_EQ(cloud.colors[0], (Color{255, 128, 0}));
    EXPECT_FALSE(cloud.has_normals());
}

TEST(XyzRead, PtsWithCountLineAndColors)
{
    TempDir dir;
    const auto path = dir / "scan.pts";
    write_file(path, "3\n1.5 2.5 3.5 -1200 10 20 30\n2 3 4 0 40 50 60\n3 4 5 12 255 0 1\n");
    const ReadResult result = read_geometry(path);
    const PointCloud& cloud = result.points;
    ASSERT_EQ(cloud.size(), 3U);
    EXPECT_FALSE(cloud.has_normals());
    ASSERT_TRUE(cloud.has_colors());
    EXPECT_EQ(cloud.colors[0], (Color{10, 20, 30}));
    EXPECT_EQ(cloud.colors[2], (Color{255, 0, 1}));
    EXPECT_EQ(cloud.world(0), Vec3d(1.5, 2.5, 3.5));
    EXPECT_NE(result.description.find("intensity"), std::string::npos);
}

TEST(XyzRead, SevenColumnsInOtherExtensions)
{
    TempDir dir;
    const auto pts_like = dir / "pts_like.txt";
    write_file(pts_like, "1 2 3 0.5 10 20 30\n");
    EXPECT_TRUE(read_point_cloud(pts_like).has_colors());
    // Floats in columns 5 to 7: columns 4 to 6 are normals and the 7th is ignored.
    const auto normals = dir / "normals.xyz";
    write_file(normals, "1 2 3 0 0.6 0.8 0.01\n");
    const PointCloud cloud = read_point_cloud(normals);
    EXPECT_FALSE(cloud.has_colors());
    ASSERT_TRUE(cloud.has_normals());
    EXPECT_NEAR(cloud.normals[0].z(), 0.8F, 1e-6F);
}

TEST(XyzRead, FourColumnsAreXyzAndIgnored)
{
    TempDir dir;
    const auto path = dir / "intensity.xyz";
    write_file(path, "1 2 3 99\n4 5 6 98\n");
    const PointCloud cloud = read_point_cloud(path);
    ASSERT_EQ(cloud.size(), 2U);
    EXPECT_FALSE(cloud.has_normals());
    EXPECT_EQ(cloud.world(1), Vec3d(4, 5, 6));
}

TEST(XyzErrors, InconsistentColumnCountNamesTheLine)
{
    TempDir dir;
    expect_file_error_at_line(dir / "ragged.xyz", "# header comment\n1 2 3\n4 5 6\n7 8\n",
                              "2 values, expected 3", 4);
    expect_file_error_at_line(dir / "longer.xyz", "1 2 3\n4 5 6 7\n", "4 values, expected 3", 2);
}

TEST(XyzErrors, TooFewColumns)
{
    TempDir dir;
    expect_file_error(dir / "two.xyz", "1 2\n3 4\n", "at least 3 values");
}

TEST(XyzErrors, GarbageNumbers)
{
    TempDir dir;
    expect_file_error_at_line(dir / "garbage.xyz", "1 2 3\n4 5 6\n7 8e 9\n", "'8e'", 3);
    expect_file_error(dir / "words.xyz", "hello world again\n1 2 3\n", "header naming x, y and z");
}

TEST(XyzErrors, NonFiniteCoordinates)
{
    TempDir dir;
    const auto path = dir / "nan.xyz";
    expect_file_error_at_line(path, "1 2 3\n-inf 2 3\n4 nan 6\n7 8 9\n", "non-finite", 2);

    const ReadResult dropped = read_geometry(path, {.non_finite = NonFinitePolicy::Drop});
    EXPECT_EQ(dropped.points.size(), 2U);
    EXPECT_EQ(dropped.dropped_points, 2U);
    EXPECT_EQ(dropped.points.world(1), Vec3d(7, 8, 9));
}

TEST(XyzErrors, PtsCountMismatch)
{
    TempDir dir;
    expect_file_error_at_line(dir / "count.pts", "5\n1 2 3\n4 5 6\n",
                              "declares 5 points but the file has 2", 1);
}

TEST(XyzErrors, OnlyComments)
{
    TempDir dir;
    expect_file_error(dir / "comments.xyz", "# nothing\n\n// here\n", "no data lines");
}

} // namespace
} // namespace pointform::test
