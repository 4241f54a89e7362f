// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// `pointform deform`: an edit or a lattice gives the library's result bit for bit, with its
// report; bad edits and lattices exit 2, unreadable files 3, and no output is written or lost.

#include "pointform/io/hierarchy.h"
#include "pointform/io/io.h"
#include "pointform/multires/deformation.h"
#include "pointform/multires/lattice.h"

#include "cli_run.h"
#include "multires/multires_fixtures.h"
#include "support/test_support.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>

namespace pointform {
namespace {

using test::quoted;
using test::run;

bool same_positions(const MultiresMesh& a, const MultiresMesh& b)
{
    return std::equal(a.positions().begin(), a.positions().end(), b.positions().begin(),
                      b.positions().end());
}

TEST(DeformCli, AnEditGivesTheLibrarysResultAndItsReport)
{
    test::TempDir dir;
    const MultiresMesh original = test::relief_sphere(3, Predictor::Butterfly);
    const auto input = dir / "in.pfh";
    write_hierarchy(input, original);
    const Vec3d centre = original.world(3);
    // A second handle: a vertex of level 1 near the first, inside the region.
    std::uint32_t second = 0;
    for (std::uint32_t v = 0; v < original.vertex_count(1); ++v)
        if (v != 3 && (original.world(v) - centre).norm() < 0.4)
            second = v;
    ASSERT_NE(second, 0U);
    test::write_file(dir / "edit.json",
                     R"({"level": 1, "handles": [{"vertices": [3], "translate": [0, 0, 0.1]},
                         {"vertices": [)" +
                         std::to_string(second) +
                         R"(], "matrix": [1,0,0,0.02, 0,1,0,0, 0,0,1,0, 0,0,0,1]}],
                         "region": {"ball": {"center": [)" +
                         std::to_string(centre.x()) + "," + std::to_string(centre.y()) + "," +
                         std::to_string(centre.z()) + R"(], "radius": 0.9}}})");
    const auto output = dir / "out.pfh";
    const auto mesh_path = dir / "out.ply";
    const auto r = run("deform " + quoted(input) + " -o " + quoted(output) + " --mesh " +
                       quoted(mesh_path) + " --edit " + quoted(dir / "edit.json") + " --json");
    ASSERT_EQ(r.exit_code, 0) << r.out;

    MultiresMesh expected = original;
    MultiresEdit edit{.level = 1,
                      .handles = {DeformHandle::translate({3}, Vec3d(0, 0, 0.1)),
                                  DeformHandle::translate({second}, Vec3d(0.02, 0, 0))},
                      .region = RegionOfInterest::ball(Vec3d(std::stod(std::to_string(centre.x())),
                                                             std::stod(std::to_string(centre.y())),
                                                             std::stod(std::to_string(centre.z()))),
                                                       0.9)};
    const DeformReport report = deform(expected, edit);
    const MultiresMesh written = read_hierarchy(output);
    EXPECT_TRUE(same_positions(written, expected));
    EXPECT_EQ(written.predictor(), Predictor::Butterfly);
    EXPECT_EQ(read_mesh(mesh_path).face_count(), original.face_count(3));

    const auto json = nlohmann::json::parse(r.out);
    EXPECT_EQ(json["mode"], "edit");
    EXPECT_EQ(json["predictor"], "butterfly");
    const auto& d = json["deformation"];
    EXPECT_EQ(d["handle_vertices"].get<std::size_t>(), 2U);
    EXPECT_EQ(d["free_vertices"].get<std::size_t>(), report.free_vertices);
    EXPECT_DOUBLE_EQ(d["largest_displacement"].get<double>(), report.largest_displacement);
    ASSERT_EQ(d["levels"].size(), 4U);
    for (std::size_t l = 0; l < 4; ++l)
        EXPECT_EQ(d["levels"][l]["moved"].get<std::size_t>(), report.levels[l].moved);
    EXPECT_GT(d["levels"][3]["moved"].get<std::size_t>(), 0U);
    EXPECT_LT(d["levels"][3]["moved"].get<std::size_t>(), original.vertex_count() / 2);
    ASSERT_EQ(json["details"]["levels"].size(), 3U);
    EXPECT_GE(json["details"]["levels"][0]["normal_share"].get<double>(), 0.0);

    // Without --json: a table for people.
    const auto text = run("deform " + quoted(input) + " -o " + quoted(output) + " --edit " +
                          quoted(dir / "edit.json"));
    ASSERT_EQ(text.exit_code, 0) << text.out;
    EXPECT_NE(text.out.find("normal details"), std::string::npos) << text.out;
}

TEST(DeformCli, LatticesAtRestAndPlain)
{
    test::TempDir dir;
    const MultiresMesh original = test::relief_plate(2);
    const auto input = dir / "in.pfh";
    write_hierarchy(input, original);
    const Lattice rest = rest_lattice(Vec3d(-1.5, -1.5, -0.5), Vec3d(1.5, 1.5, 0.5), {2, 2, 1});
    nlohmann::json lattice;
    lattice["min"] = {-1.5, -1.5, -0.5};
    lattice["max"] = {1.5, 1.5, 0.5};
    lattice["degree"] = {2, 2, 1};
    lattice["level"] = 1;
    lattice["control_points"] = nlohmann::json::array();
    for (const Vec3d& p : rest.control_points)
        lattice["control_points"].push_back({p.x(), p.y(), p.z()});
    test::write_file(dir / "rest.json", lattice.dump());
    const auto r = run("deform " + quoted(input) + " -o " + quoted(dir / "rest.pfh") +
                       " --lattice " + quoted(dir / "rest.json"));
    ASSERT_EQ(r.exit_code, 0) << r.out;
    EXPECT_LE(test::largest_difference(read_hierarchy(dir / "rest.pfh"), original),
              1e-12 * test::diagonal(original));

    // Lift the middle control points; --plain moves every vertex through the lattice.
    for (std::size_t j = 0; j <= 2; ++j)
        for (std::size_t k = 0; k <= 1; ++k)
            lattice["control_points"][rest.index(1, j, k)][2] =
                rest.control_points[rest.index(1, j, k)].z() + 0.3;
    test::write_file(dir / "lift.json", lattice.dump());
    for (const bool plain : {false, true})
    {
        const auto out = dir / (plain ? "plain.pfh" : "details.pfh");
        const auto lifted = run("deform " + quoted(input) + " -o " + quoted(out) + " --lattice " +
                                quoted(dir / "lift.json") + (plain ? " --plain" : "") + " --json");
        ASSERT_EQ(lifted.exit_code, 0) << lifted.out;
        EXPECT_EQ(nlohmann::json::parse(lifted.out)["mode"],
                  plain ? "lattice (plain)" : "lattice (details)");
        MultiresMesh expected = original;
        Lattice lift = rest;
        for (std::size_t j = 0; j <= 2; ++j)
            for (std::size_t k = 0; k <= 1; ++k)
                lift.control_points[lift.index(1, j, k)].z() += 0.3;
        (void)apply_lattice(expected, lift, 1, plain ? LatticeMode::Plain : LatticeMode::Details);
        EXPECT_TRUE(same_positions(read_hierarchy(out), expected));
    }
}

TEST(DeformCli, BadEditsExitTwoAndWriteNothing)
{
    test::TempDir dir;
    const MultiresMesh original = test::relief_sphere(2);
    const auto input = dir / "in.pfh";
    write_hierarchy(input, original);
    const auto output = dir / "out.pfh";
    const auto mesh_path = dir / "out.ply";
    test::write_file(mesh_path, "precious");
    const auto refused = [&](const std::string& option, const std::string& text,
                             const std::string& says, int code = 2) {
        SCOPED_TRACE(text);
        test::write_file(dir / "bad.json", text);
        const auto r = run("deform " + quoted(input) + " -o " + quoted(output) + " --mesh " +
                           quoted(mesh_path) + " " + option + " " + quoted(dir / "bad.json"));
        EXPECT_EQ(r.exit_code, code) << r.out;
        EXPECT_NE(r.out.find(says), std::string::npos) << r.out;
        EXPECT_FALSE(std::filesystem::exists(output));
        EXPECT_EQ(test::read_file(mesh_path), "precious");
    };
    const std::string move = R"("translate": [0, 0, 1]})";
    refused("--edit", R"({"level": 0, "handles": [{"vertices": [4000], )" + move + "]}",
            "vertex 4000 is not a vertex of level 0");
    refused("--edit",
            R"({"level": 0, "handles": [{"vertices": [1], )" + move +
                R"(], "region": {"vertices": [2, 3]}})",
            "outside the region");
    refused("--edit", R"({"level": 7, "handles": []})", "level 7 does not exist");
    refused("--edit", R"({"level": 0, "handles": [{"vertices": [1], "translate": [NaN, 0, 0]}]})",
            "not valid JSON");
    refused("--edit", R"({"level": 0, "handles": [{"vertices": [1], "translate": [1e999, 0, 0]}]})",
            "number overflow");
    refused("--edit", R"({"level": 0, "handels": []})", "unknown key \"handels\"");
    refused("--edit", R"({"level": -1})", "\"level\" must be a whole number");
    refused("--edit", R"({"level": 0, "handles": [{"vertices": [1.5], )" + move + "]}",
            "must be a whole number");
    refused("--edit", R"({"level": 0, "handles": [{"vertices": [1], "matrix": [1, 2, 3]}]})",
            "16 numbers");
    refused("--edit", std::string(100, '[') + std::string(100, ']'), "nesting deeper");
    refused("--edit",
            R"({"level": 0, "handles": [{"vertices": [1], )" + move +
                R"(], "region": {"ball": {"center": [0,0,0], "radius": 0}}})",
            "radius");
    refused("--edit",
            R"({"level": 0, "handles": [{"vertices": [1], "ball": {"center": [0,0,0],
                "radius": 0.5}, "translate": [0, 0, 1]}]})",
            "exactly one of \"vertices\", \"ball\" and \"box\"");
    refused("--edit",
            R"({"level": 0, "handles": [{"ball": {"center": [9,9,9], "radius": 0.5},
                "translate": [0, 0, 1]}]})",
            "holds no vertex of level 0");
    refused("--edit",
            R"({"level": 0, "handles": [{"box": {"min": [0,0,0], "max": [-1,1,1]},
                "translate": [0, 0, 1]}]})",
            "handle 0's box needs finite corners");
    refused("--edit",
            R"({"level": 0, "handles": [{"ball": {"centre": [0,0,0], "radius": 1},
                "translate": [0, 0, 1]}]})",
            "unknown key \"centre\"");
    refused("--lattice",
            R"({"min": [-2,-2,-2], "max": [2,2,2], "degree": [1,1,1],
                "control_points": [[0,0,0]]})",
            "needs 8 control points, not 1");
    refused("--lattice",
            R"({"min": [-2,-2,-2], "max": [2,2,2], "degree": [1,1,1], "level": 9,
                "control_points": [[-2,-2,-2],[2,-2,-2],[-2,2,-2],[2,2,-2],
                                   [-2,-2,2],[2,-2,2],[-2,2,2],[2,2,2]]})",
            "level 9 does not exist");
    refused("--lattice", R"({"min": [2,2,2], "max": [-2,-2,-2], "degree": [1,1,1],
                             "control_points": []})",
            "min < max");

    // Missing files exit 3; a missing mode or --plain without a lattice exit 2.
    auto r = run("deform " + quoted(input) + " -o " + quoted(output) + " --edit " +
                 quoted(dir / "missing.json"));
    EXPECT_EQ(r.exit_code, 3) << r.out;
    r = run("deform " + quoted(dir / "missing.pfh") + " -o " + quoted(output) + " --edit " +
            quoted(dir / "bad.json"));
    EXPECT_EQ(r.exit_code, 3) << r.out;
    r = run("deform " + quoted(input) + " -o " + quoted(output));
    EXPECT_EQ(r.exit_code, 2) << r.out;
    EXPECT_NE(r.out.find("--edit"), std::string::npos) << r.out;
    r = run("deform " + quoted(input) + " -o " + quoted(output) + " --plain --edit " +
            quoted(dir / "bad.json"));
    EXPECT_EQ(r.exit_code, 2) << r.out;
    EXPECT_FALSE(std::filesystem::exists(output));
}

TEST(DeformCli, TheDocumentedExamplesRunOnTheQuickStartBunny)
{
    // docs/deform.md and the README edit the bunny that the quick start reconstructs (default
    // options); their vertex ids must still name its ear tip.
    test::TempDir dir;
    const auto hierarchy = dir / "bunny.pfh";
    const auto made =
        run("reconstruct " + quoted(test::data_path("bunny/bun_zipper.ply")) + " -o " +
            quoted(dir / "bunny.ply") + " --save-hierarchy " + quoted(hierarchy) + " -q");
    ASSERT_EQ(made.exit_code, 0) << made.out;
    const MultiresMesh bunny = read_hierarchy(hierarchy);
    const std::filesystem::path examples = test::data_path("../docs/examples");
    const auto ear = run("deform " + quoted(hierarchy) + " -o " + quoted(dir / "ear.pfh") +
                         " --edit " + quoted(examples / "bunny_ear.json") + " --json");
    ASSERT_EQ(ear.exit_code, 0) << ear.out;
    const auto report = nlohmann::json::parse(ear.out);
    // The handle is the base vertices in a ball at the tip of an ear (the highest part of the
    // bunny there): several of them, all high, and the tip rises by most of the translation.
    EXPECT_GE(report["deformation"]["handle_vertices"].get<std::size_t>(), 6U);
    const Vec3d center(-0.02, 0.185, -0.019);
    std::uint32_t tip = 0;
    std::size_t handle = 0;
    for (std::uint32_t v = 0; v < bunny.vertex_count(0); ++v)
    {
        if ((bunny.world(v) - center).norm() > 0.012)
            continue;
        ++handle;
        EXPECT_GT(bunny.world(v).y(), 0.17) << "vertex " << v << " is not at the ear tip";
        if (bunny.world(v).y() > bunny.world(tip).y())
            tip = v;
    }
    EXPECT_EQ(report["deformation"]["handle_vertices"].get<std::size_t>(), handle);
    EXPECT_GT(read_hierarchy(dir / "ear.pfh").world(tip).y(), bunny.world(tip).y() + 0.02);
    const auto bend = run("deform " + quoted(hierarchy) + " -o " + quoted(dir / "bend.pfh") +
                          " --lattice " + quoted(examples / "bunny_bend.json"));
    EXPECT_EQ(bend.exit_code, 0) << bend.out;
}

} // namespace
} // namespace pointform
