// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// `pointform export`: the .glb is the library's bytes with the chosen levels, the .obj the
// finest chosen level; bad level lists exit 2 and write nothing (an existing output keeps its
// bytes); an unreadable input exits 3.

#include "pointform/io/hierarchy.h"
#include "pointform/io/io.h"
#include "pointform/io/textured_export.h"
#include "pointform/multires/export.h"

#include "cli_run.h"
#include "support/test_support.h"
#include "support/textured_fixtures.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

namespace pointform {
namespace {

using test::file_count;
using test::quoted;
using test::run;

/// The JSON chunk of a .glb file.
nlohmann::json glb_json(const std::string& bytes)
{
    std::uint32_t length = 0;
    std::memcpy(&length, bytes.data() + 12, 4);
    return nlohmann::json::parse(bytes.substr(20, length));
}

TEST(ExportCli, GlbHoldsTheChosenLevelsAsTheLibraryWritesThem)
{
    test::TempDir dir;
    const MultiresMesh hierarchy = test::plate_hierarchy(3);
    const auto input = dir / "plate.pfh";
    write_hierarchy(input, hierarchy);

    const auto all = dir / "all.glb";
    auto r = run("export " + quoted(input) + " -o " + quoted(all) + " --json");
    ASSERT_EQ(r.exit_code, 0) << r.out;
    auto report = nlohmann::json::parse(r.out);
    EXPECT_EQ(report["format"], "glb");
    ASSERT_EQ(report["levels"].size(), 4U);
    for (std::size_t l = 0; l < 4; ++l)
    {
        EXPECT_EQ(report["levels"][l]["level"], l);
        EXPECT_EQ(report["levels"][l]["vertices"], hierarchy.vertex_count(l));
        EXPECT_EQ(report["levels"][l]["faces"], hierarchy.face_count(l));
    }
    EXPECT_EQ(report["bytes"], std::filesystem::file_size(all));
    const std::vector<std::size_t> every = {0, 1, 2, 3};
    const std::vector<std::uint8_t> expected = encode_gltf(level_chain(hierarchy, every));
    EXPECT_EQ(test::read_file(all), std::string(expected.begin(), expected.end()));

    const auto some = dir / "some.glb";
    r = run("export " + quoted(input) + " -o " + quoted(some) + " --levels 1,3");
    ASSERT_EQ(r.exit_code, 0) << r.out;
    EXPECT_NE(r.out.find("bytes"), std::string::npos) << r.out;
    const nlohmann::json gltf = glb_json(test::read_file(some));
    ASSERT_EQ(gltf["nodes"].size(), 2U);
    EXPECT_EQ(gltf["nodes"][0]["name"], "level 1");
    EXPECT_EQ(gltf["nodes"][1]["name"], "level 3");
    EXPECT_EQ(gltf["nodes"][1]["extensions"]["MSFT_lod"]["ids"], nlohmann::json::array({0}));
    EXPECT_EQ(file_count(dir.path()), 3U); // the input and two outputs, no temporaries
}

TEST(ExportCli, ObjHoldsTheFinestChosenLevel)
{
    test::TempDir dir;
    const MultiresMesh hierarchy = test::plate_hierarchy(3);
    const auto input = dir / "plate.pfh";
    write_hierarchy(input, hierarchy);
    const auto obj = dir / "plate.obj";
    const auto r = run("export " + quoted(input) + " -o " + quoted(obj) + " --levels 0,2 --json");
    ASSERT_EQ(r.exit_code, 0) << r.out;
    const auto report = nlohmann::json::parse(r.out);
    EXPECT_EQ(report["format"], "obj");
    ASSERT_EQ(report["levels"].size(), 1U);
    EXPECT_EQ(report["levels"][0]["level"], 2);
    const TriMesh back = read_mesh(obj);
    EXPECT_EQ(back.triangles, hierarchy.faces(2));
    EXPECT_EQ(back.vertex_count(), hierarchy.vertex_count(2));
    EXPECT_TRUE(back.vertices.has_normals());
    EXPECT_EQ(file_count(dir.path()), 2U); // no .mtl without a texture
}

TEST(ExportCli, BadLevelListsExit2AndWriteNothing)
{
    test::TempDir dir;
    const auto input = dir / "plate.pfh";
    write_hierarchy(input, test::plate_hierarchy(2));
    const auto output = dir / "out.glb";
    for (const char* levels : {"3", "0,3", "1,1", "2,1", "''", "x", "1,,2", "-1", "1,", "all,1"})
    {
        SCOPED_TRACE(levels);
        const auto r =
            run("export " + quoted(input) + " -o " + quoted(output) + " --levels " + levels);
        EXPECT_EQ(r.exit_code, 2) << r.out;
        EXPECT_NE(r.out.find("invalid input"), std::string::npos) << r.out;
        EXPECT_EQ(file_count(dir.path()), 1U);
    }
    // A format other than .glb and .obj.
    const auto r = run("export " + quoted(input) + " -o " + quoted(dir / "out.ply"));
    EXPECT_EQ(r.exit_code, 2) << r.out;
    EXPECT_EQ(file_count(dir.path()), 1U);
}

TEST(ExportCli, AnExistingOutputIsKeptOnFailure)
{
    test::TempDir dir;
    const auto input = dir / "plate.pfh";
    write_hierarchy(input, test::plate_hierarchy(2));
    const auto output = dir / "kept.glb";
    test::write_file(output, "precious bytes");
    auto r = run("export " + quoted(input) + " -o " + quoted(output) + " --levels 7");
    EXPECT_EQ(r.exit_code, 2) << r.out;
    EXPECT_EQ(test::read_file(output), "precious bytes");
    r = run("export " + quoted(dir / "absent.pfh") + " -o " + quoted(output));
    EXPECT_EQ(r.exit_code, 3) << r.out;
    EXPECT_EQ(test::read_file(output), "precious bytes");
    EXPECT_EQ(file_count(dir.path()), 2U);
    // Success replaces it.
    r = run("export " + quoted(input) + " -o " + quoted(output) + " -q");
    EXPECT_EQ(r.exit_code, 0) << r.out;
    EXPECT_EQ(test::read_file(output).substr(0, 4), "glTF");
}

TEST(ExportCli, UnreadableInputExits3)
{
    test::TempDir dir;
    const auto output = dir / "out.glb";
    auto r = run("export " + quoted(dir / "missing.pfh") + " -o " + quoted(output));
    EXPECT_EQ(r.exit_code, 3) << r.out;
    EXPECT_NE(r.out.find("missing.pfh"), std::string::npos) << r.out;
    test::write_file(dir / "garbage.pfh", "not a hierarchy at all");
    r = run("export " + quoted(dir / "garbage.pfh") + " -o " + quoted(output));
    EXPECT_EQ(r.exit_code, 3) << r.out;
    // An unwritable output (its folder is missing) is a file error too.
    const auto input = dir / "plate.pfh";
    write_hierarchy(input, test::plate_hierarchy(1));
    r = run("export " + quoted(input) + " -o " + quoted(dir / "no" / "such" / "out.glb"));
    EXPECT_EQ(r.exit_code, 3) << r.out;
    EXPECT_EQ(file_count(dir.path()), 2U); // garbage.pfh and plate.pfh
}

} // namespace
} // namespace pointform
