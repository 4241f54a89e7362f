// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "io_test_util.h"
#include "support/test_support.h"
#include "support/thread_counts.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <set>

namespace pointform::test {
namespace {

TEST(PlyRoundTrip, BinaryWithAllAttributes)
{
    TempDir dir;
    const auto path = dir / "cloud.ply";
    const PointCloud cloud = make_cloud(500, true, true, true);
    write_point_cloud(path, cloud);
    EXPECT_NE(read_file(path).find("format binary_little_endian 1.0"), std::string::npos);

    const ReadResult result = read_geometry(path);
    EXPECT_EQ(result.format, FileFormat::Ply);
    EXPECT_EQ(result.description, "PLY binary_little_endian");
    EXPECT_TRUE(result.triangles.empty());
    EXPECT_EQ(result.dropped_points, 0U);
    expect_same_cloud(cloud, result.points, 0.0); // float in, float out: exact
}

TEST(PlyRoundTrip, AsciiWithAllAttributes)
{
    TempDir dir;
    const auto path = dir / "cloud.ply";
    const PointCloud cloud = make_cloud(300, true, true, true);
    write_point_cloud(path, cloud, {.ascii = true});
    const std::string text = read_file(path);
    EXPECT_NE(text.find("format ascii 1.0"), std::string::npos);
    EXPECT_NE(text.find("property uchar red"), std::string::npos);
    EXPECT_NE(text.find("property float radius"), std::string::npos);

    const ReadResult result = read_geometry(path);
    EXPECT_EQ(result.description, "PLY ascii");
    expect_same_cloud(cloud, result.points, 0.0); // shortest float text round-trips exactly
}

TEST(PlyRoundTrip, PositionsOnlyHaveNoAttributes)
{
    TempDir dir;
    const auto path = dir / "plain.ply";
    const PointCloud cloud = make_cloud(50, false, false, false);
    write_point_cloud(path, cloud);
    const PointCloud back = read_point_cloud(path);
    expect_same_cloud(cloud, back, 0.0);
    EXPECT_EQ(read_file(path).find("nx"), std::string::npos);
}

TEST(PlyRoundTrip, GeoreferencedOriginKeepsPrecision)
{
    TempDir dir;
    const Vec3d origin(512345.0, 4012345.0, 120.0);
    const PointCloud cloud = make_cloud(400, true, false, false, origin, 50.0);
    for (const bool ascii : {false, true})
    {
        const auto path = dir / (ascii ? "geo_ascii.ply" : "geo_binary.ply");
        write_point_cloud(path, cloud, {.ascii = ascii});
        EXPECT_NE(read_file(path).find("property double x"), std::string::npos);
        const PointCloud back = read_point_cloud(path);
        ASSERT_EQ(back.size(), cloud.size());
        // The reader re-centres on the first point, so compare world coordinates.
        EXPECT_LT((back.origin - cloud.world(0)).cwiseAbs().maxCoeff(), 1.0);
        for (std::size_t i = 0; i < cloud.size(); ++i)
            ASSERT_LT((back.world(i) - cloud.world(i)).norm(), 1e-4) << i;
        expect_same_cloud(cloud, back, 1e-6);
    }
}

TEST(PlyRoundTrip, FloatInputWithAnOriginGoesBackOutAsTheSameFloats)
{
    // A float PLY whose first point is away from zero is read with an origin (its rounded first
    // point); its world coordinates are still the file's floats, so it is written back with
    // float x y z (not doubles at twice the size) and the very same values.
    TempDir dir;
    std::mt19937 random(5);
    std::uniform_real_distribution<float> around(-3.0F, 3.0F);
    std::vector<Vec3f> floats;
    Bytes b;
    b.text(
        "ply\nformat binary_little_endian 1.0\nelement vertex 3000\nproperty float x\n"
        "property float y\nproperty float z\nend_header\n");
    for (int i = 0; i < 3000; ++i)
    {
        const Vec3f p(7.6F + around(random), -12.3F + around(random), 0.01F * around(random));
        floats.push_back(p);
        b.le(p.x()).le(p.y()).le(p.z());
    }
    write_file(dir / "in.ply", b.str());
    const PointCloud cloud = read_point_cloud(dir / "in.ply");
    ASSERT_FALSE(cloud.origin.isZero(0.0));
    write_point_cloud(dir / "out.ply", cloud);
    const std::string text = read_file(dir / "out.ply");
    EXPECT_NE(text.find("property float x"), std::string::npos);
    EXPECT_EQ(text.find("property double"), std::string::npos);
    const PointCloud back = read_point_cloud(dir / "out.ply");
    ASSERT_EQ(back.size(), floats.size());
    for (std::size_t i = 0; i < floats.size(); ++i)
        ASSERT_EQ(back.world(i), floats[i].cast<double>()) << i;

    // One coordinate that no float holds, and the file goes back to doubles.
    PointCloud finer = cloud;
    finer.positions[1234].x() = std::nextafter(finer.positions[1234].x(), 100.0F);
    finer.origin.x() += 1e-9;
    write_point_cloud(dir / "finer.ply", finer);
    EXPECT_NE(read_file(dir / "finer.ply").find("property double x"), std::string::npos);
    const PointCloud finer_back = read_point_cloud(dir / "finer.ply");
    for (std::size_t i = 0; i < finer.size(); ++i)
        ASSERT_LT((finer_back.world(i) - finer.world(i)).norm(), 1e-5) << i;
}

TEST(PlyRoundTrip, MeshBinaryAndAscii)
{
    TempDir dir;
    const TriMesh mesh = make_grid_mesh(7, 9);
    for (const bool ascii : {false, true})
    {
        const auto path = dir / (ascii ? "mesh_ascii.ply" : "mesh_binary.ply");
        write_mesh(path, mesh, {.ascii = ascii});
        EXPECT_NE(read_file(path).find("property list uchar int vertex_indices"),
                  std::string::npos);
        const TriMesh back = read_mesh(path);
        expect_same_cloud(mesh.vertices, back.vertices, 0.0);
        EXPECT_EQ(back.triangles, mesh.triangles);
    }
}

/// A PLY file exercising every scalar type, list skipping, an extra element before the vertices
/// and the faces before the vertices, in the given byte order.
std::string every_type_ply(std::endian order)
{
    Bytes b;
    b.text("ply\n");
    b.text(order == std::endian::big ? "format binary_big_endian 1.0\n"
                                     : "format binary_little_endian 1.0\n");
    b.text(
        "comment every scalar type\n"
        "obj_info made by hand\n"
        "element face 2\n"
        "property uchar flags\n"
        "property list ushort uint vertex_indices\n"
        "property list uchar float texcoord\n"
        "element range_grid 3\n"
        "property list uchar int vertex_indices\n"
        "element vertex 4\n"
        "property short x\n"
        "property ushort y\n"
        "property int z\n"
        "property double nx\n"
        "property float32 ny\n"
        "property int8 nz\n"
        "property uchar red\n"
        "property uint16 green\n"
        "property float blue\n"
        "property uint extra\n"
        "property list uint8 int16 neighbours\n"
        "property char extra2\n"
        "property float64 radius\n"
        "end_header\n");
    // faces: a quad and a triangle, each with a 2-float texcoord list
    b.put<std::uint8_t>(1, order).put<std::uint16_t>(4, order);
    for (const std::uint32_t v : {0U, 1U, 2U, 3U})
        b.put(v, order);
    b.put<std::uint8_t>(2, order).put(0.5F, order).put(0.25F, order);
    b.put<std::uint8_t>(0, order).put<std::uint16_t>(3, order);
    for (const std::uint32_t v : {3U, 2U, 1U})
        b.put(v, order);
    b.put<std::uint8_t>(0, order);
    // range_grid: lists of 0 or 1 int
    b.put<std::uint8_t>(1, order).put<std::int32_t>(2, order);
    b.put<std::uint8_t>(0, order);
    b.put<std::uint8_t>(1, order).put<std::int32_t>(3, order);
    // vertices
    for (int i = 0; i < 4; ++i)
    {
        b.put<std::int16_t>(static_cast<std::int16_t>(-1000 + i), order);
        b.put<std::uint16_t>(static_cast<std::uint16_t>(60000 + i), order);
        b.put<std::int32_t>(-2000000000 + i, order);
        b.put<double>(0.0, order).put<float>(0.0F, order).put<std::int8_t>(-1, order);
        b.put<std::uint8_t>(static_cast<std::uint8_t>(10 * i), order);
        b.put<std::uint16_t>(static_cast<std::uint16_t>(0x1200 * (i + 1)), order);
        b.put<float>(0.5F, order);
        b.put<std::uint32_t>(0xDEADBEEFU, order);
        b.put<std::uint8_t>(static_cast<std::uint8_t>(i), order);
        for (int k = 0; k < i; ++k)
            b.put<std::int16_t>(static_cast<std::int16_t>(k), order);
        b.put<std::int8_t>(-5, order);
        b.put<double>(0.125 * (i + 1), order);
    }
    return b.str();
}

void check_every_type(const ReadResult& result)
{
    const PointCloud& cloud = result.points;
    ASSERT_EQ(cloud.size(), 4U);
    ASSERT_TRUE(cloud.has_normals());
    ASSERT_TRUE(cloud.has_colors());
    ASSERT_TRUE(cloud.has_radii());
    for (std::size_t i = 0; i < 4; ++i)
    {
        const double k = static_cast<double>(i);
        EXPECT_EQ(cloud.world(i), Vec3d(-1000.0 + k, 60000.0 + k, -2000000000.0 + k)) << i;
        EXPECT_EQ(cloud.normals[i], Vec3f(0.0F, 0.0F, -1.0F));
        EXPECT_EQ(cloud.colors[i].r, 10 * i);
        EXPECT_EQ(cloud.colors[i].g, 0x12 * (i + 1)); // 16-bit: high byte
        EXPECT_EQ(cloud.colors[i].b, 128);            // float 0.5
        EXPECT_FLOAT_EQ(cloud.radii[i], 0.125F * static_cast<float>(i + 1));
    }
    const std::vector<Triangle> expected = {{0, 1, 2}, {0, 2, 3}, {3, 2, 1}};
    EXPECT_EQ(result.triangles, expected);
}

TEST(PlyRead, BigEndianEveryScalarTypeAndElementOrder)
{
    TempDir dir;
    const auto path = dir / "big.ply";
    write_file(path, every_type_ply(std::endian::big));
    const ReadResult result = read_geometry(path);
    EXPECT_EQ(result.description, "PLY binary_big_endian");
    check_every_type(result);
}

TEST(PlyRead, LittleEndianEveryScalarTypeAndElementOrder)
{
    TempDir dir;
    const auto path = dir / "little.ply";
    write_file(path, every_type_ply(std::endian::little));
    check_every_type(read_geometry(path));
}

TEST(PlyRead, AsciiRangeScanWithCrlfAndRangeGrid)
{
    TempDir dir;
    const auto path = dir / "scan.ply";
    write_file(path,
               "ply\r\nformat ascii 1.0\r\nobj_info is_cyberware_data 1\r\n"
               "obj_info num_cols 2\r\nelement vertex 3\r\nproperty float x\r\n"
               "property float y\r\nproperty float z\r\nelement range_grid 4\r\n"
               "property list uchar int vertex_indices\r\nend_header\r\n"
               "-0.06325 0.0359793 0.0420873 \r\n0.1 0.2 0.3 \r\n1e-3 -2E-2 +3.5 \r\n"
               "1 0\r\n0\r\n1 1\r\n1 2\r\n");
    const ReadResult result = read_geometry(path);
    ASSERT_EQ(result.points.size(), 3U);
    EXPECT_TRUE(result.triangles.empty());
    EXPECT_FALSE(result.points.has_normals());
    EXPECT_EQ(result.points.positions[0], Vec3f(-0.06325F, 0.0359793F, 0.0420873F));
    EXPECT_EQ(result.points.positions[2], Vec3f(1e-3F, -2e-2F, 3.5F));
}

TEST(PlyRead, AsciiFloatColorsPolygonsAndVertexIndex)
{
    TempDir dir;
    const auto path = dir / "poly.ply";
    write_file(path,
               "ply\nformat ascii 1.0\nelement vertex 5\nproperty double x\n"
               "property double y\nproperty double z\nproperty float red\n"
               "property float green\nproperty float blue\nproperty uchar alpha\n"
               "element face 1\nproperty list uchar uint vertex_index\nend_header\n"
               "0 0 0 1 0 0.5 255\n1 0 0 0 1 0.5 255\n1 1 0 0 0 0 255\n"
               "0.5 1.5 0 1 1 1 255\n0 1 0 0.2 0.4 0.6 255\n"
               "5 0 1 2 3 4\n");
    const ReadResult result = read_geometry(path);
    ASSERT_EQ(result.points.size(), 5U);
    EXPECT_EQ(result.points.colors[0], (Color{255, 0, 128}));
    EXPECT_EQ(result.points.colors[4], (Color{51, 102, 153}));
    const std::vector<Triangle> fan = {{0, 1, 2}, {0, 2, 3}, {0, 3, 4}};
    EXPECT_EQ(result.triangles, fan);
}

TEST(PlyRead, EmptyVertexElementGivesEmptyCloud)
{
    TempDir dir;
    const auto path = dir / "none.ply";
    write_file(path,
               "ply\nformat binary_little_endian 1.0\nelement vertex 0\n"
               "property float x\nproperty float y\nproperty float z\nend_header\n");
    EXPECT_TRUE(read_point_cloud(path).empty());
}

std::string small_binary_ply(std::uint64_t declared, std::size_t written)
{
    Bytes b;
    b.text("ply\nformat binary_little_endian 1.0\nelement vertex " + std::to_string(declared) +
           "\nproperty float x\nproperty float y\nproperty float z\nend_header\n");
    for (std::size_t i = 0; i < written; ++i)
        b.le(1.0F * static_cast<float>(i)).le(2.0F).le(3.0F);
    return b.str();
}

TEST(PlyErrors, TruncatedBinaryNamesTheByteOffset)
{
    TempDir dir;
    std::string bytes = small_binary_ply(10, 10);
    const std::size_t header = bytes.size() - 120;
    bytes.resize(bytes.size() - 5); // last vertex loses 5 bytes
    expect_file_error_at_offset(dir / "truncated.ply", bytes, "truncated",
                                header + std::size_t{9 * 12 + 4}); // x of vertex 9 read, y cut
}

TEST(PlyErrors, HeaderCountLargerThanBinaryData)
{
    TempDir dir;
    const auto e = expect_file_error(dir / "lying.ply", small_binary_ply(12, 8), "vertex 8 of 12");
    ASSERT_TRUE(e);
    EXPECT_TRUE(e->offset());
}

TEST(PlyErrors, HeaderCountSmallerThanBinaryData)
{
    TempDir dir;
    expect_file_error(dir / "short_count.ply", small_binary_ply(3, 5), "do not match");
}

TEST(PlyErrors, HugeDeclaredCountFailsCleanly)
{
    TempDir dir;
    expect_file_error(dir / "huge.ply", small_binary_ply(1000000000000ULL, 2), "truncated");
    expect_file_error(dir / "huge_ascii.ply",
                      "ply\nformat ascii 1.0\nelement vertex 4000000000\nproperty float x\n"
                      "property float y\nproperty float z\nelement face 999999999999\n"
                      "property list uchar int vertex_indices\nend_header\n0 0 0\n",
                      "file ends after 1 of the 4000000000 vertex");
    expect_file_error(dir / "too_many.ply",
                      "ply\nformat ascii 1.0\nelement vertex 5000000000\nproperty float x\n"
                      "property float y\nproperty float z\nelement face 1\n"
                      "property list uchar int vertex_indices\nend_header\n0 0 0\n",
                      "too many vertices");
}

const char* const ascii_header =
    "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
    "property float y\nproperty float z\n";

TEST(PlyErrors, AsciiCountLargerThanData)
{
    TempDir dir;
    expect_file_error_at_line(dir / "lying.ply",
                              std::string(ascii_header) + "end_header\n0 0 0\n1 1 1\n",
                              "file ends after 2 of the 3 vertex", 10);
}

TEST(PlyErrors, AsciiLineWithTooFewValues)
{
    TempDir dir;
    const auto e = expect_file_error_at_line(
        dir / "few.ply", std::string(ascii_header) + "end_header\n0 0 0\n1 1\n2 2 2\n",
        "fewer values", 9);
    ASSERT_TRUE(e);
    EXPECT_NE(std::string(e->what()).find(":9"), std::string::npos);
}

TEST(PlyErrors, AsciiLineWithTooManyValues)
{
    TempDir dir;
    expect_file_error_at_line(dir / "many.ply",
                              std::string(ascii_header) + "end_header\n0 0 0\n1 1 1 1\n2 2 2\n",
                              "more values", 9);
}

TEST(PlyErrors, AsciiMoreLinesThanDeclared)
{
    TempDir dir;
    expect_file_error_at_line(
        dir / "extra.ply", std::string(ascii_header) + "end_header\n0 0 0\n1 1 1\n2 2 2\n3 3 3\n",
        "more data", 11);
}

TEST(PlyErrors, GarbageNumber)
{
    TempDir dir;
    expect_file_error_at_line(dir / "garbage.ply",
                              std::string(ascii_header) + "end_header\n0 0 0\n1 1.5x 1\n2 2 2\n",
                              "'1.5x'", 9);
}

TEST(PlyErrors, NonFiniteCoordinates)
{
    TempDir dir;
    const auto path = dir / "nan.ply";
    expect_file_error_at_line(
        path, std::string(ascii_header) + "end_header\n0 0 0\nnan 1 1\n2 inf 2\n", "non-finite", 9);

    const ReadResult dropped = read_geometry(path, {.non_finite = NonFinitePolicy::Drop});
    EXPECT_EQ(dropped.points.size(), 1U);
    EXPECT_EQ(dropped.dropped_points, 2U);

    Bytes b;
    b.text(
        "ply\nformat binary_little_endian 1.0\nelement vertex 2\nproperty float x\n"
        "property float y\nproperty float z\nend_header\n");
    const std::size_t data = b.size();
    b.le(0.0F).le(0.0F).le(0.0F).le(1.0F).le(std::numeric_limits<float>::infinity()).le(1.0F);
    expect_file_error_at_offset(dir / "nan_binary.ply", b.str(), "non-finite", data + 12);
}

/// Binary vertices of one size are read in parallel blocks (CloudBuilder::add_all()): the cloud,
/// the drops and the error must be those of reading them one by one, as the ascii reader does,
/// at any thread count, with non-finite points in different blocks.
TEST(PlyErrors, BinaryVerticesReadInParallelAsOneByOne)
{
    TempDir dir;
    constexpr std::size_t count = 200000;
    const std::set<std::size_t> bad = {70001, 150000};
    const char* properties =
        "property double x\nproperty double y\nproperty double z\nproperty float nx\n"
        "property float ny\nproperty float nz\nproperty uchar red\nproperty uchar green\n"
        "property uchar blue\nproperty int unused\nproperty float radius\nend_header\n";
    Bytes b;
    b.text("ply\nformat binary_little_endian 1.0\nelement vertex " + std::to_string(count) + "\n")
        .text(properties);
    const std::size_t data = b.size();
    std::string ascii = "ply\nformat ascii 1.0\nelement vertex " + std::to_string(count) + "\n";
    ascii += properties;
    for (std::size_t i = 0; i < count; ++i)
    {
        const double t = static_cast<double>(i);
        const double x =
            bad.contains(i) ? std::numeric_limits<double>::quiet_NaN() : 500000.0 + std::sin(t);
        const auto n = static_cast<float>(i % 7) - 3.0F;
        b.le(x).le(std::cos(t)).le(0.001 * t).le(n).le(1.0F).le(0.0F);
        b.le(static_cast<std::uint8_t>(i))
            .le(std::uint8_t{7})
            .le(static_cast<std::uint8_t>(i / 256));
        b.le(static_cast<std::int32_t>(i)).le(static_cast<float>(t) * 0.5F);
        char line[256];
        std::snprintf(line, sizeof line, "%.17g %.17g %.17g %.9g 1 0 %u 7 %u %zu %.9g\n", x,
                      std::cos(t), 0.001 * t, static_cast<double>(n),
                      static_cast<unsigned>(i % 256), static_cast<unsigned>((i / 256) % 256), i,
                      static_cast<double>(static_cast<float>(t) * 0.5F));
        ascii += line;
    }
    const auto binary_path = dir / "binary.ply";
    const auto ascii_path = dir / "ascii.ply";
    write_file(binary_path, b.str());
    write_file(ascii_path, ascii);

    const ReadResult one_by_one = read_geometry(ascii_path, {.non_finite = NonFinitePolicy::Drop});
    ASSERT_EQ(one_by_one.points.size(), count - bad.size());
    EXPECT_EQ(one_by_one.dropped_points, bad.size());
    const auto runs = test::at_thread_counts(
        [&] { return read_geometry(binary_path, {.non_finite = NonFinitePolicy::Drop}); },
        {.min_multi_block_loops = 2});
    for (const ReadResult& read : runs)
    {
        EXPECT_EQ(read.dropped_points, bad.size());
        EXPECT_EQ(read.points.origin, one_by_one.points.origin);
        EXPECT_EQ(read.points.positions, one_by_one.points.positions);
        EXPECT_EQ(read.points.normals, one_by_one.points.normals);
        EXPECT_EQ(read.points.radii, one_by_one.points.radii);
        ASSERT_EQ(read.points.colors.size(), one_by_one.points.colors.size());
        for (std::size_t i = 0; i < read.points.colors.size(); ++i)
        {
            const Color c = read.points.colors[i];
            const Color d = one_by_one.points.colors[i];
            ASSERT_TRUE(c.r == d.r && c.g == d.g && c.b == d.b) << i;
        }
    }
    // Without dropping: the first bad point, where it starts.
    const std::size_t stride = 3 * 8 + 3 * 4 + 3 + 4 + 4;
    (void)expect_file_error_at_offset(dir / "bad.ply", b.str(), "point 70001",
                                      data + 70001 * stride);
}

TEST(PlyErrors, DroppingVerticesOfAMeshIsAnError)
{
    TempDir dir;
    expect_file_error(dir / "nan_mesh.ply",
                      std::string(ascii_header) +
                          "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
                          "0 0 0\nnan 1 1\n2 2 2\n3 0 1 2\n",
                      "face indices would be wrong", {.non_finite = NonFinitePolicy::Drop});
}

TEST(PlyErrors, FaceIndexOutOfRange)
{
    TempDir dir;
    expect_file_error_at_line(
        dir / "bad_face.ply",
        std::string(ascii_header) +
            "element face 2\nproperty list uchar int vertex_indices\nend_header\n"
            "0 0 0\n1 1 1\n2 2 2\n3 0 1 2\n3 0 1 3\n",
        "refers to vertex 3", 14);

    expect_file_error(dir / "negative_face.ply",
                      std::string(ascii_header) +
                          "element face 1\nproperty list uchar int vertex_indices\n"
                          "end_header\n0 0 0\n1 1 1\n2 2 2\n3 0 -1 2\n",
                      "refers to vertex -1");

    Bytes b;
    b.text(
        "ply\nformat binary_big_endian 1.0\nelement vertex 1\nproperty float x\n"
        "property float y\nproperty float z\nelement face 1\n"
        "property list uchar int vertex_indices\nend_header\n");
    b.be(0.0F).be(0.0F).be(0.0F);
    const std::size_t face_at = b.size();
    b.be<std::uint8_t>(3).be<std::int32_t>(0).be<std::int32_t>(0).be<std::int32_t>(7);
    expect_file_error_at_offset(dir / "bad_face_binary.ply", b.str(), "refers to vertex 7",
                                face_at);

    // Found by the fuzzer: an ascii value far beyond any integer type, or NaN, for an int index.
    for (const std::string index : {"3.3e105", "nan"})
        expect_file_error(dir / "huge_face_index.ply",
                          std::string(ascii_header) +
                              "element face 1\nproperty list uchar int vertex_indices\n"
                              "end_header\n0 0 0\n1 1 1\n2 2 2\n3 0 1 " +
                              index + "\n",
                          "face 0");
}

TEST(PlyErrors, MalformedHeaders)
{
    TempDir dir;
    expect_file_error(dir / "magic.ply", "plx\nformat ascii 1.0\nend_header\n", "not a PLY file");
    expect_file_error(dir / "no_end.ply",
                      "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n",
                      "no end_header");
    expect_file_error(
        dir / "type.ply",
        "ply\nformat ascii 1.0\nelement vertex 1\nproperty float128 x\nend_header\n0\n",
        "unknown property type");
    expect_file_error(dir / "format.ply", "ply\nformat binary_middle_endian 1.0\nend_header\n",
                      "unknown PLY format");
    expect_file_error(
        dir / "noxyz.ply",
        "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
        "end_header\n0 0\n",
        "no x, y and z");
    expect_file_error(dir / "count.ply", "ply\nformat ascii 1.0\nelement vertex -3\nend_header\n",
                      "element line");
    expect_file_error(dir / "noformat.ply", "ply\nelement vertex 0\nend_header\n",
                      "no format line");
    expect_file_error(dir / "orphan.ply", "ply\nformat ascii 1.0\nproperty float x\nend_header\n",
                      "before any element");
}

} // namespace
} // namespace pointform::test
