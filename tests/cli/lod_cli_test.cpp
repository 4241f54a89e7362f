// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// `pointform lod`: every level of a hierarchy file comes out as a closed manifold mesh with the
// 1-to-4 split's counts; a bad level or a damaged file gives a clear error and no output file.

#include "pointform/geometry/mesh_topology.h"
#include "pointform/io/hierarchy.h"
#include "pointform/io/io.h"

#include "cli_run.h"
#include "support/test_meshes.h"
#include "support/test_support.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>

namespace pointform {
namespace {

using test::file_count;
using test::quoted;
using test::run;

constexpr double radius = 2.0;
constexpr std::size_t finest = 3;

/// An icosahedron around `centre` refined to level 3, every new vertex pushed onto the sphere.
MultiresMesh sphere_hierarchy(const Vec3d& centre)
{
    MultiresMesh mesh(test::icosphere(0, centre, radius));
    for (std::size_t l = 0; l < finest; ++l)
    {
        (void)mesh.split();
        for (Vec3d& p : mesh.finest_new_positions())
            p = radius * p.normalized();
    }
    return mesh;
}

TEST(LodCli, EveryLevelIsAClosedManifoldWithTheSplitCounts)
{
    test::TempDir dir;
    const Vec3d centre(100.0, -50.0, 7.0);
    const auto input = dir / "sphere.pfh";
    write_hierarchy(input, sphere_hierarchy(centre));

    // Without -o: the table of levels only.
    const auto list = run("lod " + quoted(input) + " --json");
    ASSERT_EQ(list.exit_code, 0) << list.out;
    const auto table = nlohmann::json::parse(list.out)["levels"];
    ASSERT_EQ(table.size(), finest + 1);

    std::size_t previous_vertices = 0;
    std::size_t previous_edges = 0;
    for (std::size_t level = 0; level <= finest; ++level)
    {
        SCOPED_TRACE("level " + std::to_string(level));
        const std::string ext = level == 1 ? ".obj" : level == 2 ? ".off" : ".ply";
        const auto output = dir / ("level" + std::to_string(level) + ext);
        const auto r = run("lod " + quoted(input) + " --level " + std::to_string(level) + " -o " +
                           quoted(output) + " --json");
        ASSERT_EQ(r.exit_code, 0) << r.out;
        const auto report = nlohmann::json::parse(r.out);
        const TriMesh mesh = read_mesh(output);
        const MeshTopology topo = analyze_topology(mesh);
        EXPECT_TRUE(topo.is_oriented_manifold());
        EXPECT_TRUE(topo.is_closed());
        EXPECT_EQ(topo.euler_characteristic, 2);
        EXPECT_EQ(topo.components, 1U);
        EXPECT_EQ(topo.vertices, mesh.vertex_count()); // no unused vertex
        EXPECT_EQ(mesh.face_count(), 20U << (2 * level));
        if (level > 0)
        {
            EXPECT_EQ(mesh.vertex_count(), previous_vertices + previous_edges);
        }
        previous_vertices = mesh.vertex_count();
        previous_edges = topo.edges;
        EXPECT_EQ(report["level"].get<std::size_t>(), level);
        EXPECT_EQ(report["faces"].get<std::size_t>(), mesh.face_count());
        EXPECT_EQ(report["vertices"].get<std::size_t>(), mesh.vertex_count());
        EXPECT_TRUE(report["manifold"].get<bool>());
        EXPECT_EQ(table[level]["faces"].get<std::size_t>(), mesh.face_count());
        EXPECT_EQ(table[level]["vertices"].get<std::size_t>(), mesh.vertex_count());
        // Geometric truth: every vertex lies on the sphere (float output of world coordinates).
        for (std::size_t v = 0; v < mesh.vertex_count(); ++v)
            ASSERT_NEAR((mesh.vertices.world(v) - centre).norm(), radius, 1e-4 * radius);
    }
}

TEST(LodCli, DefaultsToTheFinestLevelAndPrintsTheTable)
{
    test::TempDir dir;
    const auto input = dir / "sphere.pfh";
    write_hierarchy(input, sphere_hierarchy(Vec3d::Zero()));
    const auto output = dir / "finest.ply";
    const auto r = run("lod " + quoted(input) + " -o " + quoted(output));
    ASSERT_EQ(r.exit_code, 0) << r.out;
    EXPECT_EQ(read_mesh(output).face_count(), 20U << (2 * finest));
    EXPECT_NE(r.out.find("4 levels"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("1280  <- written"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("level 3 -> "), std::string::npos) << r.out;
}

TEST(LodCli, InfoSummarizesAHierarchyFile)
{
    test::TempDir dir;
    const Vec3d centre(3.0, 4.0, 5.0);
    const MultiresMesh mesh = sphere_hierarchy(centre);
    const auto input = dir / "sphere.pfh";
    write_hierarchy(input, mesh);
    const auto r = run("info " + quoted(input) + " --json");
    ASSERT_EQ(r.exit_code, 0) << r.out;
    const auto report = nlohmann::json::parse(r.out);
    EXPECT_EQ(report["origin"][2].get<double>(), centre.z());
    ASSERT_EQ(report["levels"].size(), mesh.level_count());
    for (std::size_t level = 0; level < mesh.level_count(); ++level)
    {
        EXPECT_EQ(report["levels"][level]["vertices"].get<std::size_t>(), mesh.vertex_count(level));
        EXPECT_EQ(report["levels"][level]["faces"].get<std::size_t>(), mesh.face_count(level));
    }
}

TEST(LodCli, MissingLevelsListTheLevelsAndWriteNothing)
{
    test::TempDir dir;
    const auto input = dir / "sphere.pfh";
    write_hierarchy(input, sphere_hierarchy(Vec3d::Zero()));
    const auto output = dir / "out.ply";
    for (const std::string level : {"4", "-1", "99999999999"})
    {
        const auto r = run("lod " + quoted(input) + " --level=" + level + " -o " + quoted(output));
        EXPECT_EQ(r.exit_code, 2) << r.out;
        EXPECT_NE(r.out.find("level " + level + " does not exist"), std::string::npos) << r.out;
        EXPECT_NE(r.out.find("4 levels (0 to 3)"), std::string::npos) << r.out;
        EXPECT_FALSE(std::filesystem::exists(output));
    }
    EXPECT_EQ(file_count(dir.path()), 1U);
}

TEST(LodCli, DamagedFilesGiveFileErrorsAndWriteNothing)
{
    test::TempDir dir;
    const auto good = dir / "sphere.pfh";
    write_hierarchy(good, sphere_hierarchy(Vec3d::Zero()));
    const std::string bytes = test::read_file(good);
    const auto output = dir / "out.ply";

    const auto expect_failure = [&](const std::filesystem::path& input,
                                    const std::string& message) {
        const auto r = run("lod " + quoted(input) + " -o " + quoted(output));
        EXPECT_EQ(r.exit_code, 3) << r.out;
        EXPECT_NE(r.out.find(message), std::string::npos) << r.out;
        EXPECT_NE(r.out.find(input.filename().string()), std::string::npos) << r.out;
        EXPECT_FALSE(std::filesystem::exists(output));
    };
    std::string flipped = bytes;
    flipped[bytes.size() / 2] = static_cast<char>(flipped[bytes.size() / 2] ^ 1);
    test::write_file(dir / "flipped.pfh", flipped);
    expect_failure(dir / "flipped.pfh", "corrupt");

    test::write_file(dir / "cut.pfh", bytes.substr(0, bytes.size() - 100));
    expect_failure(dir / "cut.pfh", "truncated");

    std::string v9 = bytes;
    v9[8] = 9;
    test::write_file(dir / "v9.pfh", v9);
    expect_failure(dir / "v9.pfh", "version 9 is not supported");

    write_mesh(dir / "mesh.ply", test::icosphere(1));
    expect_failure(dir / "mesh.ply", "not a pointform hierarchy");

    expect_failure(dir / "missing.pfh", "does not exist");
    // Only the inputs made here are left.
    EXPECT_EQ(file_count(dir.path()), 5U);
}

} // namespace
} // namespace pointform
