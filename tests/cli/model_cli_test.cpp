// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// `pointform model` and `pointform morph` end to end: scenes of primitives and scans in, closed
// meshes with the right topology out, and errors that point at the line and column.

#include "pointform/geometry/mesh_topology.h"
#include "pointform/io/io.h"

#include "cli_run.h"
#include "support/test_support.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>

namespace pointform {
namespace {

using test::quoted;
using test::run;

/// Largest |f| over the mesh's vertices for an analytic signed distance f.
template <typename Distance>
double max_vertex_distance(const TriMesh& mesh, Distance distance)
{
    double worst = 0.0;
    for (std::size_t v = 0; v < mesh.vertex_count(); ++v)
    {
        worst = std::max(worst, std::abs(distance(mesh.vertices.world(v))));
    }
    return worst;
}

TEST(ModelCli, UnionOfTwoSpheresIsOneClosedSphere)
{
    test::TempDir dir;
    const auto output = dir / "spheres.ply";
    const auto r = run("model 'union(sphere([0,0,0], 1), sphere([1.2,0,0], 0.8))' -o " +
                       quoted(output) + " --json");
    ASSERT_EQ(r.exit_code, 0) << r.out;
    const auto report = nlohmann::json::parse(r.out);
    EXPECT_EQ(report["input_kind"].get<std::string>(), "expression");
    EXPECT_EQ(report["components"].get<int>(), 1);
    EXPECT_EQ(report["boundary_loops"].get<int>(), 0);
    EXPECT_EQ(report["euler_characteristic"].get<int>(), 2);
    // Marching cubes keeps every triangle; none had to be mended here.
    EXPECT_EQ(report["degenerate_triangles"].get<std::size_t>(), 0U);
    EXPECT_EQ(report["degenerate_kept"].get<std::size_t>(), 0U);
    const TriMesh mesh = read_mesh(output);
    EXPECT_EQ(mesh.face_count(), report["faces"].get<std::size_t>());
    const MeshTopology topo = analyze_topology(mesh);
    EXPECT_TRUE(topo.is_oriented_manifold());
    EXPECT_TRUE(topo.is_closed());
    // Default cell for primitives: the longest side of the bounds (x: −1 … 2) / 128.
    const double cell = report["cell"].get<double>();
    EXPECT_NEAR(cell, 3.0 / 128.0, 1e-12);
    const double worst = max_vertex_distance(mesh, [](const Vec3d& p) {
        return std::min(p.norm() - 1.0, (p - Vec3d(1.2, 0, 0)).norm() - 0.8);
    });
    // Vertices are refined onto the surface; those on grid edges across the crease where the
    // spheres meet (a kink of min) land within a quarter cell.
    EXPECT_LT(worst, 0.25 * cell);
    // No surface inside the other sphere: every vertex is outside (or on) both.
    for (std::size_t v = 0; v < mesh.vertex_count(); ++v)
    {
        const Vec3d p = mesh.vertices.world(v);
        ASSERT_GT(p.norm() - 1.0, -0.25 * cell);
        ASSERT_GT((p - Vec3d(1.2, 0, 0)).norm() - 0.8, -0.25 * cell);
    }
}

TEST(ModelCli, SemiRegularUnionOfTwoSpheresLiesOnTheSpheres)
{
    test::TempDir dir;
    const auto output = dir / "spheres.ply";
    const auto hierarchy = dir / "spheres.pfh";
    const auto r = run("model 'union(sphere([0,0,0], 1), sphere([1.2,0,0], 0.8))' -o " +
                       quoted(output) + " --semi-regular --base-faces 500 --levels 2 " +
                       "--save-hierarchy " + quoted(hierarchy) + " --json");
    ASSERT_EQ(r.exit_code, 0) << r.out;
    const auto report = nlohmann::json::parse(r.out);
    EXPECT_EQ(report["polygonization"].get<std::string>(), "semi-regular");
    ASSERT_EQ(report["levels"].size(), 2U);
    // Every level splits every face in four; the base mesh has about the faces asked for.
    const auto base = report["base_mesh"]["faces"].get<std::size_t>();
    EXPECT_NEAR(static_cast<double>(base), 500.0, 10.0);
    EXPECT_EQ(report["faces"].get<std::size_t>(), 16 * base);
    EXPECT_EQ(report["components"].get<int>(), 1);
    EXPECT_EQ(report["boundary_loops"].get<int>(), 0);
    EXPECT_EQ(report["euler_characteristic"].get<int>(), 2);
    const TriMesh mesh = read_mesh(output);
    EXPECT_EQ(mesh.face_count(), 16 * base);
    const MeshTopology topo = analyze_topology(mesh);
    EXPECT_TRUE(topo.is_oriented_manifold());
    EXPECT_TRUE(topo.is_closed());
    // Every new vertex is projected onto the zero set: on the spheres away from the crease
    // where they meet, within a quarter cell next to it (where the base mesh keeps the
    // marching-cubes vertices of the kink).
    const double cell = report["cell"].get<double>();
    const double worst = max_vertex_distance(mesh, [](const Vec3d& p) {
        return std::min(p.norm() - 1.0, (p - Vec3d(1.2, 0, 0)).norm() - 0.8);
    });
    EXPECT_LT(worst, 0.25 * cell);
    EXPECT_LT(report["max_abs_field_at_vertices"].get<double>(), 0.25 * cell);
    EXPECT_LT(report["mean_abs_field_at_vertices"].get<double>(), 1e-3 * cell);
    // The hierarchy holds the base mesh and both levels.
    const auto lod = run("lod " + quoted(hierarchy) + " --json");
    ASSERT_EQ(lod.exit_code, 0) << lod.out;
    const auto levels = nlohmann::json::parse(lod.out)["levels"];
    ASSERT_EQ(levels.size(), 3U);
    EXPECT_EQ(levels[0]["faces"].get<std::size_t>(), base);
    EXPECT_EQ(levels[2]["faces"].get<std::size_t>(), 16 * base);
}

TEST(ModelCli, RefinementOptionsNeedSemiRegular)
{
    test::TempDir dir;
    const auto output = dir / "x.ply";
    const auto r = run("model 'sphere([0,0,0], 1)' -o " + quoted(output) + " --levels 2");
    EXPECT_NE(r.exit_code, 0);
    EXPECT_NE(r.out.find("--semi-regular"), std::string::npos) << r.out;
    EXPECT_FALSE(std::filesystem::exists(output));
    const auto huge = run("model 'sphere([0,0,0], 1)' -o " + quoted(output) +
                          " --semi-regular --base-faces 999999999");
    EXPECT_NE(huge.exit_code, 0);
    EXPECT_NE(huge.out.find("--base-faces"), std::string::npos) << huge.out;
    EXPECT_FALSE(std::filesystem::exists(output));
}

TEST(ModelCli, DrilledRoundedBoxHasGenusOne)
{
    test::TempDir dir;
    // A scene file with bindings and comments; the hole makes a genus-1 surface: χ = 0.
    test::write_file(dir / "drilled.pf",
                     "# a rounded cube with a hole through it\n"
                     "let cube = box([-1, -1, -1], [1, 1, 1], rounded = 0.2)\n"
                     "let drill = cylinder([0, 0, -2], [0, 0, 2], 0.4)\n"
                     "difference(cube, drill)\n");
    const auto output = dir / "drilled.obj";
    const auto r = run("model " + quoted(dir / "drilled.pf") + " -o " + quoted(output) +
                       " --resolution 64 --json");
    ASSERT_EQ(r.exit_code, 0) << r.out;
    const auto report = nlohmann::json::parse(r.out);
    EXPECT_EQ(report["input_kind"].get<std::string>(), "scene file");
    EXPECT_EQ(report["components"].get<int>(), 1);
    EXPECT_EQ(report["boundary_loops"].get<int>(), 0);
    EXPECT_EQ(report["euler_characteristic"].get<int>(), 0);
    EXPECT_TRUE(report["manifold"].get<bool>());
    // 64 cells along the longest side (2).
    EXPECT_NEAR(report["cell"].get<double>(), 2.0 / 64.0, 1e-12);
    // No vertex inside the drilled hole.
    const TriMesh mesh = read_mesh(output);
    const double cell = report["cell"].get<double>();
    for (std::size_t v = 0; v < mesh.vertex_count(); ++v)
    {
        const Vec3d p = mesh.vertices.world(v);
        ASSERT_GT(std::hypot(p.x(), p.y()), 0.4 - 0.1 * cell) << p.transpose();
    }
}

TEST(ModelCli, HalfSpaceNeedsBoundsOrABoundedPartner)
{
    test::TempDir dir;
    const auto output = dir / "cut.ply";
    const auto unbounded =
        run("model 'union(sphere([0,0,0],1), half_space([0,0,0],[1,1,1]))' -o " + quoted(output));
    EXPECT_EQ(unbounded.exit_code, 2) << unbounded.out;
    EXPECT_NE(unbounded.out.find("--bounds"), std::string::npos) << unbounded.out;
    EXPECT_FALSE(std::filesystem::exists(output));
    // Intersected with a sphere it is bounded: a closed hemisphere.
    const auto half =
        run("model 'intersection(sphere([0,0,0],1), half_space([0,0,0],[0,0,1]))' -o " +
            quoted(output) + " --resolution 32 --json");
    ASSERT_EQ(half.exit_code, 0) << half.out;
    const auto report = nlohmann::json::parse(half.out);
    EXPECT_EQ(report["boundary_loops"].get<int>(), 0);
    EXPECT_EQ(report["euler_characteristic"].get<int>(), 2);
    const TriMesh mesh = read_mesh(output);
    const double cell = report["cell"].get<double>();
    for (std::size_t v = 0; v < mesh.vertex_count(); ++v)
    {
        ASSERT_LT(mesh.vertices.world(v).z(), 0.1 * cell);
    }
    // With --bounds the plane is cut off at the box: an open surface.
    const auto plane = run("model 'half_space([0,0,0],[0,0,1])' -o " + quoted(output) +
                           " --bounds -1,-1,-1,1,1,1 --resolution 16 --json");
    ASSERT_EQ(plane.exit_code, 0) << plane.out;
    EXPECT_EQ(nlohmann::json::parse(plane.out)["boundary_loops"].get<int>(), 1);
}

TEST(ModelCli, ScanWithAPrimitive)
{
    test::TempDir dir;
    const auto bunny = test::data_path("bunny/bun_zipper.ply");
    // A ball pasted onto the bunny's back and a slab cut off its base.
    test::write_file(
        dir / "scene.pf",
        "let bunny = scan(\"" + bunny.string() +
            "\")\n"
            "let ball = sphere([-0.02, 0.17, 0.0], 0.02)\n"
            "difference(union(bunny, ball), box([-0.2, 0.0, -0.2], [0.2, 0.05, 0.2]))\n");
    const auto output = dir / "bunny.ply";
    const auto r = run("model " + quoted(dir / "scene.pf") + " -o " + quoted(output) + " --json");
    ASSERT_EQ(r.exit_code, 0) << r.out;
    const auto report = nlohmann::json::parse(r.out);
    ASSERT_EQ(report["scans"].size(), 1U);
    EXPECT_TRUE(report["scans"][0]["estimated_normals"].get<bool>());
    // Default cell: 0.4 of the scan's median influence radius.
    EXPECT_NEAR(report["cell"].get<double>(),
                0.4 * report["scans"][0]["median_radius"].get<double>(),
                1e-6 * report["cell"].get<double>());
    const TriMesh mesh = read_mesh(output);
    EXPECT_TRUE(analyze_topology(mesh).is_oriented_manifold());
    const double cell = report["cell"].get<double>();
    std::size_t on_ball = 0;
    for (std::size_t v = 0; v < mesh.vertex_count(); ++v)
    {
        const Vec3d p = mesh.vertices.world(v);
        // Nothing is left below the cut (vertices on the crease where the cut meets the scan
        // lie within half a cell of it).
        ASSERT_GT(p.y(), 0.05 - 0.5 * cell) << p.transpose();
        if (std::abs((p - Vec3d(-0.02, 0.17, 0.0)).norm() - 0.02) < 0.1 * cell)
        {
            ++on_ball;
        }
    }
    EXPECT_GT(on_ball, 50U); // the ball's cap above the bunny is in the mesh
}

TEST(ModelCli, MorphWritesTheSequence)
{
    test::TempDir dir;
    const auto prefix = dir / "m";
    const auto r = run("morph 'sphere([0,0,0], 1)' 'box([-0.7,-0.7,-0.7],[0.7,0.7,0.7])' -o " +
                       quoted(prefix) + " --steps 4 --resolution 32 --json");
    ASSERT_EQ(r.exit_code, 0) << r.out;
    const auto report = nlohmann::json::parse(r.out);
    ASSERT_EQ(report["steps"].size(), 5U);
    for (int i = 0; i <= 4; ++i)
    {
        const auto path = dir / ("m_00" + std::to_string(i) + ".ply");
        ASSERT_TRUE(std::filesystem::exists(path)) << path;
        EXPECT_EQ(report["steps"][i]["output"].get<std::string>(), path.string());
        EXPECT_DOUBLE_EQ(report["steps"][i]["t"].get<double>(), i / 4.0);
        EXPECT_EQ(report["steps"][i]["euler_characteristic"].get<int>(), 2);
        EXPECT_EQ(report["steps"][i]["boundary_loops"].get<int>(), 0);
    }
    EXPECT_FALSE(std::filesystem::exists(dir / "m_005.ply"));
    const double cell = report["cell"].get<double>();
    // t = 0 is the sphere, t = 1 the box.
    const TriMesh first = read_mesh(dir / "m_000.ply");
    EXPECT_LT(max_vertex_distance(first, [](const Vec3d& p) { return p.norm() - 1.0; }),
              0.1 * cell);
    const TriMesh last = read_mesh(dir / "m_004.ply");
    EXPECT_LT(max_vertex_distance(last,
                                  [](const Vec3d& p) {
                                      const Vec3d q = p.cwiseAbs() - Vec3d::Constant(0.7);
                                      return q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0);
                                  }),
              0.1 * cell);
    // Halfway, the surface is the zero set of the average of the two distances.
    const TriMesh middle = read_mesh(dir / "m_002.ply");
    EXPECT_LT(max_vertex_distance(middle,
                                  [](const Vec3d& p) {
                                      const Vec3d q = p.cwiseAbs() - Vec3d::Constant(0.7);
                                      const double box =
                                          q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0);
                                      return 0.5 * (p.norm() - 1.0) + 0.5 * box;
                                  }),
              0.1 * cell);
}

TEST(ModelCli, ErrorsPointAtTheLineAndColumnAndWriteNothing)
{
    test::TempDir dir;
    const auto output = dir / "out.ply";
    const auto typo =
        run("model 'union(sphere([0,0,0],1), sphre([1,0,0],1))' -o " + quoted(output));
    EXPECT_EQ(typo.exit_code, 2);
    EXPECT_NE(typo.out.find("expression:1:26: unknown function 'sphre'; did you mean 'sphere'?"),
              std::string::npos)
        << typo.out;
    test::write_file(dir / "bad.pf",
                     "let a = sphere([0,0,0], 1)\nlet b = sphere([1,0,0] 1)\n"
                     "union(a, b)\n");
    const auto file = run("model " + quoted(dir / "bad.pf") + " -o " + quoted(output));
    EXPECT_EQ(file.exit_code, 2);
    EXPECT_NE(file.out.find((dir / "bad.pf").string() +
                            ":2:24: expected ',' or ')' after argument 1 of sphere, found '1'"),
              std::string::npos)
        << file.out;
    const auto missing = run("model 'scan(\"nothere.ply\")' -o " + quoted(output));
    EXPECT_EQ(missing.exit_code, 2);
    EXPECT_NE(missing.out.find("expression:1:6: scan file not found"), std::string::npos)
        << missing.out;
    const auto negative = run("model 'sphere([0,0,0], -1)' -o " + quoted(output));
    EXPECT_EQ(negative.exit_code, 2);
    EXPECT_NE(negative.out.find("radius' of sphere must be > 0"), std::string::npos)
        << negative.out;
    const auto bad_bounds =
        run("model 'sphere([0,0,0],1)' -o " + quoted(output) + " --bounds 1,2,3");
    EXPECT_NE(bad_bounds.exit_code, 0);
    EXPECT_FALSE(std::filesystem::exists(output));

    // A morph between shapes that do not overlap, or with a broken scene, writes no file.
    const auto apart =
        run("morph 'sphere([0,0,0],1)' 'sphere([5,0,0],1)' -o " + quoted(dir / "m") + " --steps 2");
    EXPECT_EQ(apart.exit_code, 2) << apart.out;
    const auto broken = run("morph 'sphere([0,0,0],1)' 'box([0,0,0],[1,1,1]' -o " +
                            quoted(dir / "m") + " --steps 2");
    EXPECT_EQ(broken.exit_code, 2) << broken.out;
    EXPECT_NE(broken.out.find("expression:1:20: expected ',' or ')' after argument 2 of box, "
                              "found end of input"),
              std::string::npos)
        << broken.out;
    // An output folder that does not exist: the run fails and leaves nothing behind.
    const auto nowhere = run("morph 'sphere([0,0,0],1)' 'sphere([0.5,0,0],1)' -o " +
                             quoted(dir / "no" / "m") + " --steps 2 --resolution 8");
    EXPECT_NE(nowhere.exit_code, 0);
    EXPECT_FALSE(std::filesystem::exists(dir / "m_000.ply"));
}

} // namespace
} // namespace pointform
