// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "io_test_util.h"
#include "support/test_support.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>

namespace pointform::test {
namespace {

/// One point of the test clouds: the fields x y z normal_x normal_y normal_z rgb curvature
/// hist[3], all float32 as PCL writes them (rgb is a packed 0x00RRGGBB in a float's bits).
struct PcdPoint
{
    std::array<float, 3> xyz;
    std::array<float, 3> normal;
    std::uint32_t rgb;
    float curvature;
    std::array<float, 3> hist;
};

constexpr std::uint32_t width = 4;
constexpr std::uint32_t height = 3;

bool is_missing(std::size_t i)
{
    return i == 1 || i == 5 || i == 6;
}

/// An organized 4 x 3 cloud whose points 1, 5 and 6 are NaN (missing pixels).
std::vector<PcdPoint> organized_points()
{
    std::vector<PcdPoint> points;
    const float nan = std::numeric_limits<float>::quiet_NaN();
    for (std::uint32_t i = 0; i < width * height; ++i)
    {
        const auto f = static_cast<float>(i);
        PcdPoint p{};
        p.xyz = is_missing(i) ? std::array<float, 3>{nan, nan, nan}
                              : std::array<float, 3>{0.1F * f, 1.0F + 0.2F * f, -0.05F * f};
        p.normal = is_missing(i) ? std::array<float, 3>{nan, nan, nan}
                                 : std::array<float, 3>{0.0F, 0.6F, 0.8F};
        p.rgb = ((20 * i) << 16U) | ((10 * i) << 8U) | i;
        p.curvature = 0.01F * f;
        p.hist = {f, f, f};
        points.push_back(p);
    }
    return points;
}

std::string header(std::string_view data, std::uint64_t points = std::uint64_t{width} * height)
{
    return "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\n"
           "FIELDS x y z normal_x normal_y normal_z rgb curvature hist\n"
           "SIZE 4 4 4 4 4 4 4 4 4\nTYPE F F F F F F F F F\nCOUNT 1 1 1 1 1 1 1 1 3\n"
           "WIDTH " +
           std::to_string(width) + "\nHEIGHT " + std::to_string(height) +
           "\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " + std::to_string(points) + "\nDATA " +
           std::string(data) + "\n";
}

std::string ascii_pcd(const std::vector<PcdPoint>& points)
{
    std::string text = header("ascii");
    for (const PcdPoint& p : points)
    {
        const auto number = [](float v) {
            return std::isnan(v) ? std::string("nan") : std::to_string(v);
        };
        for (const float v : p.xyz)
            text += number(v) + " ";
        for (const float v : p.normal)
            text += number(v) + " ";
        text += std::to_string(p.rgb) + " " + std::to_string(p.curvature);
        for (const float v : p.hist)
            text += " " + std::to_string(v);
        text += "\n";
    }
    return text;
}

std::string aos_bytes(const std::vector<PcdPoint>& points)
{
    Bytes b;
    for (const PcdPoint& p : points)
    {
        for (const float v : p.xyz)
            b.le(v);
        for (const float v : p.normal)
            b.le(v);
        b.le(p.rgb).le(p.curvature);
        for (const float v : p.hist)
            b.le(v);
    }
    return b.str();
}

/// Fields one after another: all x, then all y, ... (what binary_compressed compresses).
std::string soa_bytes(const std::vector<PcdPoint>& points)
{
    Bytes b;
    for (int k = 0; k < 3; ++k)
        for (const PcdPoint& p : points)
            b.le(p.xyz[k]);
    for (int k = 0; k < 3; ++k)
        for (const PcdPoint& p : points)
            b.le(p.normal[k]);
    for (const PcdPoint& p : points)
        b.le(p.rgb);
    for (const PcdPoint& p : points)
        b.le(p.curvature);
    for (const PcdPoint& p : points)
        for (const float v : p.hist)
            b.le(v);
    return b.str();
}

std::string compressed_pcd(const std::vector<PcdPoint>& points)
{
    const std::string raw = soa_bytes(points);
    const std::string lzf = lzf_literal_encode(raw);
    Bytes b;
    b.text(header("binary_compressed"))
        .le(static_cast<std::uint32_t>(lzf.size()))
        .le(static_cast<std::uint32_t>(raw.size()))
        .text(lzf);
    return b.str();
}

void check_organized(const ReadResult& result)
{
    const std::vector<PcdPoint> points = organized_points();
    EXPECT_EQ(result.format, FileFormat::Pcd);
    EXPECT_EQ(result.dropped_points, 3U);
    const PointCloud& cloud = result.points;
    ASSERT_EQ(cloud.size(), 9U);
    ASSERT_TRUE(cloud.has_normals());
    ASSERT_TRUE(cloud.has_colors());
    std::size_t k = 0;
    for (std::size_t i = 0; i < points.size(); ++i)
    {
        if (is_missing(i))
            continue;
        const Vec3d expected(points[i].xyz[0], points[i].xyz[1], points[i].xyz[2]);
        EXPECT_LT((cloud.world(k) - expected).norm(), 1e-5) << i;
        EXPECT_LT((cloud.normals[k] - Vec3f(0.0F, 0.6F, 0.8F)).norm(), 1e-6F);
        const std::uint32_t c = points[i].rgb;
        EXPECT_EQ(cloud.colors[k],
                  (Color{static_cast<std::uint8_t>(c >> 16U), static_cast<std::uint8_t>(c >> 8U),
                         static_cast<std::uint8_t>(c)}));
        ++k;
    }
    EXPECT_NE(result.description.find("organized 4 x 3"), std::string::npos);
}

/// Writes `content` to `path`, reads it back and checks that it holds organized_points() (see
/// check_organized) and that its description names `kind`.
void check_organized_file(const std::filesystem::path& path, const std::string& content,
                          std::string_view kind)
{
    write_file(path, content);
    const ReadResult result = read_geometry(path);
    EXPECT_NE(result.description.find(kind), std::string::npos);
    check_organized(result);
}

TEST(PcdRead, AsciiOrganizedWithNaNs)
{
    TempDir dir;
    check_organized_file(dir / "ascii.pcd", ascii_pcd(organized_points()), "PCD ascii");
}

TEST(PcdRead, BinaryOrganizedWithNaNs)
{
    TempDir dir;
    check_organized_file(dir / "binary.pcd", header("binary") + aos_bytes(organized_points()),
                         "PCD binary");
}

TEST(PcdRead, BinaryCompressedOrganizedWithNaNs)
{
    TempDir dir;
    check_organized_file(dir / "compressed.pcd", compressed_pcd(organized_points()),
                         "PCD binary_compressed");
}

TEST(PcdRead, ErrorPolicyRejectsNaNs)
{
    TempDir dir;
    const std::string head = header("binary");
    expect_file_error_at_offset(dir / "binary.pcd", head + aos_bytes(organized_points()),
                                "non-finite",
                                head.size() + sizeof(float) * 11, // point 1: 11 floats a point
                                {.non_finite = NonFinitePolicy::Error});
}

TEST(PcdRead, BackReferencesInLzf)
{
    // Four points at (1, 2, 3): each field block is one value repeated, coded as a 4-byte
    // literal and a 12-byte back reference at distance 4 (length 12 = 7 + 3 + 2).
    Bytes stream;
    for (const float v : {1.0F, 2.0F, 3.0F})
    {
        stream.le<std::uint8_t>(3).le(v);
        stream.le<std::uint8_t>(0xE0).le<std::uint8_t>(3).le<std::uint8_t>(3);
    }
    TempDir dir;
    const auto path = dir / "backref.pcd";
    Bytes file;
    file.text(
            "VERSION .7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 4\n"
            "HEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 4\nDATA binary_compressed\n")
        .le(static_cast<std::uint32_t>(stream.size()))
        .le<std::uint32_t>(48)
        .text(stream.str());
    write_file(path, file.str());
    const ReadResult result = read_geometry(path);
    ASSERT_EQ(result.points.size(), 4U);
    for (std::size_t i = 0; i < 4; ++i)
        EXPECT_EQ(result.points.world(i), Vec3d(1, 2, 3));
    EXPECT_FALSE(result.points.has_normals());
    EXPECT_FALSE(result.points.has_colors());
}

TEST(PcdRead, MixedTypesAndPackedRgbaAsUnsigned)
{
    TempDir dir;
    const auto path = dir / "mixed.pcd";
    Bytes b;
    b.text(
        "FIELDS x y z _ rgba intensity\nSIZE 8 4 2 1 4 1\nTYPE F I U U U I\nWIDTH 2\n"
        "POINTS 2\nDATA binary\n");
    b.le(1.5)
        .le<std::int32_t>(-7)
        .le<std::uint16_t>(65000)
        .le<std::uint8_t>(0)
        .le<std::uint32_t>(0xFF102030U)
        .le<std::int8_t>(-1);
    b.le(-2.5)
        .le<std::int32_t>(8)
        .le<std::uint16_t>(3)
        .le<std::uint8_t>(0)
        .le<std::uint32_t>(0x80FFFFFFU)
        .le<std::int8_t>(1);
    write_file(path, b.str());
    const PointCloud cloud = read_point_cloud(path);
    ASSERT_EQ(cloud.size(), 2U);
    EXPECT_EQ(cloud.world(0), Vec3d(1.5, -7, 65000));
    EXPECT_EQ(cloud.world(1), Vec3d(-2.5, 8, 3));
    EXPECT_EQ(cloud.colors[0], (Color{0x10, 0x20, 0x30}));
    EXPECT_EQ(cloud.colors[1], (Color{255, 255, 255}));
}

TEST(PcdRead, AsciiRgbWrittenAsFloat)
{
    // Older PCL printed the float whose bits hold the color.
    const std::uint32_t packed = 0x00FF8040U;
    const float as_float = std::bit_cast<float>(packed);
    char text[64];
    std::snprintf(text, sizeof(text), "%.9g", static_cast<double>(as_float));
    TempDir dir;
    const auto path = dir / "float_rgb.pcd";
    write_file(path, std::string("FIELDS x y z rgb\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 1 1 1 1\n"
                                 "WIDTH 1\nHEIGHT 1\nPOINTS 1\nDATA ascii\n1 2 3 ") +
                         text + "\n");
    EXPECT_EQ(read_point_cloud(path).colors[0], (Color{0xFF, 0x80, 0x40}));
}

TEST(PcdRead, OrganizedCloudKeepsItsSensor)
{
    // A depth image (HEIGHT > 1) was seen from VIEWPOINT's position; a plain list of points
    // (HEIGHT 1) says nothing of where it was seen from.
    TempDir dir;
    const auto sensor_of = [&](const std::string& name, const std::string& shape,
                               const std::string& viewpoint) {
        write_file(dir / name, "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\n" + shape + viewpoint +
                                   "POINTS 4\nDATA ascii\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n");
        return read_point_cloud(dir / name).sensor;
    };
    const std::string viewpoint = "VIEWPOINT 1.5 -2 30 1 0 0 0\n";
    EXPECT_EQ(sensor_of("organized.pcd", "WIDTH 2\nHEIGHT 2\n", viewpoint), Vec3d(1.5, -2.0, 30.0));
    // No VIEWPOINT: PCL's default, the origin.
    EXPECT_EQ(sensor_of("origin.pcd", "WIDTH 2\nHEIGHT 2\n", ""), Vec3d::Zero());
    EXPECT_FALSE(sensor_of("list.pcd", "WIDTH 4\nHEIGHT 1\n", viewpoint).has_value());
}

TEST(PcdErrors, MalformedViewpoint)
{
    TempDir dir;
    const std::string rest = "POINTS 1\nDATA ascii\n0 0 0\n";
    const std::string head = "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 1\n";
    expect_file_error(dir / "short.pcd", head + "VIEWPOINT 0 0 0 1\n" + rest, "7 values");
    expect_file_error(dir / "word.pcd", head + "VIEWPOINT 0 x 0 1 0 0 0\n" + rest, "'x'");
    expect_file_error(dir / "nan.pcd", head + "VIEWPOINT 0 0 nan 1 0 0 0\n" + rest, "VIEWPOINT");
    // The rotation is not used, but a malformed one is a malformed file all the same.
    expect_file_error(dir / "rotation.pcd", head + "VIEWPOINT 0 0 0 1 0 q 0\n" + rest, "'q'");
    expect_file_error(dir / "infinite.pcd", head + "VIEWPOINT 0 0 0 inf 0 0 0\n" + rest,
                      "VIEWPOINT");
}

TEST(PcdErrors, PointsMismatch)
{
    TempDir dir;
    expect_file_error(dir / "points.pcd", header("binary", 10) + aos_bytes(organized_points()),
                      "does not match WIDTH x HEIGHT");
}

TEST(PcdErrors, TruncatedBinary)
{
    TempDir dir;
    const std::string head = header("binary");
    std::string data = aos_bytes(organized_points());
    data.resize(data.size() - 10);
    expect_file_error_at_offset(dir / "short.pcd", head + data, "point 11 of the 12",
                                head.size() + std::size_t{11} * 11 * sizeof(float));
}

TEST(PcdErrors, BinaryLongerThanPoints)
{
    TempDir dir;
    expect_file_error(dir / "long.pcd", header("binary") + aos_bytes(organized_points()) + "junk",
                      "4 bytes after");
}

TEST(PcdErrors, CompressedSizesAndCorruptStream)
{
    TempDir dir;
    const std::vector<PcdPoint> points = organized_points();
    const std::string raw = soa_bytes(points);
    const std::string lzf = lzf_literal_encode(raw);

    expect_file_error(dir / "wrong_size.pcd",
                      Bytes()
                          .text(header("binary_compressed"))
                          .le(static_cast<std::uint32_t>(lzf.size()))
                          .le(static_cast<std::uint32_t>(raw.size() - 4))
                          .text(lzf)
                          .str(),
                      "uncompressed size");

    expect_file_error(dir / "truncated.pcd",
                      Bytes()
                          .text(header("binary_compressed"))
                          .le(static_cast<std::uint32_t>(lzf.size()))
                          .le(static_cast<std::uint32_t>(raw.size()))
                          .text(std::string_view(lzf).substr(0, lzf.size() / 2))
                          .str(),
                      "truncated");

    std::string bad = lzf;
    bad[0] = static_cast<char>(0x20); // a back reference before any output
    expect_file_error(dir / "corrupt.pcd",
                      Bytes()
                          .text(header("binary_compressed"))
                          .le(static_cast<std::uint32_t>(bad.size()))
                          .le(static_cast<std::uint32_t>(raw.size()))
                          .text(bad)
                          .str(),
                      "corrupt LZF");

    expect_file_error(dir / "headless.pcd", header("binary_compressed") + "ab", "truncated");
}

TEST(PcdErrors, AsciiLinesAndValues)
{
    TempDir dir;
    const std::string head =
        "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 3\nHEIGHT 1\n"
        "POINTS 3\nDATA ascii\n";
    expect_file_error_at_line(dir / "fewer.pcd", head + "0 0 0\n1 1 1\n", "2 of the 3 POINTS", 10);
    expect_file_error_at_line(dir / "more.pcd", head + "0 0 0\n1 1 1\n2 2 2\n3 3 3\n",
                              "more data lines", 11);
    expect_file_error_at_line(dir / "values.pcd", head + "0 0 0\n1 1\n2 2 2\n",
                              "2 values, expected 3", 9);
    expect_file_error(dir / "garbage.pcd", head + "0 0 0\n1 one 1\n2 2 2\n", "'one'");
}

TEST(PcdErrors, MalformedHeaders)
{
    TempDir dir;
    expect_file_error(dir / "nodata.pcd", "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 1\n",
                      "no DATA");
    expect_file_error(dir / "noxyz.pcd",
                      "FIELDS x y\nSIZE 4 4\nTYPE F F\nWIDTH 1\nDATA ascii\n0 0\n",
                      "no x, y and z");
    expect_file_error(dir / "sizes.pcd",
                      "FIELDS x y z\nSIZE 4 4\nTYPE F F F\nWIDTH 1\nDATA ascii\n0 0 0\n",
                      "SIZE has 2 values");
    expect_file_error(dir / "type.pcd",
                      "FIELDS x y z\nSIZE 4 4 4\nTYPE F F Q\nWIDTH 1\nDATA ascii\n0 0 0\n",
                      "unknown field type");
    expect_file_error(dir / "fsize.pcd",
                      "FIELDS x y z\nSIZE 4 4 2\nTYPE F F F\nWIDTH 1\nDATA ascii\n0 0 0\n",
                      "unsupported size");
    expect_file_error(dir / "kind.pcd", "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 1\nDATA zip\n",
                      "unknown DATA");
    expect_file_error(dir / "width.pcd",
                      "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nDATA ascii\n0 0 0\n", "no WIDTH");
}

TEST(PcdErrors, HugeDeclaredCountsFailCleanly)
{
    TempDir dir;
    expect_file_error(dir / "huge.pcd",
                      "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 100000000000\nHEIGHT 1\n"
                      "POINTS 100000000000\nDATA binary\n0123456789ab",
                      "truncated");

    expect_file_error(dir / "huge_compressed.pcd",
                      Bytes()
                          .text("FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 300000000\n"
                                "HEIGHT 1\nPOINTS 300000000\nDATA binary_compressed\n")
                          .le<std::uint32_t>(4)
                          .le<std::uint32_t>(3600000000U)
                          .text("abcd")
                          .str(),
                      "too small");
}

} // namespace
} // namespace pointform::test
