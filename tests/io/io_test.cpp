// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "io_test_util.h"
#include "support/test_support.h"

#include <gtest/gtest.h>

namespace pointform::test {
namespace {

TEST(IoFormat, FromExtension)
{
    EXPECT_EQ(format_from_extension("a.ply"), FileFormat::Ply);
    EXPECT_EQ(format_from_extension("dir.d/a.PLY"), FileFormat::Ply);
    for (const char* name : {"a.xyz", "a.pts", "a.csv", "a.txt", "a.pwn", "a.Xyz"})
        EXPECT_EQ(format_from_extension(name), FileFormat::Xyz) << name;
    EXPECT_EQ(format_from_extension("a.off"), FileFormat::Off);
    EXPECT_EQ(format_from_extension("a.obj"), FileFormat::Obj);
    EXPECT_EQ(format_from_extension("a.pcd"), FileFormat::Pcd);
    EXPECT_EQ(format_from_extension("a.las"), FileFormat::Las);
    expect_io_error([] { (void)format_from_extension("model.stl"); }, "model.stl",
                    "unknown file extension '.stl'");
    expect_io_error([] { (void)format_from_extension("README"); }, "README", "no extension");
    expect_io_error([] { (void)format_from_extension("scan.laz"); }, "scan.laz",
                    "compressed LAZ not supported");
}

TEST(IoFormat, Names)
{
    EXPECT_EQ(format_name(FileFormat::Auto), "auto");
    EXPECT_EQ(format_name(FileFormat::Ply), "ply");
    EXPECT_EQ(format_name(FileFormat::Xyz), "xyz");
    EXPECT_EQ(format_name(FileFormat::Off), "off");
    EXPECT_EQ(format_name(FileFormat::Obj), "obj");
    EXPECT_EQ(format_name(FileFormat::Pcd), "pcd");
    EXPECT_EQ(format_name(FileFormat::Las), "las");
}

TEST(IoRead, MissingEmptyAndDirectory)
{
    TempDir dir;
    const auto missing = dir / "missing.ply";
    expect_io_error([&] { (void)read_geometry(missing); }, missing, "does not exist");

    for (const char* name :
         {"empty.ply", "empty.xyz", "empty.off", "empty.obj", "empty.pcd", "empty.las"})
    {
        const auto empty = dir / name;
        write_file(empty, "");
        expect_io_error([&] { (void)read_geometry(empty); }, empty, "file is empty");
    }

    const auto folder = dir / "folder.ply";
    std::filesystem::create_directory(folder);
    expect_io_error([&] { (void)read_geometry(folder); }, folder, "directory");

    const auto unknown = dir / "model.stl";
    write_file(unknown, "solid x\n");
    expect_io_error([&] { (void)read_geometry(unknown); }, unknown, "unknown file extension");
}

TEST(IoRead, FormatOptionOverridesExtension)
{
    TempDir dir;
    const auto path = dir / "points.dat";
    write_file(path, "1 2 3\n4 5 6\n");
    const ReadResult result = read_geometry(path, {.format = FileFormat::Xyz});
    EXPECT_EQ(result.format, FileFormat::Xyz);
    EXPECT_EQ(result.points.size(), 2U);

    const auto ply_as_xyz = dir / "really_a.xyz";
    write_mesh(ply_as_xyz, make_grid_mesh(1, 1), {.format = FileFormat::Ply});
    EXPECT_EQ(read_mesh(ply_as_xyz, {.format = FileFormat::Ply}).face_count(), 2U);
}

TEST(IoRead, MeshAndPointCloudEntryPoints)
{
    TempDir dir;
    const auto mesh_path = dir / "mesh.ply";
    const TriMesh mesh = make_grid_mesh(2, 2);
    write_mesh(mesh_path, mesh);
    EXPECT_EQ(read_point_cloud(mesh_path).size(), mesh.vertex_count());

    const auto cloud_path = dir / "cloud.ply";
    write_point_cloud(cloud_path, make_cloud(10, false, false, false));
    expect_io_error([&] { (void)read_mesh(cloud_path); }, cloud_path, "no faces");
}

TEST(IoWrite, UnwritableFormatsLeaveNoFile)
{
    TempDir dir;
    const PointCloud cloud = make_cloud(10, false, false, false);
    for (const char* name : {"cloud.pcd", "cloud.las", "cloud.off", "cloud.obj"})
        expect_io_error([&] { write_point_cloud(dir / name, cloud); }, dir / name,
                        "cannot write point clouds");
    const TriMesh mesh = make_grid_mesh(1, 1);
    for (const char* name : {"mesh.xyz", "mesh.pcd"})
        expect_io_error([&] { write_mesh(dir / name, mesh); }, dir / name, "cannot write meshes");
    expect_io_error([&] { write_point_cloud(dir / "cloud.stl", cloud); }, dir / "cloud.stl",
                    "unknown file extension");
    EXPECT_TRUE(list_directory(dir.path()).empty());
}

TEST(IoWrite, FailedRenameLeavesNoTemporaryFile)
{
    TempDir dir;
    // The target is a non-empty directory: the temporary file is written, the rename fails.
    const auto target = dir / "occupied.ply";
    std::filesystem::create_directory(target);
    write_file(target / "keep", "x");
    expect_io_error([&] { write_point_cloud(target, make_cloud(100, true, false, false)); }, target,
                    "cannot move the temporary file");
    EXPECT_EQ(list_directory(dir.path()), std::vector<std::string>{"occupied.ply"});
}

TEST(IoWrite, MissingDirectoryIsAnIoError)
{
    TempDir dir;
    const auto path = dir / "no" / "such" / "dir" / "cloud.ply";
    expect_io_error([&] { write_point_cloud(path, make_cloud(5, false, false, false)); }, path,
                    "cannot create");
    EXPECT_TRUE(list_directory(dir.path()).empty());
}

TEST(IoWrite, InvalidInputWritesNothing)
{
    TempDir dir;
    TriMesh mesh = make_grid_mesh(1, 1);
    mesh.triangles.push_back({0, 1, 99});
    EXPECT_THROW(write_mesh(dir / "bad.ply", mesh), InvalidInput);

    PointCloud cloud = make_cloud(5, true, false, false);
    cloud.normals.pop_back();
    EXPECT_THROW(write_point_cloud(dir / "bad.xyz", cloud), InvalidInput);
    EXPECT_TRUE(list_directory(dir.path()).empty());
}

TEST(IoWrite, OverwritesAtomically)
{
    TempDir dir;
    const auto path = dir / "cloud.xyz";
    write_file(path, "old content that is longer than the new one\n");
    PointCloud cloud;
    cloud.positions = {Vec3f(1, 2, 3)};
    write_point_cloud(path, cloud);
    EXPECT_EQ(read_file(path), "1 2 3\n");
    EXPECT_EQ(list_directory(dir.path()), std::vector<std::string>{"cloud.xyz"});
}

TEST(IoWrite, EmptyCloudRoundTrips)
{
    TempDir dir;
    for (const char* name : {"empty.ply", "empty.xyz"})
    {
        write_point_cloud(dir / name, PointCloud{});
        if (std::string(name) == "empty.xyz")
            EXPECT_EQ(std::filesystem::file_size(dir / name), 0U);
        else
            EXPECT_TRUE(read_point_cloud(dir / name).empty());
    }
}

} // namespace
} // namespace pointform::test
