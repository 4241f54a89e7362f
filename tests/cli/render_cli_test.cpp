// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// `pointform render` end to end: PNGs of the shipped mesh and scans, option errors.

#include "pointform/io/io.h"
#include "pointform/render/render.h"

#include "cli_run.h"
#include "support/test_support.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>

namespace pointform {
namespace {

using test::quoted;
using test::run;
using test::RunResult;

/// Width and height from a PNG's IHDR chunk; {0, 0} if the file is not a PNG.
std::pair<unsigned, unsigned> png_size(const std::string& bytes)
{
    if (bytes.size() < 24 || bytes.substr(0, 8) != std::string("\x89PNG\r\n\x1a\n", 8) ||
        bytes.substr(12, 4) != "IHDR")
        return {0, 0};
    const auto be32 = [&](std::size_t at) {
        unsigned v = 0;
        for (std::size_t i = 0; i < 4; ++i)
            v = (v << 8U) | static_cast<unsigned char>(bytes[at + i]);
        return v;
    };
    return {be32(16), be32(20)};
}

std::size_t file_count(const std::filesystem::path& dir)
{
    std::size_t files = 0;
    for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator(dir))
        ++files;
    return files;
}

TEST(RenderCli, MeshWithWireframe)
{
    test::TempDir dir;
    const auto input = test::data_path("meshes/bunny_uniform.off");
    const auto out = dir / "bunny.png";
    const RunResult r = run("render " + quoted(input) + " -o " + quoted(out) +
                            " --size 240,180 --wireframe --json");
    ASSERT_EQ(r.exit_code, 0) << r.out;
    const auto report = nlohmann::json::parse(r.out);
    EXPECT_EQ(report["drawn_as"], "mesh");
    EXPECT_EQ(report["faces"], read_mesh(input).face_count());
    EXPECT_EQ(png_size(test::read_file(out)), std::make_pair(240U, 180U));
    EXPECT_EQ(file_count(dir.path()), 1U); // no temporary file left
}

TEST(RenderCli, SameImageAsTheLibrary)
{
    // The command passes its options through: its PNG is byte for byte the library's.
    test::TempDir dir;
    const auto input = test::data_path("bunny/bun_zipper.ply");
    const auto out = dir / "zipper.png";
    const RunResult r = run("render " + quoted(input) + " -o " + quoted(out) +
                            " --size 200,150 --view 45,10 --ortho");
    ASSERT_EQ(r.exit_code, 0) << r.out;
    const Image image = render_mesh(read_mesh(input), {.width = 200,
                                                       .height = 150,
                                                       .azimuth = 45,
                                                       .elevation = 10,
                                                       .projection = Projection::Orthographic});
    const std::vector<std::uint8_t> png = encode_png(image);
    EXPECT_EQ(test::read_file(out), std::string(png.begin(), png.end()));
}

TEST(RenderCli, PointsOfAScanAndOfAMesh)
{
    test::TempDir dir;
    const auto scan = dir / "scan.png";
    RunResult r = run("render " + quoted(test::data_path("bunny/bun_zipper_res4.ply")) + " -o " +
                      quoted(scan) + " --size 160,120 --points --json");
    ASSERT_EQ(r.exit_code, 0) << r.out;
    EXPECT_EQ(nlohmann::json::parse(r.out)["drawn_as"], "points");
    EXPECT_EQ(png_size(test::read_file(scan)), std::make_pair(160U, 120U));

    // A point set (no faces) is drawn as points; normals estimated, or flat with --flat.
    const auto cloud = dir / "cloud.png";
    r = run("render " + quoted(test::data_path("cgal/kitten.xyz")) + " -o " + quoted(cloud) +
            " --size 160,120 --up z --json");
    ASSERT_EQ(r.exit_code, 0) << r.out;
    EXPECT_EQ(nlohmann::json::parse(r.out)["drawn_as"], "points");
    EXPECT_EQ(png_size(test::read_file(cloud)), std::make_pair(160U, 120U));
    const auto flat = dir / "flat.png";
    r = run("render " + quoted(test::data_path("cgal/kitten.xyz")) + " -o " + quoted(flat) +
            " --size 160,120 --flat -q");
    ASSERT_EQ(r.exit_code, 0) << r.out;
    EXPECT_TRUE(r.out.empty()) << r.out;
    EXPECT_NE(test::read_file(flat), test::read_file(cloud));
}

TEST(RenderCli, SameImageWhateverTheThreadCount)
{
    test::TempDir dir;
    const std::string input = quoted(test::data_path("meshes/bunny_uniform.off"));
    ASSERT_EQ(run("-j 1 render " + input + " -o " + quoted(dir / "one.png") +
                  " --size 160,120 --wireframe")
                  .exit_code,
              0);
    ASSERT_EQ(run("-j 2 render " + input + " -o " + quoted(dir / "two.png") +
                  " --size 160,120 --wireframe")
                  .exit_code,
              0);
    EXPECT_EQ(test::read_file(dir / "one.png"), test::read_file(dir / "two.png"));
}

TEST(RenderCli, BadOptionsAndInputFailCleanly)
{
    test::TempDir dir;
    const std::string mesh = quoted(test::data_path("meshes/bunny_uniform.off"));
    const auto out = dir / "out.png";
    struct Case
    {
        std::string arguments;
        std::string message;
    };
    const std::vector<Case> usage_errors = {
        {"--size 0,10", "--size"},
        {"--size 640", "--size"},
        {"--size a,b", "--size"},
        {"--size 10.5,3", "--size"},
        {"--size 20000,10", "--size"},
        {"--size 640,480,3", "--size"},
        {"--view 30", "--view"},
        {"--view 30,95", "elevation"},
        {"--up w", "--up"},
        {"--up 0,0,0", "--up"},
        {"--supersampling 0", "supersampling"},
    };
    for (const Case& c : usage_errors)
    {
        const RunResult r = run("render " + mesh + " -o " + quoted(out) + " " + c.arguments);
        EXPECT_NE(r.exit_code, 0) << c.arguments;
        EXPECT_NE(r.out.find(c.message), std::string::npos) << c.arguments << ": " << r.out;
        EXPECT_FALSE(std::filesystem::exists(out)) << c.arguments;
    }
    RunResult r = run("render " + mesh + " -o " + quoted(dir / "out.jpg"));
    EXPECT_NE(r.exit_code, 0);
    EXPECT_NE(r.out.find(".png"), std::string::npos) << r.out;

    // Missing, empty and broken files: file errors (3).
    r = run("render " + quoted(dir / "missing.off") + " -o " + quoted(out));
    EXPECT_EQ(r.exit_code, 3) << r.out;
    test::write_file(dir / "empty.xyz", "");
    r = run("render " + quoted(dir / "empty.xyz") + " -o " + quoted(out));
    EXPECT_EQ(r.exit_code, 3) << r.out;
    test::write_file(dir / "bad.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n");
    r = run("render " + quoted(dir / "bad.off") + " -o " + quoted(out));
    EXPECT_EQ(r.exit_code, 3) << r.out;
    EXPECT_FALSE(std::filesystem::exists(out));

    // An unwritable output: file error.
    r = run("render " + mesh + " -o /nonexistent-dir/out.png --size 32,24");
    EXPECT_EQ(r.exit_code, 3) << r.out;
}

} // namespace
} // namespace pointform
