// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// Hostile valence at the command line: a polygon of a million vertices (one vertex in 999,998
// triangles once triangulated) in OFF, binary PLY and OBJ, and a hierarchy file whose base mesh
// is such a fan. `info` and `lod` process them; `remesh` refuses the million-gon with exit code 2
// and a message naming the vertex and the limit, and remeshes a fan within the limit.

#include "pointform/geometry/mesh_topology.h"
#include "pointform/io/hierarchy.h"
#include "pointform/io/io.h"
#include "pointform/polygonize/base_mesh.h"

#include "cli_run.h"
#include "support/polygon_fan.h"
#include "support/test_support.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>

namespace pointform {
namespace {

using test::quoted;
using test::run;

constexpr std::size_t n = 1'000'000;

void write_fan(const std::filesystem::path& path, std::size_t vertices)
{
    const std::string ext = path.extension().string();
    if (ext == ".off")
        test::write_polygon_fan_off(path, vertices);
    else if (ext == ".ply")
        test::write_polygon_fan_ply(path, vertices);
    else
        test::write_polygon_fan_obj(path, vertices);
}

class FanCli : public ::testing::TestWithParam<std::string>
{};

TEST_P(FanCli, InfoReportsTheMillionGon)
{
    const test::TempDir dir;
    const auto input = dir / ("fan." + GetParam());
    write_fan(input, n);
    const auto info = run("info " + quoted(input) + " --json");
    ASSERT_EQ(info.exit_code, 0) << info.out;
    const auto json = nlohmann::json::parse(info.out);
    EXPECT_EQ(json["points"], n);
    EXPECT_EQ(json["faces"], n - 2);
    EXPECT_NEAR(json["bounding_box"]["diagonal"].get<double>(), 2.0 * std::sqrt(2.0), 1e-6);
}

TEST_P(FanCli, RemeshRefusesTheMillionGonWithAClearMessage)
{
    const test::TempDir dir;
    const auto input = dir / ("fan." + GetParam());
    write_fan(input, n);
    const auto output = dir / "out.ply";
    const auto remesh = run("remesh " + quoted(input) + " -o " + quoted(output));
    EXPECT_EQ(remesh.exit_code, 2) << remesh.out;
    EXPECT_NE(remesh.out.find("vertex 0 is in " + std::to_string(n - 2) + " triangles"),
              std::string::npos)
        << remesh.out;
    EXPECT_NE(remesh.out.find(std::to_string(max_intermediate_valence)), std::string::npos)
        << remesh.out;
    EXPECT_FALSE(std::filesystem::exists(output));
}

TEST_P(FanCli, DistanceAndRenderRefuseTheMillionGonWithAClearMessage)
{
    // Its slivers' boxes overlap about n / (2π) deep: a query anywhere tests ~159,000 triangles.
    const test::TempDir dir;
    const auto input = dir / ("fan." + GetParam());
    write_fan(input, n);
    const auto distance = run("distance " + quoted(input) + " " + quoted(input));
    EXPECT_EQ(distance.exit_code, 2) << distance.out;
    EXPECT_NE(distance.out.find("retriangulate"), std::string::npos) << distance.out;
    const auto image = dir / "fan.png";
    const auto render = run("render " + quoted(input) + " -o " + quoted(image));
    EXPECT_EQ(render.exit_code, 2) << render.out;
    EXPECT_NE(render.out.find("retriangulate"), std::string::npos) << render.out;
    EXPECT_FALSE(std::filesystem::exists(image));
}

INSTANTIATE_TEST_SUITE_P(Formats, FanCli, ::testing::Values("off", "ply", "obj"));

TEST(FanCliSmall, RemeshProcessesAFanWithinTheLimit)
{
    // A 400-gon: vertex 0 is in 398 triangles, below the limit, so the disc is remeshed.
    const test::TempDir dir;
    const auto input = dir / "fan.off";
    test::write_polygon_fan_off(input, 400);
    const auto output = dir / "out.ply";
    const auto remesh = run("-q remesh " + quoted(input) + " -o " + quoted(output));
    ASSERT_EQ(remesh.exit_code, 0) << remesh.out;
    const TriMesh out = read_mesh(output);
    const MeshTopology t = analyze_topology(out);
    EXPECT_TRUE(t.is_oriented_manifold());
    EXPECT_EQ(t.components, 1U);
    EXPECT_EQ(t.boundary_loops, 1U);
    EXPECT_EQ(t.euler_characteristic, 1);
    // Flat: every vertex on the polygon's plane z = 0, within the unit disc.
    for (std::size_t v = 0; v < out.vertex_count(); ++v)
    {
        const Vec3d p = out.vertices.world(v);
        EXPECT_NEAR(p.z(), 0.0, 1e-3);
        EXPECT_LE(p.head<2>().norm(), 1.0 + 1e-3);
    }
}

TEST(FanCliSmall, DistanceAndRenderMeasureAndDrawASmallerFan)
{
    // A 2,000-gon (depth 318) is within the work budget: measured exactly (a fan against the
    // same polygon: every distance 0) and drawn.
    const test::TempDir dir;
    const auto input = dir / "fan.off";
    test::write_polygon_fan_off(input, 2000);
    const auto distance = run("distance " + quoted(input) + " " + quoted(input) + " --json");
    ASSERT_EQ(distance.exit_code, 0) << distance.out;
    const auto json = nlohmann::json::parse(distance.out);
    EXPECT_LT(json["absolute"]["hausdorff"].get<double>(), 1e-6) << distance.out;
    const auto image = dir / "fan.png";
    const auto render = run("-q render " + quoted(input) + " -o " + quoted(image));
    ASSERT_EQ(render.exit_code, 0) << render.out;
    EXPECT_TRUE(std::filesystem::exists(image));
}

TEST(FanCliHierarchy, LodAndInfoReadAHierarchyWhoseBaseIsAFan)
{
    // The base mesh is the million-gon's fan (the library test polygon_fan_test also reads a
    // refined level of it).
    const test::TempDir dir;
    const auto input = dir / "fan.pfh";
    write_hierarchy(input, MultiresMesh(test::polygon_fan_mesh(n)));

    const auto info = run("info " + quoted(input) + " --json");
    ASSERT_EQ(info.exit_code, 0) << info.out;
    const auto levels = nlohmann::json::parse(info.out)["levels"];
    ASSERT_EQ(levels.size(), 1U);
    EXPECT_EQ(levels[0]["vertices"], n);
    EXPECT_EQ(levels[0]["faces"], n - 2);

    const auto output = dir / "base.ply";
    const auto lod = run("lod " + quoted(input) + " -o " + quoted(output) + " --json");
    ASSERT_EQ(lod.exit_code, 0) << lod.out;
    const auto json = nlohmann::json::parse(lod.out);
    EXPECT_EQ(json["vertices"], n);
    EXPECT_EQ(json["faces"], n - 2);
    EXPECT_EQ(json["components"], 1);
    EXPECT_EQ(json["boundary_loops"], 1);
    EXPECT_EQ(json["euler_characteristic"], 1);
    EXPECT_EQ(json["manifold"], true);
    EXPECT_EQ(read_mesh(output).triangles, test::polygon_fan_mesh(n).triangles);
}

} // namespace
} // namespace pointform
