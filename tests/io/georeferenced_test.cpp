// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// Georeferenced coordinates (x near 5·10^5, y near 5·10^6: UTM-like eastings and northings) with
// millimetre detail, written by hand into LAS and PLY files with known double values, read back
// and compared coordinate by coordinate with those doubles to the precision the library
// promises: world = origin + float(position − origin), the origin a rounded first point, so each
// coordinate is off by at most half a float ulp of its offset from the origin (plus the double
// rounding of the sums). A reader that dropped to float without the origin (a 6 cm ulp at
// 5·10^5, 50 cm at 5·10^6) or lost the origin's fraction would fail.

#include "io_test_util.h"
#include "support/test_support.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

namespace pointform::test {
namespace {

/// The largest error the origin + float representation allows for coordinate `exact` of a
/// cloud with origin `origin`: half an ulp of float(exact − origin), plus the double rounding of
/// the difference and the sum (a few ulps of a double of that size).
double promised_error(double exact, double origin)
{
    const float offset = static_cast<float>(std::abs(exact - origin));
    const double half_ulp =
        0.5 * static_cast<double>(std::nextafter(offset, std::numeric_limits<float>::infinity()) -
                                  offset);
    return half_ulp + 4.0 * std::abs(exact) * std::numeric_limits<double>::epsilon();
}

/// Checks every coordinate of `cloud` against `expected` within promised_error, and that the
/// error budget is sub-millimetre (the detail the files carry).
void expect_coordinates(const PointCloud& cloud, const std::vector<Vec3d>& expected)
{
    ASSERT_EQ(cloud.size(), expected.size());
    double worst = 0.0;
    for (std::size_t i = 0; i < expected.size(); ++i)
        for (int k = 0; k < 3; ++k)
        {
            const double error = std::abs(cloud.world(i)[k] - expected[i][k]);
            const double bound = promised_error(expected[i][k], cloud.origin[k]);
            ASSERT_LE(error, bound) << "point " << i << " axis " << k << ": read "
                                    << cloud.world(i)[k] << ", file has " << expected[i][k];
            ASSERT_LT(bound, 1e-4); // under 2048 m from the origin: half a float ulp ≤ 61 µm
            worst = std::max(worst, error);
        }
    // The representation is not exact at this extent: some coordinates are off, but by less
    // than 0.1 mm (so a reader that returned the doubles unchanged would also pass, while one
    // that rounded anywhere to float without the origin would not).
    EXPECT_LT(worst, 1e-4);
}

/// Points around (5·10^5 + 0.123, 5·10^6 + 0.456, 100) spread over ±1 km horizontally (so within
/// 2048 m of the origin) and ±50 m vertically, every coordinate a whole number of millimetres, in
/// pairs one millimetre apart on each axis.
std::vector<Vec3d> millimetre_points(std::size_t pairs, std::uint32_t seed)
{
    std::mt19937 random(seed);
    std::uniform_int_distribution<std::int32_t> horizontal(-1'000'000, 1'000'000);
    std::uniform_int_distribution<std::int32_t> vertical(-50'000, 50'000);
    std::vector<Vec3d> points;
    for (std::size_t i = 0; i < pairs; ++i)
    {
        const std::int64_t x = 500'000'123 + horizontal(random);
        const std::int64_t y = 5'000'000'456 + horizontal(random);
        const std::int64_t z = 100'000 + vertical(random);
        for (const std::int64_t step : {0, 1})
            points.emplace_back(static_cast<double>(x + step) / 1000.0,
                                static_cast<double>(y + step) / 1000.0,
                                static_cast<double>(z + step) / 1000.0);
    }
    return points;
}

/// A LAS 1.2 point-format-0 file: X Y Z stored as int32 with the given scale and offset.
std::string las_file(const std::vector<std::array<std::int32_t, 3>>& xyz, const Vec3d& scale,
                     const Vec3d& offset)
{
    constexpr std::uint16_t header_size = 227;
    constexpr std::uint16_t record_length = 20;
    Bytes b;
    b.text("LASF").le<std::uint16_t>(0).le<std::uint16_t>(0).zeros(16);
    b.le<std::uint8_t>(1).le<std::uint8_t>(2);
    b.zeros(64).le<std::uint16_t>(1).le<std::uint16_t>(2026);
    b.le(header_size).le(static_cast<std::uint32_t>(header_size)).le<std::uint32_t>(0);
    b.le<std::uint8_t>(0).le(record_length);
    b.le(static_cast<std::uint32_t>(xyz.size())).zeros(20);
    for (int k = 0; k < 3; ++k)
        b.le(scale[k]);
    for (int k = 0; k < 3; ++k)
        b.le(offset[k]);
    b.zeros(48);
    EXPECT_EQ(b.size(), header_size);
    for (const auto& p : xyz)
        b.le(p[0]).le(p[1]).le(p[2]).zeros(record_length - 12);
    return b.str();
}

TEST(Georeferenced, LasMillimetreCoordinatesMatchTheFileDoubles)
{
    const TempDir dir;
    // Scale 1 mm; offsets away from the points, so the int32 values are large and the origin
    // (the rounded first point) is not the offset.
    const Vec3d scale(0.001, 0.001, 0.001);
    const Vec3d offset(499'000.0, 4'999'000.0, 0.0);
    const std::vector<Vec3d> points = millimetre_points(2000, 5);
    std::vector<std::array<std::int32_t, 3>> xyz;
    std::vector<Vec3d> expected; // the file's own values: X · scale + offset, in double
    for (const Vec3d& p : points)
    {
        std::array<std::int32_t, 3> raw{};
        for (int k = 0; k < 3; ++k)
            raw[static_cast<std::size_t>(k)] =
                static_cast<std::int32_t>(std::llround((p[k] - offset[k]) / scale[k]));
        xyz.push_back(raw);
        expected.emplace_back(static_cast<double>(raw[0]) * scale[0] + offset[0],
                              static_cast<double>(raw[1]) * scale[1] + offset[1],
                              static_cast<double>(raw[2]) * scale[2] + offset[2]);
    }
    write_file(dir / "utm.las", las_file(xyz, scale, offset));
    const PointCloud cloud = read_point_cloud(dir / "utm.las");
    EXPECT_EQ(cloud.origin, Vec3d(std::round(expected[0].x()), std::round(expected[0].y()),
                                  std::round(expected[0].z())));
    expect_coordinates(cloud, expected);
}

/// A PLY file with double x y z, binary little-endian or ascii with 17 significant digits.
std::string ply_file(const std::vector<Vec3d>& points, bool ascii)
{
    Bytes b;
    b.text(std::string("ply\nformat ") + (ascii ? "ascii" : "binary_little_endian") +
           " 1.0\nelement vertex " + std::to_string(points.size()) +
           "\nproperty double x\nproperty double y\nproperty double z\nend_header\n");
    for (const Vec3d& p : points)
    {
        if (!ascii)
        {
            b.le(p.x()).le(p.y()).le(p.z());
            continue;
        }
        char line[96];
        std::snprintf(line, sizeof(line), "%.17g %.17g %.17g\n", p.x(), p.y(), p.z());
        b.text(line);
    }
    return b.str();
}

TEST(Georeferenced, PlyMillimetreCoordinatesMatchTheFileDoubles)
{
    const TempDir dir;
    const std::vector<Vec3d> points = millimetre_points(2000, 7);
    for (const bool ascii : {false, true})
    {
        SCOPED_TRACE(ascii ? "ascii" : "binary");
        const auto path = dir / (ascii ? "utm_ascii.ply" : "utm_binary.ply");
        write_file(path, ply_file(points, ascii));
        const PointCloud cloud = read_point_cloud(path);
        expect_coordinates(cloud, points);
    }
}

TEST(Georeferenced, MillimetreNeighboursStayDistinct)
{
    // Pairs one millimetre apart on every axis read back one millimetre apart, to within twice
    // the promised error (the detail survives, not only the absolute position).
    const TempDir dir;
    const std::vector<Vec3d> points = millimetre_points(500, 11);
    write_file(dir / "pairs.ply", ply_file(points, false));
    const PointCloud cloud = read_point_cloud(dir / "pairs.ply");
    ASSERT_EQ(cloud.size(), points.size());
    for (std::size_t i = 0; i < points.size(); i += 2)
        for (int k = 0; k < 3; ++k)
        {
            const double step = cloud.world(i + 1)[k] - cloud.world(i)[k];
            const double bound = promised_error(points[i][k], cloud.origin[k]) +
                                 promised_error(points[i + 1][k], cloud.origin[k]);
            ASSERT_NEAR(step, points[i + 1][k] - points[i][k], bound) << i << " axis " << k;
            ASSERT_NEAR(step, 0.001, 1e-4);
        }
}

} // namespace
} // namespace pointform::test
