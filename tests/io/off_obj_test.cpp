// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "io_test_util.h"
#include "support/test_support.h"

#include <gtest/gtest.h>

namespace pointform::test {
namespace {

TEST(OffRoundTrip, Mesh)
{
    TempDir dir;
    const auto path = dir / "grid.off";
    const TriMesh mesh = make_grid_mesh(5, 6);
    write_mesh(path, mesh);
    EXPECT_EQ(read_file(path).substr(0, 4), "OFF\n");
    const ReadResult result = read_geometry(path);
    EXPECT_EQ(result.format, FileFormat::Off);
    expect_same_cloud(mesh.vertices, result.points, 0.0);
    EXPECT_EQ(result.triangles, mesh.triangles);
}

TEST(OffRoundTrip, GeoreferencedMesh)
{
    TempDir dir;
    const auto path = dir / "geo.off";
    const TriMesh mesh = make_grid_mesh(3, 3, Vec3d(600000.0, 5000000.0, 10.0));
    write_mesh(path, mesh);
    const TriMesh back = read_mesh(path);
    ASSERT_EQ(back.vertex_count(), mesh.vertex_count());
    for (std::size_t i = 0; i < mesh.vertex_count(); ++i)
        EXPECT_LT((back.vertices.world(i) - mesh.vertices.world(i)).norm(), 1e-6);
    EXPECT_EQ(back.triangles, mesh.triangles);
}

TEST(OffRead, CommentsCountsOnKeywordLineAndPolygons)
{
    TempDir dir;
    const auto path = dir / "square.off";
    write_file(path,
               "OFF 5 2 0 # counts on the keyword line\n# comment\n\n0 0 0\n1 0 0\n"
               "1 1 0  # trailing comment\n0 1 0\n0.5 0.5 1\n4 0 1 2 3\n"
               "3 0 1 4 255 0 0\n");
    const ReadResult result = read_geometry(path);
    ASSERT_EQ(result.points.size(), 5U);
    const std::vector<Triangle> expected = {{0, 1, 2}, {0, 2, 3}, {0, 1, 4}};
    EXPECT_EQ(result.triangles, expected);
    EXPECT_EQ(result.description, "OFF");
}

TEST(OffRead, ColorAndNormalVariants)
{
    TempDir dir;
    const auto coff = dir / "colors.off";
    write_file(coff,
               "COFF\n3 1 0\n0 0 0 255 0 0 255\n1 0 0 0 255 0 255\n0 1 0 0 0 255 255\n"
               "3 0 1 2\n");
    const PointCloud colored = read_point_cloud(coff);
    ASSERT_TRUE(colored.has_colors());
    EXPECT_EQ(colored.colors[1], (Color{0, 255, 0}));

    const auto cfloat = dir / "float_colors.off";
    write_file(cfloat, "COFF\n1 0 0\n0 0 0 1.0 0.5 0.0 1.0\n");
    EXPECT_EQ(read_point_cloud(cfloat).colors[0], (Color{255, 128, 0}));

    const auto noff = dir / "normals.off";
    write_file(noff, "NOFF\n2 0 0\n0 0 0 0 0 2\n1 0 0 0 -1 0\n");
    const PointCloud normals = read_point_cloud(noff);
    ASSERT_TRUE(normals.has_normals());
    EXPECT_EQ(normals.normals[0], Vec3f(0, 0, 1));
    EXPECT_EQ(normals.normals[1], Vec3f(0, -1, 0));

    const auto cnoff = dir / "both.off";
    write_file(cnoff, "CNOFF\n1 0 0\n1 2 3 1 0 0 10 20 30 255\n");
    const PointCloud both = read_point_cloud(cnoff);
    EXPECT_EQ(both.normals[0], Vec3f(1, 0, 0));
    EXPECT_EQ(both.colors[0], (Color{10, 20, 30}));
}

TEST(OffErrors, Malformed)
{
    TempDir dir;
    expect_file_error_at_line(dir / "bad_index.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n",
                              "refers to vertex 3", 6);
    expect_file_error_at_line(dir / "missing_faces.off",
                              "OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", "1 of the 2 faces", 7);
    expect_file_error_at_line(dir / "missing_vertices.off", "OFF\n4 0 0\n0 0 0\n1 0 0\n",
                              "2 of the 4 vertices", 5);
    expect_file_error_at_line(dir / "short_vertex.off", "OFF\n2 0 0\n0 0 0\n1 0\n", "2 values", 4);
    expect_file_error_at_line(dir / "garbage.off", "OFF\n1 0 0\n0 zero 0\n", "'zero'", 3);
    expect_file_error_at_line(dir / "short_face.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n4 0 1 2\n",
                              "declares 4", 6);
    expect_file_error_at_line(dir / "nan.off", "OFF\n2 0 0\n0 0 0\n1 nan 0\n", "non-finite", 4);
    expect_file_error_at_line(dir / "keyword.off", "# comment\nPLY\n", "not an OFF file", 2);
    expect_file_error_at_line(dir / "counts.off", "OFF\nthree 1 0\n", "counts", 2);
}

TEST(ObjRoundTrip, MeshWithAndWithoutNormals)
{
    TempDir dir;
    TriMesh mesh = make_grid_mesh(4, 4);
    const auto plain = dir / "plain.obj";
    write_mesh(plain, mesh);
    ReadResult result = read_geometry(plain);
    EXPECT_EQ(result.format, FileFormat::Obj);
    expect_same_cloud(mesh.vertices, result.points, 0.0);
    EXPECT_EQ(result.triangles, mesh.triangles);

    for (std::size_t i = 0; i < mesh.vertex_count(); ++i)
        mesh.vertices.normals.push_back(
            Vec3f(0.1F * static_cast<float>(i % 3), 0.2F, 1.0F).normalized());
    const auto with_normals = dir / "normals.obj";
    write_mesh(with_normals, mesh);
    EXPECT_NE(read_file(with_normals).find("//"), std::string::npos);
    result = read_geometry(with_normals);
    expect_same_cloud(mesh.vertices, result.points, 0.0);
    EXPECT_EQ(result.triangles, mesh.triangles);
}

TEST(ObjRead, CornerFormsNegativeIndicesAndIgnoredStatements)
{
    TempDir dir;
    const auto path = dir / "forms.obj";
    write_file(path,
               "# comment\nmtllib a.mtl\no thing\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
               "vt 0 0\nvt 1 0\nvn 0 0 1\ng group\nusemtl m\ns off\n"
               "f 1 2 3\nf 1/1 3/2 4/1\nf 1//1 2//1 3//1\nf 1/1/1 3/2/1 4/2/1\n"
               "f -4 -3 -2 -1\nl 1 2\n");
    const ReadResult result = read_geometry(path);
    ASSERT_EQ(result.points.size(), 4U);
    const std::vector<Triangle> expected = {{0, 1, 2}, {0, 2, 3}, {0, 1, 2},
                                            {0, 2, 3}, {0, 1, 2}, {0, 2, 3}};
    EXPECT_EQ(result.triangles, expected);
    // One shared normal referenced by every corner: attached to every vertex.
    ASSERT_TRUE(result.points.has_normals());
    for (const Vec3f& n : result.points.normals)
        EXPECT_EQ(n, Vec3f(0, 0, 1));
}

TEST(ObjRead, NormalsByVertexCountAndColors)
{
    TempDir dir;
    const auto path = dir / "points.obj";
    write_file(path, "v 0 0 0 1 0 0\nv 1 0 0 0 1 0\nvn 0 0 2\nvn 0 3 0\n");
    const ReadResult result = read_geometry(path);
    ASSERT_EQ(result.points.size(), 2U);
    EXPECT_TRUE(result.triangles.empty());
    ASSERT_TRUE(result.points.has_normals());
    EXPECT_EQ(result.points.normals[1], Vec3f(0, 1, 0));
    ASSERT_TRUE(result.points.has_colors());
    EXPECT_EQ(result.points.colors[0], (Color{255, 0, 0}));
    expect_io_error([&] { (void)read_mesh(path); }, path, "no faces");
}

TEST(ObjRead, PartialNormalReferencesGiveNoNormals)
{
    TempDir dir;
    const auto path = dir / "partial.obj";
    write_file(path, "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 5 5 5\nvn 0 0 1\nf 1//1 2//1 3//1\n");
    const PointCloud cloud = read_point_cloud(path);
    EXPECT_EQ(cloud.size(), 4U);
    EXPECT_FALSE(cloud.has_normals()); // vertex 4 has none
}

TEST(ObjErrors, Malformed)
{
    TempDir dir;
    expect_file_error_at_line(dir / "range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n",
                              "refers to vertex 4", 4);
    expect_file_error_at_line(dir / "zero.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n",
                              "refers to vertex 0", 4);
    expect_file_error_at_line(dir / "negative.obj", "v 0 0 0\nv 1 0 0\nf -1 -2 -3\n",
                              "refers to vertex -3", 3);
    expect_file_error_at_line(dir / "normal.obj",
                              "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//2 3//1\n",
                              "refers to normal 2", 5);
    expect_file_error_at_line(dir / "garbage.obj", "v 0 0 0\nv 1 0 x\n", "'x'", 2);
    expect_file_error_at_line(dir / "corner.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 three\n",
                              "'three'", 4);
    expect_file_error_at_line(dir / "short.obj", "v 0 0\n", "x y z", 1);
    expect_file_error_at_line(dir / "nan.obj", "v 0 0 0\nv inf 0 0\n", "non-finite", 2);
}

TEST(ObjErrors, DroppingVerticesOfAMeshIsAnError)
{
    TempDir dir;
    expect_file_error_at_line(dir / "drop.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n",
                              "face indices would be wrong", 2,
                              {.non_finite = NonFinitePolicy::Drop});

    const auto points = dir / "drop_points.obj";
    write_file(points, "v 0 0 0\nv nan 0 0\nv 0 1 0\n");
    const ReadResult result = read_geometry(points, {.non_finite = NonFinitePolicy::Drop});
    EXPECT_EQ(result.points.size(), 2U);
    EXPECT_EQ(result.dropped_points, 1U);
}

} // namespace
} // namespace pointform::test
