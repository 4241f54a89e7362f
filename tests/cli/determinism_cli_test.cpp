// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// Same input and options, same output bytes whatever --threads: `normals`, `mc`, `reconstruct`
// and `model --semi-regular` run on the Stanford bunny at -j 1, 2 and 3, their JSON reports'
// "parallel" figures showing the work really was split into blocks run by several threads.

#include "pointform/io/hierarchy.h"

#include "cli_run.h"
#include "multires/multires_fixtures.h"
#include "support/test_support.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>
#include <vector>

namespace pointform {
namespace {

using test::quoted;
using test::run;

/// Runs `command` (which must print a JSON report) at -j 1, 2 and 3, each writing the files
/// named by `outputs` with "{j}" replaced by the thread count, and checks that the files are
/// byte-identical across the runs and that the runs split their work into several blocks, on
/// one thread at -j 1 and on more than one at -j 2 and 3.
void expect_same_bytes(const std::string& command, const std::vector<std::string>& outputs,
                       const test::TempDir& dir)
{
    const auto expand = [](std::string text, int j) {
        for (std::size_t at = text.find("{j}"); at != std::string::npos; at = text.find("{j}"))
            text.replace(at, 3, std::to_string(j));
        return text;
    };
    std::vector<std::string> first;
    for (const int j : {1, 2, 3})
    {
        const auto r = run("-j " + std::to_string(j) + " " + expand(command, j));
        ASSERT_EQ(r.exit_code, 0) << r.out;
        const auto report = nlohmann::json::parse(r.out);
        ASSERT_TRUE(report.contains("parallel")) << r.out;
        const auto& parallel = report["parallel"];
        EXPECT_GE(parallel["multi_block_loops"].get<int>(), 3) << j << " threads";
        EXPECT_GE(parallel["blocks"].get<int>(), parallel["loops"].get<int>()) << j;
        EXPECT_EQ(parallel["max_team_threads"].get<int>(), j);
        if (j == 1)
        {
            EXPECT_EQ(parallel["max_threads_per_loop"].get<int>(), 1);
        }
        else
        {
            EXPECT_GT(parallel["max_threads_per_loop"].get<int>(), 1) << j << " threads";
        }
        EXPECT_EQ(report["threads"].get<int>(), j);
        for (std::size_t o = 0; o < outputs.size(); ++o)
        {
            const std::string bytes = test::read_file(dir / expand(outputs[o], j));
            ASSERT_FALSE(bytes.empty()) << outputs[o];
            if (j == 1)
                first.push_back(bytes);
            else
                EXPECT_TRUE(bytes == first[o])
                    << expand(outputs[o], j) << " differs from " << expand(outputs[o], 1);
        }
    }
}

const std::filesystem::path bunny = test::data_path("bunny/bun_zipper.ply");

TEST(DeterminismCli, Normals)
{
    test::TempDir dir;
    expect_same_bytes("normals " + quoted(bunny) + " -o " + quoted(dir / "n{j}.ply") + " --json",
                      {"n{j}.ply"}, dir);
}

TEST(DeterminismCli, MarchingCubes)
{
    test::TempDir dir;
    expect_same_bytes("mc " + quoted(bunny) + " -o " + quoted(dir / "m{j}.ply") + " --json",
                      {"m{j}.ply"}, dir);
}

TEST(DeterminismCli, Reconstruct)
{
    test::TempDir dir;
    expect_same_bytes("reconstruct " + quoted(bunny) + " -o " + quoted(dir / "r{j}.ply") +
                          " --levels 2 --save-hierarchy " + quoted(dir / "r{j}.pfh") + " --json",
                      {"r{j}.ply", "r{j}.pfh"}, dir);
}

TEST(DeterminismCli, ModelSemiRegular)
{
    test::TempDir dir;
    // A scan, a primitive and operators, so the scene's own evaluation is compared too.
    test::write_file(dir / "scene.pf",
                     "let bunny = scan(\"" + bunny.string() +
                         "\")\n"
                         "let ball = sphere([-0.02, 0.17, 0.0], 0.02)\n"
                         "difference(union(bunny, ball), box([-0.2, 0.0, -0.2], [0.2, 0.05, "
                         "0.2]))\n");
    expect_same_bytes("model " + quoted(dir / "scene.pf") + " -o " + quoted(dir / "s{j}.ply") +
                          " --semi-regular --levels 2 --save-hierarchy " +
                          quoted(dir / "s{j}.pfh") + " --json",
                      {"s{j}.ply", "s{j}.pfh"}, dir);
}

TEST(DeterminismCli, DeformEditAndLattice)
{
    test::TempDir dir;
    // Level 6 of the bumpy sphere adds 122,880 vertices: 30 blocks per synthesis loop.
    const MultiresMesh mesh = test::relief_sphere(6, Predictor::Butterfly);
    write_hierarchy(dir / "in.pfh", mesh);
    const Vec3d c = mesh.world(3);
    test::write_file(dir / "edit.json",
                     R"({"level": 0, "handles": [{"vertices": [3], "translate": [0.05, 0, 0.1]}],
                         "region": {"ball": {"center": [)" +
                         std::to_string(c.x()) + ", " + std::to_string(c.y()) + ", " +
                         std::to_string(c.z()) + R"(], "radius": 1.2}}})");
    expect_same_bytes("deform " + quoted(dir / "in.pfh") + " -o " + quoted(dir / "e{j}.pfh") +
                          " --mesh " + quoted(dir / "e{j}.ply") + " --edit " +
                          quoted(dir / "edit.json") + " --json",
                      {"e{j}.pfh", "e{j}.ply"}, dir);
    test::write_file(dir / "lattice.json",
                     R"({"min": [-1.2, -1.2, -1.2], "max": [1.2, 1.2, 1.2], "degree": [1, 1, 1],
                         "level": 2, "control_points": [[-1.2, -1.2, -1.2], [1.4, -1.2, -1.2],
                         [-1.2, 1.2, -1.2], [1.2, 1.2, -1.2], [-1.2, -1.2, 1.2],
                         [1.2, -1.2, 1.2], [-1.2, 1.2, 1.2], [1.2, 1.5, 1.6]]})");
    expect_same_bytes("deform " + quoted(dir / "in.pfh") + " -o " + quoted(dir / "l{j}.pfh") +
                          " --lattice " + quoted(dir / "lattice.json") + " --json",
                      {"l{j}.pfh"}, dir);
}

} // namespace
} // namespace pointform
