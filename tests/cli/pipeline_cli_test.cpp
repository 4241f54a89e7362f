// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// The library's pipeline (polygonize/reconstruct.h) and the command line make the same thing:
// `pointform reconstruct` and `pointform remesh` write, byte for byte, the mesh and hierarchy
// that reconstruct() and remesh() return, and report the same figures; `pointform normals` the
// surfels of compute_surfels().

#include "pointform/geometry/shapes.h"
#include "pointform/hermite/surfels.h"
#include "pointform/io/hierarchy.h"
#include "pointform/io/io.h"
#include "pointform/polygonize/reconstruct.h"

#include "cli_run.h"
#include "support/test_support.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

namespace pointform {
namespace {

using test::quoted;
using test::run;

std::string bytes_of(const std::filesystem::path& path)
{
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// The figures of the JSON report that the library's report must match exactly.
void expect_same_report(const nlohmann::json& json, const SemiRegularReport& report)
{
    const MultiresMesh& hierarchy = report.hierarchy;
    EXPECT_EQ(json["finest_level"].get<std::size_t>(), hierarchy.finest_level());
    EXPECT_EQ(json["faces"].get<std::size_t>(), hierarchy.face_count(hierarchy.finest_level()));
    EXPECT_EQ(json["vertices"].get<std::size_t>(), hierarchy.vertex_count());
    EXPECT_EQ(json["samples"].get<std::size_t>(), report.sample_count);
    EXPECT_EQ(json["sampling_density"].get<double>(), report.refinement.sampling_density);
    EXPECT_EQ(json["level_cap"].get<std::size_t>(), report.level_cap);
    const auto& levels = json["levels"];
    ASSERT_EQ(levels.size(), report.refinement.levels.size() + 1);
    EXPECT_EQ(levels[0]["hausdorff"].get<double>(), report.refinement.initial_hausdorff);
    for (std::size_t l = 0; l < report.refinement.levels.size(); ++l)
    {
        const RefineLevelStats& stats = report.refinement.levels[l];
        EXPECT_EQ(levels[l + 1]["faces"].get<std::size_t>(), stats.faces);
        EXPECT_EQ(levels[l + 1]["hausdorff"].get<double>(), *stats.hausdorff);
        EXPECT_EQ(levels[l + 1]["robust_distance"].get<double>(), *stats.robust_distance);
        EXPECT_EQ(levels[l + 1]["unprojected"].get<std::size_t>(), stats.unprojected);
    }
}

TEST(PipelineCli, ReconstructWritesTheLibrarysMeshAndHierarchyByteForByte)
{
    test::TempDir dir;
    const auto input = test::data_path("bunny/bun_zipper.ply");
    const auto cli_mesh = dir / "cli.ply";
    const auto cli_hierarchy = dir / "cli.pfh";
    const auto r = run("reconstruct " + quoted(input) + " -o " + quoted(cli_mesh) +
                       " --save-hierarchy " + quoted(cli_hierarchy) + " --json");
    ASSERT_EQ(r.exit_code, 0) << r.out;
    const auto json = nlohmann::json::parse(r.out);

    // The same through the public headers, at the library's defaults.
    SurfelsFromSamples surfels = surfels_from_samples(read_point_cloud(input));
    EXPECT_TRUE(surfels.estimated_normals);
    const ReconstructReport report = reconstruct(std::move(surfels.surfels));
    const MultiresMesh& hierarchy = report.semi_regular.hierarchy;
    const auto lib_mesh = dir / "lib.ply";
    const auto lib_hierarchy = dir / "lib.pfh";
    write_mesh(lib_mesh, hierarchy.level_mesh(hierarchy.finest_level()));
    write_hierarchy(lib_hierarchy, hierarchy);

    EXPECT_GE(hierarchy.level_count(), 2U);
    EXPECT_EQ(bytes_of(cli_mesh), bytes_of(lib_mesh));
    EXPECT_EQ(bytes_of(cli_hierarchy), bytes_of(lib_hierarchy));
    expect_same_report(json, report.semi_regular);
    EXPECT_EQ(json["intermediate_faces"].get<std::size_t>(), report.intermediate_faces);
    EXPECT_EQ(json["cell"].get<double>(), report.cell);
    EXPECT_EQ(json["stop"].get<std::string>(), to_string(report.semi_regular.refinement.stop));
}

// A noisy cloud, whose orientation grows guide normals in the handed cloud's position array,
// through the executable's allocation (huge pages for its blocks of 4 MiB and more, as the
// neighbour table of 80,000 samples is: large_pages.cpp) and through the test's.
TEST(PipelineCli, NormalsWritesTheLibrarysSurfelsByteForByte)
{
    test::TempDir dir;
    const auto input = dir / "noisy.ply";
    PointCloud cloud = sample_shape(Shape::Torus, {.count = 80000, .seed = 9, .noise = 0.011});
    cloud.normals.clear();
    write_point_cloud(input, cloud);
    const auto cli_surfels = dir / "cli.ply";
    const auto r = run("normals " + quoted(input) + " -o " + quoted(cli_surfels) + " --json");
    ASSERT_EQ(r.exit_code, 0) << r.out;
    const auto json = nlohmann::json::parse(r.out);

    const SurfelResult result = compute_surfels(read_point_cloud(input));
    const auto lib_surfels = dir / "lib.ply";
    write_point_cloud(lib_surfels, result.surfels);
    EXPECT_EQ(bytes_of(cli_surfels), bytes_of(lib_surfels));
    EXPECT_EQ(json["points"].get<std::size_t>(), result.surfels.size());
    EXPECT_EQ(json["flipped"].get<std::size_t>(), result.orientation.flipped);
    EXPECT_EQ(json["components"].get<std::size_t>(), result.orientation.components);
}

TEST(PipelineCli, RemeshWritesTheLibrarysMeshByteForByte)
{
    test::TempDir dir;
    const auto input = test::data_path("meshes/bunny_uniform.off");
    const auto cli_mesh = dir / "cli.ply";
    const auto r = run("remesh " + quoted(input) + " -o " + quoted(cli_mesh) +
                       " --levels 2 --predictor butterfly --samples 6000 --seed 7 --json");
    ASSERT_EQ(r.exit_code, 0) << r.out;
    const auto json = nlohmann::json::parse(r.out);

    RemeshOptions options;
    options.semi_regular.levels = 2;
    options.semi_regular.predictor = Predictor::Butterfly;
    options.surfels.samples = 6000;
    options.surfels.seed = 7;
    const RemeshReport report = remesh(read_mesh(input), options);
    const MultiresMesh& hierarchy = report.semi_regular.hierarchy;
    const auto lib_mesh = dir / "lib.ply";
    write_mesh(lib_mesh, hierarchy.level_mesh(hierarchy.finest_level()));

    EXPECT_EQ(hierarchy.finest_level(), 2U);
    EXPECT_EQ(bytes_of(cli_mesh), bytes_of(lib_mesh));
    expect_same_report(json, report.semi_regular);
    EXPECT_EQ(json["area_samples"].get<std::size_t>(), report.area_surfels);
    EXPECT_EQ(report.area_surfels, 6000U);
    EXPECT_EQ(json["stop"].get<std::string>(), "levels");
}

} // namespace
} // namespace pointform
