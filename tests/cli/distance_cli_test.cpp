// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// `pointform distance` end to end: analytic distances between meshes and point sets, JSON and
// table output, determinism, and bad input.

#include "pointform/io/io.h"

#include "cli_run.h"
#include "support/test_meshes.h"
#include "support/test_support.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

namespace pointform {
namespace {

using test::quoted;
using test::run;
using test::RunResult;

using test::box_mesh;

const std::string bunny = quoted(test::data_path("meshes/bunny_uniform.off"));

TEST(DistanceCli, MeshAgainstItselfIsZero)
{
    const RunResult r = run("distance " + bunny + " " + bunny + " --samples 20000 --json");
    ASSERT_EQ(r.exit_code, 0) << r.out;
    const auto report = nlohmann::json::parse(r.out);
    EXPECT_EQ(report["a"]["kind"], "mesh");
    EXPECT_EQ(report["a"]["faces"], 17804);
    EXPECT_EQ(report["a"]["samples"], 20000 + 8904);
    EXPECT_EQ(report["absolute"]["a_to_b"]["count"], 20000 + 8904);
    EXPECT_GT(report["diagonal"].get<double>(), 0.0);
    EXPECT_LT(report["relative_to_diagonal"]["hausdorff"].get<double>(), 1e-6);
    EXPECT_LT(report["relative_to_diagonal"]["chamfer"].get<double>(), 1e-7);
}

TEST(DistanceCli, CubeAgainstItsTranslateInBothFormats)
{
    // B = A + (t, 0, 0): the face x = 0 of A is at distance t from B, and nothing farther.
    const double t = 0.25;
    test::TempDir dir;
    write_mesh(dir / "a.off", box_mesh(Vec3d(0, 0, 0), Vec3d(1, 1, 1)));
    write_mesh(dir / "b.ply", box_mesh(Vec3d(t, 0, 0), Vec3d(1 + t, 1, 1)));
    const std::string files = quoted(dir / "a.off") + " " + quoted(dir / "b.ply");
    const RunResult r = run("distance " + files + " --samples 5000 --json");
    ASSERT_EQ(r.exit_code, 0) << r.out;
    const auto report = nlohmann::json::parse(r.out);
    const double diagonal = std::sqrt((1 + t) * (1 + t) + 2.0);
    EXPECT_NEAR(report["diagonal"].get<double>(), diagonal, 1e-9);
    for (const char* side : {"a_to_b", "b_to_a", "symmetric"})
    {
        EXPECT_NEAR(report["absolute"][side]["max"].get<double>(), t, 1e-7) << side;
        EXPECT_NEAR(report["relative_to_diagonal"][side]["max"].get<double>(), t / diagonal, 1e-7)
            << side;
    }
    EXPECT_NEAR(report["absolute"]["hausdorff"].get<double>(), t, 1e-7);
    EXPECT_DOUBLE_EQ(report["absolute"]["chamfer"].get<double>(),
                     report["absolute"]["a_to_b"]["mean"].get<double>() +
                         report["absolute"]["b_to_a"]["mean"].get<double>());

    const RunResult table = run("distance " + files + " --samples 5000");
    ASSERT_EQ(table.exit_code, 0) << table.out;
    for (const char* word : {"Hausdorff", "Chamfer", "A -> B", "B -> A", "symmetric", "p99",
                             "relative to the bounding box diagonal"})
        EXPECT_NE(table.out.find(word), std::string::npos) << word << "\n" << table.out;
    EXPECT_NE(table.out.find("0.25"), std::string::npos) << table.out;

    // F-score: every sample of either cube off the one face pair is within t of the other, the
    // rest too (the faces x = 0 and x = 1 + t are t away): at a threshold just above t both
    // shares are 1, and far below t they miss the faces that are t away.
    const RunResult scored = run("distance " + files + " --samples 5000 --json --fscore 0.0001," +
                                 std::to_string(1.01 * t / diagonal));
    ASSERT_EQ(scored.exit_code, 0) << scored.out;
    const auto fscore = nlohmann::json::parse(scored.out)["fscore"];
    ASSERT_EQ(fscore.size(), 2U);
    EXPECT_LT(fscore[0]["f"].get<double>(), 1.0);
    EXPECT_DOUBLE_EQ(fscore[1]["precision"].get<double>(), 1.0);
    EXPECT_DOUBLE_EQ(fscore[1]["recall"].get<double>(), 1.0);
    EXPECT_NE(run("distance " + files + " --fscore 0").exit_code, 0);
}

TEST(DistanceCli, PointSetAgainstMesh)
{
    // The mesh's own vertices, as a point set, lie on it: A -> B is zero.
    test::TempDir dir;
    const TriMesh mesh = read_mesh(test::data_path("meshes/bunny_uniform.off"));
    write_point_cloud(dir / "vertices.xyz", mesh.vertices);
    const RunResult r =
        run("distance " + quoted(dir / "vertices.xyz") + " " + bunny + " --samples 10000 --json");
    ASSERT_EQ(r.exit_code, 0) << r.out;
    const auto report = nlohmann::json::parse(r.out);
    EXPECT_EQ(report["a"]["kind"], "points");
    EXPECT_EQ(report["a"]["samples"], 8904);
    EXPECT_LT(report["relative_to_diagonal"]["a_to_b"]["max"].get<double>(), 1e-6);
    // B -> A: mesh samples to the vertices, bounded by the edge length of the uniform remesh.
    const double b_to_a = report["relative_to_diagonal"]["b_to_a"]["max"].get<double>();
    EXPECT_GT(b_to_a, 0.0);
    EXPECT_LT(b_to_a, 0.02);
}

TEST(DistanceCli, SameResultWhateverTheThreadCount)
{
    const std::string sphere = quoted(test::data_path("meshes/spot.obj"));
    const RunResult one = run("-j 1 distance " + bunny + " " + sphere + " --samples 5000 --json");
    const RunResult three = run("-j 3 distance " + bunny + " " + sphere + " --samples 5000 --json");
    ASSERT_EQ(one.exit_code, 0) << one.out;
    ASSERT_EQ(three.exit_code, 0) << three.out;
    const auto a = nlohmann::json::parse(one.out);
    const auto b = nlohmann::json::parse(three.out);
    EXPECT_EQ(a["absolute"], b["absolute"]);
    EXPECT_EQ(a["relative_to_diagonal"], b["relative_to_diagonal"]);
    // A different seed samples differently.
    const RunResult other =
        run("distance " + bunny + " " + sphere + " --samples 5000 --seed 2 --json");
    ASSERT_EQ(other.exit_code, 0) << other.out;
    EXPECT_NE(a["absolute"]["a_to_b"]["mean"],
              nlohmann::json::parse(other.out)["absolute"]["a_to_b"]["mean"]);
}

TEST(DistanceCli, BadInputFailsCleanly)
{
    test::TempDir dir;
    test::write_file(dir / "nan.xyz", "0 0 0\n1 0 0\nnan 1 0\n");
    test::write_file(dir / "empty.ply",
                     "ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\n"
                     "property float y\nproperty float z\nend_header\n");
    test::write_file(dir / "flat.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n2 0 0\n3 0 1 2\n");
    struct Case
    {
        std::string arguments;
        int exit_code;
        std::string message;
    };
    const std::vector<Case> cases = {
        {quoted(dir / "missing.ply") + " " + bunny, 3, "missing.ply"},
        {bunny + " " + quoted(dir / "nan.xyz"), 3, "nan.xyz"},
        {quoted(dir / "empty.ply") + " " + bunny, 2, "empty.ply"},
        {bunny + " " + quoted(dir / "flat.off"), 2, "zero area"},
    };
    for (const Case& c : cases)
    {
        const RunResult r = run("distance " + c.arguments);
        EXPECT_EQ(r.exit_code, c.exit_code) << c.arguments << ": " << r.out;
        EXPECT_NE(r.out.find(c.message), std::string::npos) << c.arguments << ": " << r.out;
    }
    // Usage errors: a missing operand, zero samples.
    EXPECT_NE(run("distance " + bunny).exit_code, 0);
    EXPECT_NE(run("distance " + bunny + " " + bunny + " --samples 0").exit_code, 0);
}

} // namespace
} // namespace pointform
