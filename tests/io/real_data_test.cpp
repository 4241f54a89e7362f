// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// The real files in data/ (see data/SOURCES.md): counts and bounding boxes as measured there.

#include "io_test_util.h"
#include "support/test_support.h"

#include <gtest/gtest.h>

#include <cctype>
#include <ostream>

namespace pointform::test {
namespace {

struct Expected
{
    const char* file;
    FileFormat format;
    std::size_t points;
    std::size_t triangles;
    bool normals;
    bool colors;
    Vec3d size; ///< bbox size, 4 significant digits
    std::size_t dropped = 0;
};

// GoogleTest looks this printer up by its name.
void PrintTo(const Expected& e, std::ostream* os) // NOLINT(readability-identifier-naming)
{
    *os << e.file;
}

class RealData : public ::testing::TestWithParam<Expected>
{};

TEST_P(RealData, CountsAttributesAndBoundingBox)
{
    const Expected& e = GetParam();
    const ReadResult result = read_geometry(data_path(e.file));
    EXPECT_EQ(result.format, e.format);
    EXPECT_EQ(result.points.size(), e.points);
    EXPECT_EQ(result.triangles.size(), e.triangles);
    EXPECT_EQ(result.dropped_points, e.dropped);
    EXPECT_EQ(result.points.has_normals(), e.normals);
    EXPECT_EQ(result.points.has_colors(), e.colors);
    const Vec3d size = result.points.bounds().size();
    for (int k = 0; k < 3; ++k)
        EXPECT_NEAR(size[k], e.size[k], 1e-3 * e.size[k] + 1e-4) << "axis " << k;
    for (const Vec3f& n : result.points.normals)
    {
        ASSERT_NEAR(n.norm(), 1.0F, 1e-5F);
    }
    for (const Triangle& t : result.triangles)
    {
        for (const std::uint32_t v : t)
        {
            ASSERT_LT(v, result.points.size());
        }
    }
}

INSTANTIATE_TEST_SUITE_P(
    Files, RealData,
    ::testing::Values(Expected{"bunny/bun000.ply", FileFormat::Ply, 40256, 0, false, false,
                               Vec3d(0.1557, 0.1522, 0.1174)},
                      Expected{"bunny/bun045.ply", FileFormat::Ply, 40097, 0, false, false,
                               Vec3d(0.1472, 0.1534, 0.1387)},
                      Expected{"bunny/bun_zipper.ply", FileFormat::Ply, 35947, 69451, false, false,
                               Vec3d(0.1557, 0.1543, 0.1207)},
                      Expected{"bunny/bun_zipper_res4.ply", FileFormat::Ply, 453, 948, false, false,
                               Vec3d(0.1513, 0.1483, 0.1144)},
                      Expected{"cgal/spheres.ply", FileFormat::Ply, 5969, 0, true, false,
                               Vec3d(2.267, 2.151, 2.089)},
                      Expected{"cgal/kitten.xyz", FileFormat::Xyz, 5210, 0, true, false,
                               Vec3d(0.651, 0.9986, 0.5906)},
                      Expected{"meshes/bunny_uniform.off", FileFormat::Off, 8904, 17804, false,
                               false, Vec3d(0.1556, 0.154, 0.1205)},
                      Expected{"meshes/spot.obj", FileFormat::Obj, 2930, 5856, false, false,
                               Vec3d(0.9431, 1.69, 1.718)},
                      Expected{"pcl/bun0.pcd", FileFormat::Pcd, 397, 0, true, false,
                               Vec3d(0.1535, 0.1471, 0.1128)},
                      Expected{"pcl/bunny.pcd", FileFormat::Pcd, 397, 0, false, false,
                               Vec3d(0.1535, 0.1471, 0.1128)},
                      Expected{"pcl/table_scene_mug_stereo_textured.pcd", FileFormat::Pcd, 209280,
                               0, false, true, Vec3d(1.172, 0.69, 1.903), 307200 - 209280},
                      Expected{"lidar/simple.las", FileFormat::Las, 1065, 0, false, true,
                               Vec3d(3363, 4636, 179.8)},
                      Expected{"lidar/4_6_crop.las", FileFormat::Las, 23875, 0, false, true,
                               Vec3d(200, 200, 61.78)}),
    [](const ::testing::TestParamInfo<Expected>& test) {
        std::string name = test.param.file;
        for (char& c : name)
            if (!std::isalnum(static_cast<unsigned char>(c)))
                c = '_';
        return name;
    });

TEST(RealDataLas, HeaderBoundsAndGeoreferencedOrigin)
{
    // Minimum corners from the LAS headers (min x, min y, min z).
    const PointCloud simple = read_point_cloud(data_path("lidar/simple.las"));
    const Aabb a = simple.bounds();
    EXPECT_NEAR(a.min.x(), 635619.85, 1e-3);
    EXPECT_NEAR(a.min.y(), 848899.70, 1e-3);
    EXPECT_NEAR(a.min.z(), 406.59, 1e-3);
    EXPECT_NEAR(a.max.x(), 638982.55, 1e-3);
    EXPECT_GT(simple.origin.norm(), 1e5);

    const PointCloud crop = read_point_cloud(data_path("lidar/4_6_crop.las"));
    const Aabb b = crop.bounds();
    EXPECT_NEAR(b.min.x(), 1639600.0, 1e-3);
    EXPECT_NEAR(b.min.y(), 1454500.02, 1e-3);
    EXPECT_NEAR(b.min.z(), 7077.92, 1e-3);
    EXPECT_NEAR(b.max.z(), 7139.7, 1e-3);
    EXPECT_EQ(read_geometry(data_path("lidar/4_6_crop.las")).description, "LAS 1.2 point format 3");
}

TEST(RealDataRoundTrip, ZipperBunnyThroughBinaryPly)
{
    TempDir dir;
    const TriMesh mesh = read_mesh(data_path("bunny/bun_zipper.ply"));
    const auto path = dir / "bunny.ply";
    write_mesh(path, mesh);
    const TriMesh back = read_mesh(path);
    expect_same_cloud(mesh.vertices, back.vertices, 0.0);
    EXPECT_EQ(back.triangles, mesh.triangles);
}

TEST(RealDataRoundTrip, SpotThroughOffAndObj)
{
    TempDir dir;
    const TriMesh mesh = read_mesh(data_path("meshes/spot.obj"));
    for (const char* name : {"spot.off", "spot.obj", "spot_ascii.ply"})
    {
        write_mesh(dir / name, mesh, {.ascii = true});
        const TriMesh back = read_mesh(dir / name);
        expect_same_cloud(mesh.vertices, back.vertices, 0.0);
        EXPECT_EQ(back.triangles, mesh.triangles);
    }
}

TEST(RealDataRoundTrip, LidarThroughPlyAndXyz)
{
    TempDir dir;
    const PointCloud cloud = read_point_cloud(data_path("lidar/4_6_crop.las"));
    for (const char* name : {"crop.ply", "crop.xyz"})
    {
        write_point_cloud(dir / name, cloud);
        PointCloud expected = cloud;
        if (std::string(name) == "crop.xyz")
            expected.colors.clear();                                     // xyz carries no colors
        expect_same_cloud(expected, read_point_cloud(dir / name), 1e-8); // 1e-8 x 290 m: 3 µm
    }
}

TEST(RealDataRoundTrip, OrganizedPcdThroughPly)
{
    TempDir dir;
    const PointCloud cloud = read_point_cloud(data_path("pcl/table_scene_mug_stereo_textured.pcd"));
    // A depth image (640 x 480) seen from its VIEWPOINT, the origin.
    ASSERT_TRUE(cloud.sensor.has_value());
    EXPECT_EQ(*cloud.sensor, Vec3d::Zero());
    write_point_cloud(dir / "mug.ply", cloud);
    const PointCloud again = read_point_cloud(dir / "mug.ply");
    expect_same_cloud(cloud, again, 0.0);
    EXPECT_FALSE(again.sensor.has_value()); // PLY has no place for it
}

TEST(RealDataRoundTrip, KittenThroughXyz)
{
    TempDir dir;
    const PointCloud cloud = read_point_cloud(data_path("cgal/kitten.xyz"));
    write_point_cloud(dir / "kitten.xyz", cloud);
    expect_same_cloud(cloud, read_point_cloud(dir / "kitten.xyz"), 0.0);
}

} // namespace
} // namespace pointform::test
