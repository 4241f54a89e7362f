// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// `pointform model` on scenes that once broke it: a Boolean whose surface holds no seed of its
// members, a scene nested 20 000 deep, and bindings shared along 2^40 paths. Each answers within
// seconds, with the right mesh or a clear error at its line and column.

#include "pointform/geometry/mesh_topology.h"
#include "pointform/io/io.h"

#include "cli_run.h"
#include "support/test_support.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <string>

namespace pointform {
namespace {

using test::quoted;
using test::run;

/// Volume enclosed by a closed, outward-oriented mesh.
double enclosed_volume(const TriMesh& mesh)
{
    double volume = 0.0;
    for (const auto& t : mesh.triangles)
    {
        const Vec3d a = mesh.vertices.world(t[0]);
        const Vec3d b = mesh.vertices.world(t[1]);
        const Vec3d c = mesh.vertices.world(t[2]);
        volume += a.dot(b.cross(c)) / 6.0;
    }
    return volume;
}

/// Volume of {x, y, z ≥ a, |p| ≤ 1} by the midpoint rule over (y, z) of the exact chord in x.
double corner_of_ball_volume(double a)
{
    constexpr int n = 2000;
    const double top = std::sqrt(1.0 - 2.0 * a * a);
    const double h = (top - a) / n;
    double sum = 0.0;
    for (int i = 0; i < n; ++i)
    {
        for (int j = 0; j < n; ++j)
        {
            const double y = a + (i + 0.5) * h;
            const double z = a + (j + 0.5) * h;
            const double x2 = 1.0 - y * y - z * z;
            if (x2 > a * a)
            {
                sum += std::sqrt(x2) - a;
            }
        }
    }
    return sum * h * h;
}

double seconds_since(std::chrono::steady_clock::time_point start)
{
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

TEST(SceneHostileCli, IntersectionWithoutMemberSeedsOnItsSurfaceIsPolygonized)
{
    test::TempDir dir;
    const auto output = dir / "corner.ply";
    const auto r = run("model 'intersection(sphere([0,0,0],1), box([0.3,0.3,0.3],[2,2,2]))' -o " +
                       quoted(output) + " --resolution 64 --json");
    ASSERT_EQ(r.exit_code, 0) << r.out;
    const auto report = nlohmann::json::parse(r.out);
    EXPECT_EQ(report["components"].get<int>(), 1);
    EXPECT_EQ(report["boundary_loops"].get<int>(), 0);
    EXPECT_EQ(report["euler_characteristic"].get<int>(), 2);
    const TriMesh mesh = read_mesh(output);
    const MeshTopology topo = analyze_topology(mesh);
    EXPECT_TRUE(topo.is_closed());
    EXPECT_TRUE(topo.is_oriented_manifold());
    const double cell = report["cell"].get<double>();
    double worst = 0.0;
    for (std::size_t v = 0; v < mesh.vertex_count(); ++v)
    {
        const Vec3d p = mesh.vertices.world(v);
        const double box = (Vec3d::Constant(0.3) - p).maxCoeff();
        worst = std::max(worst, std::abs(std::max(p.norm() - 1.0, box)));
    }
    EXPECT_LT(worst, cell);
    // The mesh's volume: the corner of the ball within a few percent (sharp edges cut by ~h).
    const double volume = corner_of_ball_volume(0.3);
    EXPECT_NEAR(enclosed_volume(mesh), volume, 0.03 * volume);
}

TEST(SceneHostileCli, NestingTwentyThousandDeepIsInvalidInputAtItsLineAndColumn)
{
    std::string scene;
    for (int i = 0; i < 20000; ++i)
    {
        scene += "union(";
    }
    test::TempDir dir;
    const auto file = dir / "deep.pf";
    {
        std::ofstream out(file);
        out << "# twenty thousand open calls\n" << scene << "\n";
    }
    const auto start = std::chrono::steady_clock::now();
    const auto r = run("model " + quoted(file) + " -o " + quoted(dir / "deep.ply"));
    EXPECT_EQ(r.exit_code, 2) << r.out;
    // The 257th '(' of line 2.
    EXPECT_NE(r.out.find(file.string() + ":2:1542: nested too deep"), std::string::npos) << r.out;
    EXPECT_FALSE(std::filesystem::exists(dir / "deep.ply"));
    EXPECT_LT(seconds_since(start), 10.0);

    // The same depth through bindings: the binding that nests deeper than 256.
    std::string chain = "let a0 = sphere([0, 0, 0], 1)\n";
    for (int i = 1; i <= 20000; ++i)
    {
        chain += "let a" + std::to_string(i) + " = offset(a" + std::to_string(i - 1) + ", 0)\n";
    }
    chain += "a20000\n";
    const auto chained = dir / "chain.pf";
    {
        std::ofstream out(chained);
        out << chain;
    }
    const auto c = run("model " + quoted(chained) + " -o " + quoted(dir / "chain.ply"));
    EXPECT_EQ(c.exit_code, 2) << c.out;
    EXPECT_NE(c.out.find(chained.string() + ":257:12: offset nests the scene's field too deep"),
              std::string::npos)
        << c.out;
}

TEST(SceneHostileCli, FortySharedBindingsAnswerWithinSeconds)
{
    std::string scene = "let a0 = sphere([0, 0, 0], 1)\n";
    for (int i = 1; i < 40; ++i)
    {
        scene += "let a" + std::to_string(i) + " = union(a" + std::to_string(i - 1) + ", a" +
                 std::to_string(i - 1) + ")\n";
    }
    scene += "a39\n";
    test::TempDir dir;
    const auto file = dir / "shared.pf";
    {
        std::ofstream out(file);
        out << scene;
    }
    const auto start = std::chrono::steady_clock::now();
    const auto r = run("model " + quoted(file) + " -o " + quoted(dir / "shared.ply") +
                       " --resolution 48 --json");
    ASSERT_EQ(r.exit_code, 0) << r.out;
    EXPECT_LT(seconds_since(start), 20.0); // 2^40 evaluations per point without sharing
    const auto report = nlohmann::json::parse(r.out);
    EXPECT_EQ(report["components"].get<int>(), 1);
    EXPECT_EQ(report["euler_characteristic"].get<int>(), 2);
    const TriMesh mesh = read_mesh(dir / "shared.ply");
    const double cell = report["cell"].get<double>();
    for (std::size_t v = 0; v < mesh.vertex_count(); ++v)
    {
        ASSERT_NEAR(mesh.vertices.world(v).norm(), 1.0, cell);
    }
}

} // namespace
} // namespace pointform
