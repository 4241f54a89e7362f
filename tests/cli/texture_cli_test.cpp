// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// `pointform texture`: a checker, an image or a coloured scan through the parameterization,
// written as a textured glTF with every level or an OBJ + MTL + PNG; bad input exits 2 or 3
// and writes nothing.

#include "pointform/io/hierarchy.h"
#include "pointform/io/io.h"
#include "pointform/io/png.h"

#include "cli_run.h"
#include "multires/multires_fixtures.h"
#include "support/test_support.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <string>

namespace pointform {
namespace {

using test::file_count;
using test::quoted;
using test::run;

class TextureCli : public ::testing::Test
{
protected:
    void SetUp() override
    {
        mesh_ = test::relief_sphere(3);
        input_ = dir_ / "in.pfh";
        write_hierarchy(input_, mesh_);
    }

    test::TempDir dir_;
    MultiresMesh mesh_;
    std::filesystem::path input_;
};

TEST_F(TextureCli, CheckerAsATexturedLevelOfDetailChain)
{
    const auto out = dir_ / "checker.glb";
    const auto r = run("texture " + quoted(input_) + " -o " + quoted(out) + " --json");
    ASSERT_EQ(r.exit_code, 0) << r.out;
    const auto report = nlohmann::json::parse(r.out);
    EXPECT_EQ(report["source"], "checker");
    EXPECT_EQ(report["level"].get<std::size_t>(), 3U);
    ASSERT_EQ(report["levels"].size(), 4U);
    for (const auto& level : report["levels"])
    {
        EXPECT_EQ(level["flipped"].get<std::size_t>(), 0U);
        EXPECT_GE(level["l2_stretch"].get<double>(), 1.0 - 1e-9);
        EXPECT_LT(level["l2_stretch"].get<double>(), 1.5);
    }
    EXPECT_EQ(report["levels"][3]["faces"].get<std::size_t>(), mesh_.face_count(3));
    EXPECT_GT(report["atlas"]["texel_usage"].get<double>(), 0.2);
    EXPECT_FALSE(report["normal_map"].get<bool>());
    const std::string bytes = test::read_file(out);
    ASSERT_GE(bytes.size(), 12U);
    EXPECT_EQ(bytes.substr(0, 4), "glTF");
}

TEST_F(TextureCli, ObjWithANormalMapOfACoarseLevel)
{
    const auto out = dir_ / "light.obj";
    const auto r = run("texture " + quoted(input_) + " -o " + quoted(out) +
                       " --normal-map-level 1 --size 256 --json");
    ASSERT_EQ(r.exit_code, 0) << r.out;
    const auto report = nlohmann::json::parse(r.out);
    EXPECT_TRUE(report["normal_map"].get<bool>());
    ASSERT_EQ(report["levels"].size(), 1U);
    EXPECT_EQ(report["levels"][0]["level"].get<std::size_t>(), 1U);
    EXPECT_EQ(report["atlas"]["size"].get<int>(), 256);
    for (const char* name : {"light.obj", "light.mtl", "light_color.png", "light_normal.png"})
        EXPECT_TRUE(std::filesystem::exists(dir_ / name)) << name;
    const TextureImage normal = read_png(dir_ / "light_normal.png");
    EXPECT_EQ(normal.width, 256);
    const std::string obj = test::read_file(out);
    EXPECT_NE(obj.find("mtllib light.mtl"), std::string::npos);
    EXPECT_NE(obj.find("\nvt "), std::string::npos);
}

TEST_F(TextureCli, ColoursOfAScanAreBakedBack)
{
    // Samples on the bumpy sphere with a colour that varies smoothly over space.
    PointCloud scan;
    const std::vector<Triangle> faces = mesh_.faces(3);
    for (const Triangle& t : faces)
    {
        const Vec3d c = (mesh_.world(t[0]) + mesh_.world(t[1]) + mesh_.world(t[2])) / 3.0;
        scan.positions.push_back(c.cast<float>());
        scan.colors.push_back({static_cast<std::uint8_t>(std::lround(127.5 + 120.0 * c.x())),
                               static_cast<std::uint8_t>(std::lround(127.5 + 120.0 * c.y())),
                               static_cast<std::uint8_t>(std::lround(127.5 + 120.0 * c.z()))});
    }
    write_point_cloud(dir_ / "scan.ply", scan);
    const auto r = run("texture " + quoted(input_) + " -o " + quoted(dir_ / "baked.glb") +
                       " --bake-colors " + quoted(dir_ / "scan.ply") + " --json");
    ASSERT_EQ(r.exit_code, 0) << r.out;
    const auto report = nlohmann::json::parse(r.out);
    EXPECT_EQ(report["source"], "bake-colors");
    EXPECT_LT(report["bake"]["rms_color_error"].get<double>(), 6.0);
    EXPECT_GT(report["bake"]["texels"].get<std::size_t>(), 0U);

    // The same scan without colours: exit 2, nothing written.
    scan.colors.clear();
    write_point_cloud(dir_ / "grey.ply", scan);
    const auto grey = run("texture " + quoted(input_) + " -o " + quoted(dir_ / "grey.glb") +
                          " --bake-colors " + quoted(dir_ / "grey.ply"));
    EXPECT_EQ(grey.exit_code, 2) << grey.out;
    EXPECT_NE(grey.out.find("no colours"), std::string::npos) << grey.out;
    EXPECT_FALSE(std::filesystem::exists(dir_ / "grey.glb"));
}

TEST_F(TextureCli, AnImageBecomesTheAtlas)
{
    TextureImage image;
    image.width = 4;
    image.height = 4;
    image.pixels.assign(4 * 4 * 3, 200);
    write_png(dir_ / "paint.png", image);
    const auto r = run("texture " + quoted(input_) + " -o " + quoted(dir_ / "painted.obj") +
                       " --image " + quoted(dir_ / "paint.png") + " --size 64 --level 2");
    ASSERT_EQ(r.exit_code, 0) << r.out;
    const TextureImage atlas = read_png(dir_ / "painted_color.png");
    EXPECT_EQ(atlas.width, 64);
    EXPECT_EQ(atlas.pixels[0], 200);
}

TEST_F(TextureCli, BadInputExitsTwoOrThreeAndWritesNothing)
{
    const auto out = dir_ / "out.glb";
    test::write_file(out, "precious");
    test::write_file(dir_ / "not.png", "this is not a PNG");
    std::string png = test::read_file(test::data_path("../docs/images/bunny_mc_wireframe.png"));
    test::write_file(dir_ / "cut.png", png.substr(0, png.size() / 2));
    const std::size_t files = file_count(dir_.path());
    const auto refused = [&](const std::string& options, int code, const std::string& says) {
        SCOPED_TRACE(options);
        const auto r = run("texture " + quoted(input_) + " -o " + quoted(out) + " " + options);
        EXPECT_EQ(r.exit_code, code) << r.out;
        EXPECT_NE(r.out.find(says), std::string::npos) << r.out;
        EXPECT_EQ(test::read_file(out), "precious");
        EXPECT_EQ(file_count(dir_.path()), files);
    };
    refused("--level 7", 2, "level 7 does not exist");
    refused("--normal-map-level 3", 2, "must be coarser");
    refused("--size 0", 2, "--size");
    refused("--size 100000", 2, "--size");
    refused("--image " + quoted(dir_ / "not.png"), 3, "not.png");
    refused("--image " + quoted(dir_ / "cut.png"), 3, "cut.png");
    refused("--image " + quoted(dir_ / "missing.png"), 3, "missing.png");
    refused("--bake-colors " + quoted(dir_ / "missing.ply"), 3, "missing.ply");
    refused("--checker --image " + quoted(dir_ / "not.png"), 2, "excludes");
    const auto other = run("texture " + quoted(input_) + " -o " + quoted(dir_ / "out.stl"));
    EXPECT_EQ(other.exit_code, 2) << other.out;
    EXPECT_FALSE(std::filesystem::exists(dir_ / "out.stl"));
}

} // namespace
} // namespace pointform
