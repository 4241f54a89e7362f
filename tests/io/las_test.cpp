// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "io_test_util.h"
#include "support/test_support.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>

namespace pointform::test {
namespace {

using Rgb16 = std::array<std::uint16_t, 3>;

constexpr std::size_t min_record_length[11] = {20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67};

std::size_t rgb_offset(int format)
{
    switch (format)
    {
        case 2:
            return 20;
        case 3:
        case 5:
            return 28;
        case 7:
        case 8:
        case 10:
            return 30;
        default:
            return 0;
    }
}

struct LasSpec
{
    int minor = 2;
    int format = 0;
    std::size_t extra_bytes = 0; ///< bytes after the standard record fields
    std::size_t padding = 0;     ///< bytes between the header and the point data
    Vec3d scale = Vec3d(0.001, 0.001, 0.001);
    Vec3d offset = Vec3d(5e5, 4e6, 100.0);
    bool legacy_count = true;         ///< LAS 1.4: also fill the 32-bit legacy count
    std::uint64_t declared_extra = 0; ///< points declared beyond those written
};

/// A LAS file with the given integer coordinates (X Y Z before scale and offset) and colors.
std::string make_las(const LasSpec& spec, const std::vector<std::array<std::int32_t, 3>>& xyz,
                     const std::vector<Rgb16>& rgb)
{
    const std::size_t header_size = spec.minor <= 2 ? 227 : (spec.minor == 3 ? 235 : 375);
    const std::size_t record_length = min_record_length[spec.format] + spec.extra_bytes;
    const std::uint64_t declared = xyz.size() + spec.declared_extra;
    Bytes b;
    b.text("LASF").le<std::uint16_t>(0).le<std::uint16_t>(0).zeros(16);
    b.le<std::uint8_t>(1).le<std::uint8_t>(static_cast<std::uint8_t>(spec.minor));
    std::string name(32, '\0');
    name.replace(0, 9, "pointform");
    b.text(name).text(name).le<std::uint16_t>(1).le<std::uint16_t>(2026);
    b.le(static_cast<std::uint16_t>(header_size));
    b.le(static_cast<std::uint32_t>(header_size + spec.padding));
    b.le<std::uint32_t>(0);
    b.le(static_cast<std::uint8_t>(spec.format)).le(static_cast<std::uint16_t>(record_length));
    b.le(static_cast<std::uint32_t>(spec.legacy_count ? declared : 0)).zeros(20);
    for (int k = 0; k < 3; ++k)
        b.le(spec.scale[k]);
    for (int k = 0; k < 3; ++k)
        b.le(spec.offset[k]);
    b.zeros(48); // max and min: informative only
    if (spec.minor >= 3)
        b.le<std::uint64_t>(0);
    if (spec.minor >= 4)
        b.le<std::uint64_t>(0).le<std::uint32_t>(0).le(declared).zeros(std::size_t{15} * 8);
    EXPECT_EQ(b.size(), header_size);
    b.zeros(spec.padding);
    for (std::size_t i = 0; i < xyz.size(); ++i)
    {
        const std::size_t start = b.size();
        b.le(xyz[i][0]).le(xyz[i][1]).le(xyz[i][2]);
        b.le<std::uint16_t>(static_cast<std::uint16_t>(i)); // intensity
        const std::size_t at = rgb_offset(spec.format);
        if (at != 0)
        {
            b.zeros(at - (b.size() - start));
            b.le(rgb[i][0]).le(rgb[i][1]).le(rgb[i][2]);
        }
        b.zeros(record_length - (b.size() - start));
    }
    return b.str();
}

/// Integer coordinates spread over about ±1 km around the offset, at 1 mm resolution.
std::vector<std::array<std::int32_t, 3>> sample_xyz(std::size_t n)
{
    std::vector<std::array<std::int32_t, 3>> xyz;
    for (std::size_t i = 0; i < n; ++i)
    {
        const auto k = static_cast<std::int32_t>(i);
        xyz.push_back({(k * 7919) % 2000000 - 1000000, 1000000 - (k * 104729) % 2000000,
                       (k * 613) % 50000 - 25000});
    }
    return xyz;
}

std::vector<Rgb16> sample_rgb(std::size_t n, bool sixteen_bit)
{
    std::vector<Rgb16> rgb;
    for (std::size_t i = 0; i < n; ++i)
    {
        const auto v = static_cast<std::uint16_t>(i % 256);
        rgb.push_back(sixteen_bit ? Rgb16{static_cast<std::uint16_t>(v * 257),
                                          static_cast<std::uint16_t>((255 - v) << 8U), 0xFFFF}
                                  : Rgb16{v, static_cast<std::uint16_t>(255 - v), 255});
    }
    return rgb;
}

void check_points(const ReadResult& result, const LasSpec& spec,
                  const std::vector<std::array<std::int32_t, 3>>& xyz)
{
    ASSERT_EQ(result.points.size(), xyz.size());
    double worst = 0.0;
    for (std::size_t i = 0; i < xyz.size(); ++i)
    {
        Vec3d expected;
        for (int k = 0; k < 3; ++k)
            expected[k] = static_cast<double>(xyz[i][static_cast<std::size_t>(k)]) * spec.scale[k] +
                          spec.offset[k];
        worst = std::max(worst, (result.points.world(i) - expected).cwiseAbs().maxCoeff());
    }
    // Positions within ±1 km of the origin stored as float: error well below 1 mm.
    EXPECT_LT(worst, 2e-4);
    // The origin sits near the first point, not at zero.
    EXPECT_GT(result.points.origin.norm(), 1e5);
}

struct LasCase
{
    int minor;
    int format;
};

class LasFormats : public ::testing::TestWithParam<LasCase>
{};

TEST_P(LasFormats, ScaleOffsetColorsAndExtraBytes)
{
    const LasCase param = GetParam();
    TempDir dir;
    const auto path = dir / "points.las";
    LasSpec spec;
    spec.minor = param.minor;
    spec.format = param.format;
    spec.extra_bytes = 5;
    spec.padding = 54 + 16; // where a VLR would sit
    const auto xyz = sample_xyz(500);
    const auto rgb = sample_rgb(500, true);
    write_file(path, make_las(spec, xyz, rgb));

    const ReadResult result = read_geometry(path);
    EXPECT_EQ(result.format, FileFormat::Las);
    EXPECT_EQ(result.description, "LAS 1." + std::to_string(param.minor) + " point format " +
                                      std::to_string(param.format));
    check_points(result, spec, xyz);
    const bool has_rgb = rgb_offset(param.format) != 0;
    ASSERT_EQ(result.points.has_colors(), has_rgb);
    for (std::size_t i = 0; has_rgb && i < rgb.size(); ++i)
    {
        ASSERT_EQ(result.points.colors[i], (Color{static_cast<std::uint8_t>(rgb[i][0] >> 8U),
                                                  static_cast<std::uint8_t>(rgb[i][1] >> 8U), 255}))
            << i;
    }
}

INSTANTIATE_TEST_SUITE_P(AllPointFormats, LasFormats,
                         ::testing::Values(LasCase{0, 0}, LasCase{0, 1}, LasCase{1, 1},
                                           LasCase{2, 2}, LasCase{2, 3}, LasCase{3, 4},
                                           LasCase{3, 5}, LasCase{4, 6}, LasCase{4, 7},
                                           LasCase{4, 8}, LasCase{4, 9}, LasCase{4, 10},
                                           LasCase{4, 0}, LasCase{4, 3}),
                         [](const ::testing::TestParamInfo<LasCase>& test) {
                             return "v1_" + std::to_string(test.param.minor) + "_format" +
                                    std::to_string(test.param.format);
                         });

TEST(LasRead, EightBitColorsAreKept)
{
    TempDir dir;
    const auto path = dir / "rgb8.las";
    const LasSpec spec{.minor = 2, .format = 2};
    const auto xyz = sample_xyz(300);
    const auto rgb = sample_rgb(300, false);
    write_file(path, make_las(spec, xyz, rgb));
    const PointCloud cloud = read_point_cloud(path);
    ASSERT_TRUE(cloud.has_colors());
    for (std::size_t i = 0; i < rgb.size(); ++i)
        ASSERT_EQ(cloud.colors[i], (Color{static_cast<std::uint8_t>(rgb[i][0]),
                                          static_cast<std::uint8_t>(rgb[i][1]), 255}));
}

TEST(LasRead, Las14SixtyFourBitCountOnly)
{
    TempDir dir;
    const auto path = dir / "count64.las";
    const LasSpec spec{.minor = 4, .format = 6, .legacy_count = false};
    const auto xyz = sample_xyz(123);
    write_file(path, make_las(spec, xyz, {}));
    check_points(read_geometry(path), spec, xyz);
}

TEST(LasRead, NoPoints)
{
    TempDir dir;
    for (const int minor : {0, 2, 3, 4})
    {
        const auto path = dir / ("empty_1_" + std::to_string(minor) + ".las");
        write_file(path, make_las({.minor = minor, .format = minor == 4 ? 6 : 1}, {}, {}));
        const ReadResult result = read_geometry(path);
        EXPECT_TRUE(result.points.empty()) << minor;
    }
}

TEST(LasRead, LargeScaledCoordinatesKeepPrecision)
{
    TempDir dir;
    const auto path = dir / "utm.las";
    const LasSpec spec{.minor = 2,
                       .format = 1,
                       .scale = Vec3d(0.01, 0.01, 0.001),
                       .offset = Vec3d(-4e6, 6e6, -50.0)};
    const auto xyz = sample_xyz(1000);
    write_file(path, make_las(spec, xyz, {}));
    const ReadResult result = read_geometry(path);
    const Vec3d first(xyz[0][0] * 0.01 - 4e6, xyz[0][1] * 0.01 + 6e6, xyz[0][2] * 0.001 - 50.0);
    EXPECT_LE((result.points.origin - first).cwiseAbs().maxCoeff(), 0.5);
    // Relative positions (what algorithms use) are right to far better than 1 mm.
    for (std::size_t i = 1; i < xyz.size(); ++i)
    {
        const Vec3d d(static_cast<double>(xyz[i][0] - xyz[0][0]) * 0.01,
                      static_cast<double>(xyz[i][1] - xyz[0][1]) * 0.01,
                      static_cast<double>(xyz[i][2] - xyz[0][2]) * 0.001);
        const Vec3d got = (result.points.positions[i] - result.points.positions[0]).cast<double>();
        ASSERT_LT((got - d).cwiseAbs().maxCoeff(), 1e-3) << i;
    }
}

TEST(LasErrors, Truncated)
{
    TempDir dir;
    const auto path = dir / "short.las";
    const LasSpec spec{.minor = 2, .format = 3, .declared_extra = 1};
    const auto xyz = sample_xyz(10);
    std::string bytes = make_las(spec, xyz, sample_rgb(10, true));
    bytes += std::string(20, '\0'); // part of the 11th record
    write_file(path, bytes);
    const auto e =
        expect_io_error([&] { (void)read_geometry(path); }, path, "point record 10 of the 11");
    ASSERT_TRUE(e && e->offset());
    EXPECT_EQ(*e->offset(), 227U + 10U * 34U);

    const auto header_only = dir / "header.las";
    write_file(header_only, bytes.substr(0, 150));
    expect_io_error([&] { (void)read_geometry(header_only); }, header_only, "truncated");

    // A LAS 1.4 header that claims its full 375 bytes in a file of 229: the 64-bit point count
    // at byte 247 lies past the end (found by the readers' fuzzer: a read out of bounds).
    const auto short14 = dir / "short14.las";
    std::string v14 = make_las({.minor = 4, .format = 6, .legacy_count = false}, {}, {});
    ASSERT_GE(v14.size(), 375U);
    write_file(short14, v14.substr(0, 229));
    expect_io_error([&] { (void)read_geometry(short14); }, short14, "truncated");
}

TEST(LasErrors, CompressedLaz)
{
    TempDir dir;
    const auto path = dir / "compressed.las";
    std::string bytes = make_las({.minor = 2, .format = 3}, sample_xyz(3), sample_rgb(3, true));
    bytes[104] = static_cast<char>(3 | 0x80);
    write_file(path, bytes);
    const auto e =
        expect_io_error([&] { (void)read_geometry(path); }, path, "compressed LAZ not supported");
    ASSERT_TRUE(e && e->offset());
    EXPECT_EQ(*e->offset(), 104U);

    const auto laz = dir / "points.laz";
    write_file(laz, bytes);
    expect_io_error([&] { (void)read_geometry(laz); }, laz, "compressed LAZ not supported");
}

TEST(LasErrors, UnsupportedVersionFormatAndLayout)
{
    TempDir dir;
    const std::string good = make_las({.minor = 2, .format = 1}, sample_xyz(3), {});
    const auto check = [&](const std::string& name, std::size_t at, char value,
                           std::string_view fragment) {
        std::string bytes = good;
        bytes[at] = value;
        const auto path = dir / name;
        write_file(path, bytes);
        expect_io_error([&] { (void)read_geometry(path); }, path, fragment);
    };
    check("major.las", 24, 2, "unsupported LAS version 2.2");
    check("minor.las", 25, 5, "unsupported LAS version 1.5");
    check("format.las", 104, 11, "unsupported LAS point data format 11");
    check("record.las", 105, 20, "too short for point format 1");
    check("magic.las", 0, 'X', "not a LAS file");
    check("offset.las", 97, 0x7F, "truncated");
}

} // namespace
} // namespace pointform::test
