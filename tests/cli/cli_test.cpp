// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// The command-line tool end to end: exit codes, messages and outputs, on good and bad input.

#include "pointform/io/io.h"

#include "cli_run.h"
#include "support/test_support.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

namespace pointform {
namespace {

using test::quoted;
using test::run;
using test::RunResult;

TEST(Cli, HelpOnEverySubcommand)
{
    for (const std::string sub : {"", "info", "normals", "sample", "mc", "distance", "render"})
    {
        const RunResult r = run(sub + " --help");
        EXPECT_EQ(r.exit_code, 0) << sub;
        EXPECT_NE(r.out.find("Usage"), std::string::npos) << sub;
    }
}

TEST(Cli, NormalsOnBunnyWritesSurfels)
{
    test::TempDir dir;
    const auto out = dir / "bunny.ply";
    const RunResult r = run("normals " + quoted(test::data_path("bunny/bun_zipper.ply")) + " -o " +
                            quoted(out) + " -k 12 --radius-scale 2 --json");
    ASSERT_EQ(r.exit_code, 0) << r.out;
    const auto report = nlohmann::json::parse(r.out);
    EXPECT_EQ(report["points"], 35947);
    EXPECT_EQ(report["unoriented"], 0);
    EXPECT_TRUE(report["timings_s"].contains("orientation"));

    const PointCloud surfels = read_point_cloud(out);
    ASSERT_EQ(surfels.size(), 35947U);
    ASSERT_TRUE(surfels.has_normals());
    ASSERT_TRUE(surfels.has_radii());
    for (std::size_t i = 0; i < surfels.size(); ++i)
    {
        EXPECT_NEAR(surfels.normals[i].norm(), 1.0F, 1e-4F);
        EXPECT_GT(surfels.radii[i], 0.0F);
    }
    // The header says what the issue promises: binary PLY with x y z nx ny nz and radius.
    const std::string head = test::read_file(out).substr(0, 400);
    EXPECT_NE(head.find("format binary_little_endian"), std::string::npos);
    EXPECT_NE(head.find("property float radius"), std::string::npos);
}

TEST(Cli, OrientTowardsAndRegions)
{
    test::TempDir dir;
    test::write_file(dir / "regions.json",
                     R"({"regions": [{"box": {"min": [-1,-1,-1], "max": [1,1,1]}, "set": 0.25}]})");
    const auto out = dir / "s.ply";
    const RunResult r =
        run("normals " + quoted(test::data_path("pcl/bunny.pcd")) + " -o " + quoted(out) +
            " --orient towards:0,0,1 --radius-regions " + quoted(dir / "regions.json"));
    ASSERT_EQ(r.exit_code, 0) << r.out;
    const PointCloud surfels = read_point_cloud(out);
    for (std::size_t i = 0; i < surfels.size(); ++i)
    {
        const Vec3d to_view = Vec3d(0, 0, 1) - surfels.world(i);
        EXPECT_GE(surfels.normals[i].cast<double>().dot(to_view), 0.0);
        EXPECT_EQ(surfels.radii[i], 0.25F);
    }
}

TEST(Cli, SameOutputWhateverTheThreadCount)
{
    test::TempDir dir;
    const std::string input = quoted(test::data_path("bunny/bun000.ply"));
    ASSERT_EQ(run("-j 1 normals " + input + " -o " + quoted(dir / "one.ply")).exit_code, 0);
    ASSERT_EQ(run("-j 2 normals " + input + " -o " + quoted(dir / "two.ply")).exit_code, 0);
    ASSERT_EQ(run("-j 3 normals " + input + " -o " + quoted(dir / "three.ply")).exit_code, 0);
    const std::string one = test::read_file(dir / "one.ply");
    EXPECT_FALSE(one.empty());
    EXPECT_EQ(one, test::read_file(dir / "two.ply"));
    EXPECT_EQ(one, test::read_file(dir / "three.ply"));
}

/// The coordinates a LAS 1.0–1.3 file stores, as the format defines them (int32 X · scale +
/// offset, in double), decoded here from the raw header and records.
std::vector<Vec3d> las_coordinates(const std::filesystem::path& path)
{
    const std::string bytes = test::read_file(path);
    const auto load = [&bytes](std::size_t at, auto value) {
        std::memcpy(&value, bytes.data() + at, sizeof(value));
        return value;
    };
    const auto data = load(96, std::uint32_t{});
    const auto record = load(105, std::uint16_t{});
    const auto count = load(107, std::uint32_t{});
    std::vector<Vec3d> out;
    for (std::size_t i = 0; i < count; ++i)
    {
        Vec3d p;
        for (std::size_t k = 0; k < 3; ++k)
            p[static_cast<int>(k)] =
                static_cast<double>(load(data + i * record + 4 * k, std::int32_t{})) *
                    load(131 + 8 * k, double{}) +
                load(155 + 8 * k, double{});
        out.push_back(p);
    }
    return out;
}

TEST(Cli, GeoreferencedLidarKeepsItsCoordinates)
{
    test::TempDir dir;
    const auto out = dir / "lidar.ply";
    const auto input = test::data_path("lidar/4_6_crop.las");
    const RunResult r =
        run("normals " + quoted(input) + " -o " + quoted(out) + " --orient along:0,0,1");
    ASSERT_EQ(r.exit_code, 0) << r.out;
    // Compared with the file's own values (not with another read of it, which would round the
    // same way): coordinates near 1.6e6 m with centimetre detail, where float alone would round
    // to 0.125 m. The output keeps each within half a float ulp of its offset from the origin.
    const std::vector<Vec3d> expected = las_coordinates(input);
    const PointCloud surfels = read_point_cloud(out);
    ASSERT_EQ(surfels.size(), expected.size());
    ASSERT_GT(surfels.origin.cwiseAbs().maxCoeff(), 1e6);
    for (std::size_t i = 0; i < expected.size(); ++i)
        for (int k = 0; k < 3; ++k)
        {
            const auto offset = static_cast<float>(std::abs(expected[i][k] - surfels.origin[k]));
            const double bound = 0.5 * static_cast<double>(std::nextafter(offset, 1e30F) - offset) +
                                 1e-8; // + the double rounding of the sums at 1.6e6
            ASSERT_NEAR(surfels.world(i)[k], expected[i][k], bound)
                << "point " << i << " axis " << k;
        }
    // Airborne LiDAR: normals turned to the sky, as asked.
    for (const auto& n : surfels.normals)
        EXPECT_GE(n.z(), 0.0F);
}

TEST(Cli, InfoReportsDensityAndAttributes)
{
    const RunResult r = run("info --json " + quoted(test::data_path("cgal/kitten.xyz")));
    ASSERT_EQ(r.exit_code, 0) << r.out;
    const auto info = nlohmann::json::parse(r.out);
    EXPECT_EQ(info["points"], 5210);
    EXPECT_GT(info["nearest_neighbor_distance"]["median"].get<double>(), 0.0);
    const auto& attributes = info["attributes"];
    EXPECT_NE(std::find(attributes.begin(), attributes.end(), "normals"), attributes.end());
}

/// Every bad input: a clear message naming the problem, a non-zero exit, no output file.
struct BadCase
{
    std::string name;
    std::string content; ///< written to the input file; empty name = missing file
    std::string extension;
    std::string extra_arguments;
    int exit_code;
    std::string message;
};

TEST(Cli, BadInputFailsCleanly)
{
    const std::string ply_header =
        "ply\nformat binary_little_endian 1.0\nelement vertex 100\n"
        "property float x\nproperty float y\nproperty float z\n"
        "end_header\n";
    std::string line_points;
    for (int i = 0; i < 50; ++i)
        line_points +=
            std::to_string(i) + " " + std::to_string(2 * i) + " " + std::to_string(3 * i) + "\n";
    std::string same_points;
    for (int i = 0; i < 50; ++i)
        same_points += "1 2 3\n";
    const std::vector<BadCase> cases = {
        {"missing", "", ".ply", "", 3, "missing.ply"},
        {"empty", "\x01", ".xyz", "", 3, "empty.xyz"},
        {"truncated", ply_header + std::string(12 * 40, '\0'), ".ply", "", 3, "truncated.ply"},
        {"nan", "0 0 0\n1 0 0\nnan 1 0\n0 1 1\n", ".xyz", "", 3, "nan.xyz:3"},
        {"inf", "0 0 0\n1 0 inf\n", ".xyz", "", 3, "inf.xyz:2"},
        {"few", "0 0 0\n1 0 0\n0 1 0\n1 1 1\n", ".xyz", "", 2, "fewer than k"},
        {"coincident", same_points, ".xyz", "", 2, "coincide"},
        {"collinear", line_points, ".xyz", "", 2, "line"},
        {"badorient", line_points, ".xyz", "--orient sideways", 105, "sideways"},
    };
    for (const auto& c : cases)
    {
        test::TempDir dir;
        const auto input = dir / (c.name + c.extension);
        if (c.name != "missing")
            test::write_file(input, c.content == "\x01" ? std::string() : c.content);
        const auto output = dir / "out.ply";
        const RunResult r =
            run("normals " + quoted(input) + " -o " + quoted(output) + " " + c.extra_arguments);
        EXPECT_NE(r.exit_code, 0) << c.name;
        if (c.exit_code != 105)
        {
            EXPECT_EQ(r.exit_code, c.exit_code) << c.name << ": " << r.out;
        }
        EXPECT_NE(r.out.find(c.message), std::string::npos) << c.name << ": " << r.out;
        EXPECT_FALSE(std::filesystem::exists(output)) << c.name;
        // Nothing else is left behind either (no temporary files).
        std::size_t files = 0;
        for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator(dir.path()))
            ++files;
        EXPECT_EQ(files, c.name == "missing" ? 0U : 1U) << c.name;
    }
}

TEST(Cli, UnwritableOutputFailsWithFileError)
{
    const RunResult r =
        run("normals " + quoted(test::data_path("pcl/bunny.pcd")) + " -o /nonexistent-dir/out.ply");
    EXPECT_EQ(r.exit_code, 3) << r.out;
    EXPECT_NE(r.out.find("/nonexistent-dir/out.ply"), std::string::npos) << r.out;
}

} // namespace
} // namespace pointform
