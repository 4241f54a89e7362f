// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// `pointform mc` end to end: raw points and surfels in, a mesh and its report out.

#include "pointform/geometry/mesh_topology.h"
#include "pointform/io/io.h"
#include "pointform/polygonize/reconstruct.h"

#include "cli_run.h"
#include "support/test_support.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <numbers>
#include <string>

namespace pointform {
namespace {

using test::quoted;
using test::run;

TEST(McCli, BunnyScanToAMesh)
{
    test::TempDir dir;
    const auto output = dir / "bunny.ply";
    const auto r = run("mc " + quoted(test::data_path("bunny/bun_zipper.ply")) + " -o " +
                       quoted(output) + " --json");
    ASSERT_EQ(r.exit_code, 0) << r.out;
    const auto report = nlohmann::json::parse(r.out);
    const TriMesh mesh = read_mesh(output);
    EXPECT_EQ(report["faces"].get<std::size_t>(), mesh.face_count());
    EXPECT_EQ(report["vertices"].get<std::size_t>(), mesh.vertex_count());
    EXPECT_EQ(report["degenerate_kept"].get<std::size_t>(), 0U);
    EXPECT_LE(report["degenerate_triangles"].get<std::size_t>(), mesh.face_count());
    const MeshTopology topo = analyze_topology(mesh);
    EXPECT_TRUE(topo.is_oriented_manifold());
    EXPECT_EQ(report["boundary_loops"].get<std::size_t>(), topo.boundary_loops);
    // The scan has holes underneath, which the field leaves open and the default closes.
    EXPECT_EQ(report["fill_holes"].get<double>(), 0.05);
    EXPECT_GE(report["holes_filled"].get<std::size_t>(), 1U);
    EXPECT_GT(report["hole_vertices"].get<std::size_t>(), 0U);
    EXPECT_LT(report["hole_area_share"].get<double>(), 0.05);
    EXPECT_EQ(topo.boundary_loops, 0U);
    // Every sample lies within about a cell of the mesh.
    EXPECT_LT(report["hausdorff_samples_to_mesh"].get<double>(),
              2.0 * report["cell"].get<double>());
    EXPECT_GT(report["hausdorff_samples_to_mesh"].get<double>(), 0.0);
}

TEST(McCli, SurfelsWithoutRadiiAndEveryMeshFormat)
{
    test::TempDir dir;
    // A sampled sphere with exact normals but no radius property.
    ASSERT_EQ(run("sample sphere -n 5000 -o " + quoted(dir / "sphere.ply")).exit_code, 0);
    for (const std::string ext : {".ply", ".obj", ".off"})
    {
        const auto output = dir / ("sphere" + ext);
        const auto r = run("mc " + quoted(dir / "sphere.ply") + " -o " + quoted(output) +
                           " --resolution 40 --json");
        ASSERT_EQ(r.exit_code, 0) << r.out;
        const auto report = nlohmann::json::parse(r.out);
        EXPECT_FALSE(report["estimated_normals"].get<bool>());
        EXPECT_EQ(report["boundary_loops"].get<int>(), 0);
        EXPECT_EQ(report["euler_characteristic"].get<int>(), 2);
        const TriMesh mesh = read_mesh(output);
        EXPECT_EQ(mesh.face_count(), report["faces"].get<std::size_t>());
        for (std::size_t v = 0; v < mesh.vertex_count(); v += 17)
        {
            EXPECT_NEAR(mesh.vertices.world(v).norm(), 1.0, 0.05);
        }
    }
}

TEST(McCli, HolesInTheSamplesAreClosedUnlessAsked)
{
    test::TempDir dir;
    ASSERT_EQ(run("sample sphere -n 20000 --holes 3 --hole-radius 0.06 --seed 4 -o " +
                  quoted(dir / "holey.ply"))
                  .exit_code,
              0);
    const auto r = run("mc " + quoted(dir / "holey.ply") + " -o " + quoted(dir / "out.ply") +
                       " --reestimate --fill-holes 0 --json");
    ASSERT_EQ(r.exit_code, 0) << r.out;
    const auto report = nlohmann::json::parse(r.out);
    EXPECT_TRUE(report["estimated_normals"].get<bool>());
    EXPECT_EQ(report["holes_filled"].get<int>(), 0);
    // Three separate holes (they may overlap into fewer loops, never more).
    const int loops = report["boundary_loops"].get<int>();
    EXPECT_GE(loops, 1);
    EXPECT_LE(loops, 3);
    EXPECT_EQ(report["euler_characteristic"].get<int>(), 2 - loops);
    EXPECT_EQ(report["rim_reach"].get<double>(), 0.25);
    // The paper's field (a whole radius past the rims) reaches farther into the holes: more
    // surface, over the same samples.
    const auto paper = run("mc " + quoted(dir / "holey.ply") + " -o " + quoted(dir / "paper.ply") +
                           " --reestimate --rim-reach 1 --fill-holes 0 --json");
    ASSERT_EQ(paper.exit_code, 0) << paper.out;
    const auto paper_report = nlohmann::json::parse(paper.out);
    EXPECT_EQ(paper_report["rim_reach"].get<double>(), 1.0);
    EXPECT_GT(paper_report["faces"].get<double>(), report["faces"].get<double>());
    // By default the holes are closed with patches near the sphere, the zero set kept.
    const auto closed = run("mc " + quoted(dir / "holey.ply") + " -o " +
                            quoted(dir / "closed.ply") + " --reestimate --json");
    ASSERT_EQ(closed.exit_code, 0) << closed.out;
    const auto closed_report = nlohmann::json::parse(closed.out);
    EXPECT_EQ(closed_report["holes_filled"].get<int>(), loops);
    EXPECT_EQ(closed_report["boundary_loops"].get<int>(), 0);
    EXPECT_EQ(closed_report["euler_characteristic"].get<int>(), 2);
    EXPECT_EQ(
        closed_report["vertices"].get<std::size_t>(),
        report["vertices"].get<std::size_t>() + closed_report["hole_vertices"].get<std::size_t>());
    const TriMesh mesh = read_mesh(dir / "closed.ply");
    for (std::size_t v = 0; v < mesh.vertex_count(); ++v)
        ASSERT_NEAR(mesh.vertices.world(v).norm(), 1.0, 0.02) << v;
}

TEST(McCli, ShortHandlesAreCutUnlessAsked)
{
    // A noisy 45° cone: the fits of its base and side reach past the rim and meet as tunnels,
    // which mc cuts by default as reconstruct does, and keeps with --max-handle 0.
    test::TempDir dir;
    ASSERT_EQ(
        run("sample cone -n 20000 --noise 0.002 --seed 2 -o " + quoted(dir / "cone.ply")).exit_code,
        0);
    const auto kept = run("mc " + quoted(dir / "cone.ply") + " -o " + quoted(dir / "kept.ply") +
                          " --reestimate --max-handle 0 --json");
    ASSERT_EQ(kept.exit_code, 0) << kept.out;
    const auto kept_report = nlohmann::json::parse(kept.out);
    const auto cut = run("mc " + quoted(dir / "cone.ply") + " -o " + quoted(dir / "cut.ply") +
                         " --reestimate --json");
    ASSERT_EQ(cut.exit_code, 0) << cut.out;
    const auto cut_report = nlohmann::json::parse(cut.out);
    const auto genus = [](const nlohmann::json& r) {
        return (2 * r["components"].get<long long>() - r["euler_characteristic"].get<long long>() -
                r["boundary_loops"].get<long long>()) /
               2;
    };
    EXPECT_EQ(kept_report["handles"]["cuts"].get<int>(), 0);
    EXPECT_EQ(kept_report["max_handle"].get<double>(), 0.0);
    EXPECT_EQ(cut_report["max_handle"].get<double>(), pointform::default_max_handle);
    const auto handles = cut_report["handles"];
    EXPECT_EQ(handles["genus_before"], kept_report["handles"]["genus_before"]);
    ASSERT_GT(handles["genus_before"].get<long long>(), 3) << "no tunnels: the test tests nothing";
    EXPECT_GT(handles["cuts"].get<long long>(), handles["genus_before"].get<long long>() / 2);
    EXPECT_FALSE(handles["skipped_not_manifold"].get<bool>());
    EXPECT_LT(genus(cut_report), genus(kept_report));
    EXPECT_TRUE(cut_report["manifold"].get<bool>());
    // The human summary says so.
    const auto text =
        run("mc " + quoted(dir / "cone.ply") + " -o " + quoted(dir / "cut.ply") + " --reestimate");
    ASSERT_EQ(text.exit_code, 0) << text.out;
    EXPECT_NE(text.out.find("capped both sides"), std::string::npos) << text.out;
}

TEST(McCli, DebrisOfStraySamplesIsRemoved)
{
    // A sphere of 6,000 points and, far off, a flat cluster of 24 strays: the field makes a
    // small surface of its own around them, which no more than 24 samples are nearest to.
    test::TempDir dir;
    std::string ply;
    constexpr int sphere = 6000;
    constexpr int strays = 24;
    ply = "ply\nformat ascii 1.0\nelement vertex " + std::to_string(sphere + strays) +
          "\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
    const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
    for (int i = 0; i < sphere; ++i)
    {
        const double z = 1.0 - 2.0 * (i + 0.5) / sphere;
        const double rho = std::sqrt(1.0 - z * z);
        ply += std::to_string(rho * std::cos(golden * i)) + " " +
               std::to_string(rho * std::sin(golden * i)) + " " + std::to_string(z) + "\n";
    }
    for (int i = 0; i < strays; ++i)
    {
        const double rho = 0.08 * std::sqrt((i + 0.5) / strays);
        ply += std::to_string(3.0 + rho * std::cos(golden * i)) + " " +
               std::to_string(rho * std::sin(golden * i)) + " 0\n";
    }
    test::write_file(dir / "strays.ply", ply);
    const auto kept = run("mc " + quoted(dir / "strays.ply") + " -o " + quoted(dir / "kept.ply") +
                          " --min-component-samples 0 --json");
    ASSERT_EQ(kept.exit_code, 0) << kept.out;
    const auto kept_report = nlohmann::json::parse(kept.out);
    EXPECT_EQ(kept_report["components_removed"].get<int>(), 0);
    EXPECT_EQ(kept_report["components"].get<int>(), 2);

    const auto r =
        run("mc " + quoted(dir / "strays.ply") + " -o " + quoted(dir / "out.ply") + " --json");
    ASSERT_EQ(r.exit_code, 0) << r.out;
    const auto report = nlohmann::json::parse(r.out);
    EXPECT_EQ(report["min_component_samples"].get<int>(), 32);
    EXPECT_EQ(report["components_removed"].get<int>(), 1);
    EXPECT_GT(report["faces_removed"].get<int>(), 0);
    EXPECT_EQ(report["components"].get<int>(), 1);
    EXPECT_EQ(report["boundary_loops"].get<int>(), 0);
    const TriMesh mesh = read_mesh(dir / "out.ply");
    for (std::size_t v = 0; v < mesh.vertex_count(); ++v)
        ASSERT_NEAR(mesh.vertices.world(v).norm(), 1.0, 0.02) << v;
}

TEST(McCli, ASpongeIsMadeAgainAtTheNoisesScale)
{
    // A plate 0.06 thick under noise of 0.0063 of the diagonal (2 sampling steps at 100k): its
    // faces merge into one slab and its field's fits, narrower than the slab, make a sponge. As
    // reconstruct does, mc makes the field again with its fits at the noise's scale (one sheet);
    // a noisy sphere's field stays as it was.
    test::TempDir dir;
    ASSERT_EQ(
        run("sample plate --thickness 0.06 --noise 0.0063 -n 100000 -o " + quoted(dir / "slab.ply"))
            .exit_code,
        0);
    const auto r = run("mc " + quoted(dir / "slab.ply") + " -o " + quoted(dir / "slab_mc.ply") +
                       " --reestimate --json");
    ASSERT_EQ(r.exit_code, 0) << r.out;
    const auto report = nlohmann::json::parse(r.out);
    EXPECT_TRUE(report["field_noise_scale"]["refitted"].get<bool>());
    EXPECT_GE(report["field_noise_scale"]["sponge_genus"].get<std::size_t>(), 64U);
    EXPECT_GT(report["field_noise_scale"]["cells"].get<std::size_t>(), 0U);
    const MeshTopology topo = analyze_topology(read_mesh(dir / "slab_mc.ply"));
    // Handles left: at most a few (the sponge had over a thousand).
    const std::int64_t twice_genus = 2 * static_cast<std::int64_t>(topo.components) -
                                     topo.euler_characteristic -
                                     static_cast<std::int64_t>(topo.boundary_loops);
    EXPECT_LE(twice_genus, 4);

    ASSERT_EQ(
        run("sample sphere --noise 0.002 -n 30000 -o " + quoted(dir / "sphere.ply")).exit_code, 0);
    const auto sphere = run("mc " + quoted(dir / "sphere.ply") + " -o " +
                            quoted(dir / "sphere_mc.ply") + " --reestimate --json");
    ASSERT_EQ(sphere.exit_code, 0) << sphere.out;
    EXPECT_FALSE(nlohmann::json::parse(sphere.out)["field_noise_scale"]["refitted"].get<bool>());
}

TEST(McCli, BadOptionsAndInputsFailCleanly)
{
    test::TempDir dir;
    const auto output = dir / "out.ply";
    const std::string bunny = quoted(test::data_path("bunny/bun_zipper.ply"));
    struct Case
    {
        std::string arguments;
        std::string message;
    };
    std::vector<Case> cases = {
        {"mc " + quoted(dir / "missing.ply") + " -o " + quoted(output), "missing.ply"},
        {"mc " + bunny + " -o " + quoted(output) + " --cell -1", "--cell"},
        {"mc " + bunny + " -o " + quoted(output) + " --cell 0.01 --resolution 10", "excludes"},
        {"mc " + bunny + " -o " + quoted(output) + " --fit smooth", "--fit"},
        {"mc " + bunny + " -o " + quoted(output) + " --rim-reach 0", "--rim-reach"},
        {"mc " + bunny + " -o " + quoted(output) + " --rim-reach 1.5", "--rim-reach"},
        {"mc " + bunny + " -o " + quoted(output) + " --fill-holes 1", "--fill-holes"},
        {"mc " + bunny + " -o " + quoted(output) + " --fill-holes -0.1", "--fill-holes"},
        {"mc " + bunny + " -o " + quoted(output) + " --max-handle -1", "--max-handle"},
        {"mc " + bunny + " -o " + quoted(output) + " --max-handle 65", "--max-handle"},
        {"mc " + bunny + " -o " + quoted(output) + " --min-component-samples -1",
         "--min-component-samples"},
        {"mc " + bunny + " -o " + quoted(output) + " --cell 1e-9", "cells along an axis"},
    };
    // Surfels whose normals are all zero.
    std::string zero_normals =
        "ply\nformat ascii 1.0\nelement vertex 40\nproperty float x\n"
        "property float y\nproperty float z\nproperty float nx\n"
        "property float ny\nproperty float nz\nend_header\n";
    for (int i = 0; i < 40; ++i)
    {
        zero_normals += std::to_string(std::cos(i)) + " " + std::to_string(std::sin(i)) + " " +
                        std::to_string(0.1 * i) + " 0 0 0\n";
    }
    test::write_file(dir / "zero_normals.ply", zero_normals);
    cases.push_back({"mc " + quoted(dir / "zero_normals.ply") + " -o " + quoted(output),
                     "zero or non-finite normal"});
    // A mesh whose face points past its vertices.
    test::write_file(dir / "bad_index.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n");
    cases.push_back(
        {"mc " + quoted(dir / "bad_index.off") + " -o " + quoted(output), "bad_index.off"});
    cases.push_back({"mc " + bunny + " -o " + quoted(output) + " --resolution 0", "--resolution"});
    // Far more cells than memory: refused before anything is allocated.
    cases.push_back({"mc " + bunny + " -o " + quoted(output) + " --resolution 200000", "GiB"});
    for (const Case& c : cases)
    {
        const auto r = run(c.arguments);
        EXPECT_NE(r.exit_code, 0) << c.arguments;
        EXPECT_NE(r.out.find(c.message), std::string::npos) << c.arguments << ": " << r.out;
        EXPECT_FALSE(std::filesystem::exists(output)) << c.arguments;
    }
}

} // namespace
} // namespace pointform
