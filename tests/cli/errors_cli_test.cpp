// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// Exit codes as the README states them (2 invalid input and usage, 3 file errors, 4 other
// failures), the memory guard that refuses work before allocating it, and all-or-nothing
// outputs: a failed command leaves every pre-existing file byte for byte as it was.

#include "cli_run.h"
#include "support/test_support.h"

#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <set>
#include <string>
#include <vector>

namespace pointform {
namespace {

using test::quoted;
using test::read_file;
using test::run;
using test::write_file;

struct BadValue
{
    std::string arguments;
    std::string mentions; ///< the message names the option
};

TEST(ErrorsCli, EveryCommandExits2OnABadOptionValue)
{
    // Values are checked while parsing, before any file is opened, so the inputs need not
    // exist.
    const std::vector<BadValue> cases = {
        {"info in.ply --json=maybe", "--json"},
        {"normals in.ply -o out.ply -k 2", "-k"},
        {"sample sphere -o out.ply -n -5", "--count"},
        {"sample cube -o out.ply", "shape"},
        {"mc in.ply -o out.ply --resolution 1", "--resolution"},
        {"distance a.ply b.ply --samples 0", "--samples"},
        {"render in.ply -o out.png --supersampling 9", "--supersampling"},
        {"render in.ply -o out.png --size 0,10", "--size"},
        {"model 'sphere([0,0,0],1)' -o out.ply --cell -1", "--cell"},
        {"morph 'sphere([0,0,0],1)' 'sphere([0,0,0],2)' -o seq --steps 0", "--steps"},
        {"reconstruct in.ply -o out.ply --levels 99", "--levels"},
        {"reconstruct in.ply -o out.ply --denoise 1001", "--denoise"},
        {"reconstruct in.ply -o out.ply --denoise -1", "--denoise"},
        {"mc in.ply -o out.ply --fill-holes 2", "--fill-holes"},
        {"remesh in.off -o out.ply --levels abc", "--levels"},
        {"lod in.pfh -l abc", "--level"},
    };
    for (const BadValue& c : cases)
    {
        const test::RunResult r = run(c.arguments);
        EXPECT_EQ(r.exit_code, 2) << c.arguments << "\n" << r.out;
        EXPECT_NE(r.out.find(c.mentions), std::string::npos) << c.arguments << "\n" << r.out;
    }
}

TEST(ErrorsCli, UsageErrorsExit2AndHelpExits0)
{
    EXPECT_EQ(run("info in.ply --no-such-option").exit_code, 2);
    EXPECT_EQ(run("normals in.ply").exit_code, 2); // -o is required
    EXPECT_EQ(run("").exit_code, 2);               // a subcommand is required
    EXPECT_EQ(run("frobnicate").exit_code, 2);
    EXPECT_EQ(run("--help").exit_code, 0);
    EXPECT_EQ(run("mc --help").exit_code, 0);
    EXPECT_EQ(run("--version").exit_code, 0);
}

TEST(ErrorsCli, ThreadCountsOutOfRangeExit2)
{
    for (const char* threads : {"-1", "100000", "abc", "1e9"})
    {
        const test::RunResult r = run(std::string("-j ") + threads + " info in.ply");
        EXPECT_EQ(r.exit_code, 2) << threads << "\n" << r.out;
        EXPECT_NE(r.out.find("-j"), std::string::npos) << r.out;
    }
}

TEST(ErrorsCli, ASceneWithNoSurfaceInItsBoxIsAnOtherFailure)
{
    test::TempDir dir;
    // Valid input, valid options, but the box holds no surface: nothing to write (exit 4).
    const test::RunResult r =
        run("model 'sphere([0,0,0],1)' --bounds 5,5,5,6,6,6 -o " + quoted(dir / "out.ply"));
    EXPECT_EQ(r.exit_code, 4) << r.out;
    EXPECT_NE(r.out.find("no triangles"), std::string::npos) << r.out;
    EXPECT_FALSE(std::filesystem::exists(dir / "out.ply"));
}

/// Runs `arguments` and expects a refusal (exit 2) that states its estimate, within seconds.
void expect_refused_for_memory(const std::string& arguments)
{
    const auto start = std::chrono::steady_clock::now();
    const test::RunResult r = run(arguments);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    EXPECT_EQ(r.exit_code, 2) << arguments << "\n" << r.out;
    EXPECT_NE(r.out.find("would need about"), std::string::npos) << arguments << "\n" << r.out;
    EXPECT_NE(r.out.find("GiB"), std::string::npos) << r.out;
    EXPECT_LT(seconds, 20.0) << arguments;
}

TEST(ErrorsCli, WorkThatWouldNotFitInMemoryIsRefusedBeforeAllocating)
{
    test::TempDir dir;
    const auto cloud = dir / "sphere.ply";
    ASSERT_EQ(run("sample sphere -n 2000 -o " + quoted(cloud)).exit_code, 0);
    expect_refused_for_memory("model 'sphere([0,0,0],1)' --resolution 1000000 -o " +
                              quoted(dir / "a.ply"));
    expect_refused_for_memory("mc " + quoted(cloud) + " --resolution 500000 -o " +
                              quoted(dir / "b.ply"));
    expect_refused_for_memory("reconstruct " + quoted(cloud) + " --resolution 500000 -o " +
                              quoted(dir / "c.ply"));
    expect_refused_for_memory("sample sphere -n 1000000000000000 -o " + quoted(dir / "d.ply"));
    expect_refused_for_memory("distance " + quoted(cloud) + " " + quoted(cloud) +
                              " --samples 1000000000000000");
    expect_refused_for_memory("render " + quoted(cloud) + " -o " + quoted(dir / "e.png") +
                              " --size 16384,16384 --supersampling 8");
    expect_refused_for_memory("model 'sphere([0,0,0],1)' --semi-regular --levels 8 -o " +
                              quoted(dir / "f.ply"));
    // Nothing was written.
    std::set<std::string> names;
    for (const auto& entry : std::filesystem::directory_iterator(dir.path()))
    {
        names.insert(entry.path().filename().string());
    }
    EXPECT_EQ(names, std::set<std::string>{"sphere.ply"});
}

/// The names in `dir`.
std::set<std::string> listing(const std::filesystem::path& dir)
{
    std::set<std::string> names;
    for (const auto& entry : std::filesystem::directory_iterator(dir))
    {
        names.insert(entry.path().filename().string());
    }
    return names;
}

TEST(ErrorsCli, AFailedSecondOutputLeavesTheFirstFileAsItWas)
{
    test::TempDir dir;
    const std::string old_bytes = "a user's file that must survive\n";
    const auto mesh = dir / "mesh.ply";
    write_file(mesh, old_bytes);
    const std::string scene = "'sphere([0,0,0],1)'";
    const std::string semi = " --semi-regular --levels 1 --resolution 24 -o " + quoted(mesh);

    // The hierarchy in a directory that does not exist: a file error, and mesh.ply untouched.
    const test::RunResult missing =
        run("model " + scene + semi + " --save-hierarchy " + quoted(dir / "no" / "h.pfh"));
    EXPECT_EQ(missing.exit_code, 3) << missing.out;
    EXPECT_NE(missing.out.find("h.pfh"), std::string::npos) << missing.out;
    EXPECT_EQ(read_file(mesh), old_bytes);

    // The hierarchy path is a directory.
    std::filesystem::create_directory(dir / "taken.pfh");
    const test::RunResult directory =
        run("model " + scene + semi + " --save-hierarchy " + quoted(dir / "taken.pfh"));
    EXPECT_EQ(directory.exit_code, 3) << directory.out;
    EXPECT_EQ(read_file(mesh), old_bytes);

    // Both outputs at one path.
    const test::RunResult same = run("model " + scene + semi + " --save-hierarchy " + quoted(mesh));
    EXPECT_EQ(same.exit_code, 2) << same.out;
    EXPECT_EQ(read_file(mesh), old_bytes);

    // No temporary is left behind.
    EXPECT_EQ(listing(dir.path()), (std::set<std::string>{"mesh.ply", "taken.pfh"}));

    // And when both can be written, both are.
    const test::RunResult ok =
        run("model " + scene + semi + " --save-hierarchy " + quoted(dir / "h.pfh"));
    ASSERT_EQ(ok.exit_code, 0) << ok.out;
    EXPECT_NE(read_file(mesh), old_bytes);
    EXPECT_TRUE(std::filesystem::is_regular_file(dir / "h.pfh"));
    EXPECT_EQ(listing(dir.path()), (std::set<std::string>{"h.pfh", "mesh.ply", "taken.pfh"}));
}

TEST(ErrorsCli, ReconstructAndRemeshWriteTheirMeshAndHierarchyTogether)
{
    test::TempDir dir;
    const auto cloud = dir / "sphere.ply";
    ASSERT_EQ(run("sample sphere -n 3000 -o " + quoted(cloud)).exit_code, 0);
    const std::string old_bytes = "keep me\n";
    const auto mesh = dir / "mesh.ply";
    write_file(mesh, old_bytes);
    const test::RunResult reconstructed =
        run("reconstruct " + quoted(cloud) + " --levels 1 -o " + quoted(mesh) +
            " --save-hierarchy " + quoted(dir / "no" / "h.pfh"));
    EXPECT_EQ(reconstructed.exit_code, 3) << reconstructed.out;
    EXPECT_EQ(read_file(mesh), old_bytes);

    const auto input = test::data_path("meshes/bunny_uniform.off");
    const test::RunResult remeshed =
        run("remesh " + quoted(input) + " --levels 1 -o " + quoted(mesh) + " --save-hierarchy " +
            quoted(dir / "no" / "h.pfh"));
    EXPECT_EQ(remeshed.exit_code, 3) << remeshed.out;
    EXPECT_EQ(read_file(mesh), old_bytes);
    EXPECT_EQ(listing(dir.path()), (std::set<std::string>{"mesh.ply", "sphere.ply"}));
}

TEST(ErrorsCli, AFailedMorphStepLeavesEveryEarlierStepAsItWas)
{
    test::TempDir dir;
    const auto prefix = dir / "seq";
    const std::string old_first = "step 0 from an earlier run\n";
    write_file(dir / "seq_000.ply", old_first);
    std::filesystem::create_directory(dir / "seq_002.ply"); // the third step cannot be written
    const test::RunResult r = run("morph 'sphere([0,0,0],1)' 'box([-1,-1,-1],[1,1,1])' -o " +
                                  quoted(prefix) + " --steps 3 --resolution 16");
    EXPECT_EQ(r.exit_code, 3) << r.out;
    EXPECT_NE(r.out.find("seq_002.ply"), std::string::npos) << r.out;
    EXPECT_EQ(read_file(dir / "seq_000.ply"), old_first);
    EXPECT_EQ(listing(dir.path()), (std::set<std::string>{"seq_000.ply", "seq_002.ply"}));
}

TEST(ErrorsCli, SingleOutputsKeepTheOldFileWhenTheWriteFails)
{
    test::TempDir dir;
    // An output path that is a directory: exit 3 naming it, the directory untouched.
    std::filesystem::create_directory(dir / "out.ply");
    const test::RunResult r = run("sample sphere -n 100 -o " + quoted(dir / "out.ply"));
    EXPECT_EQ(r.exit_code, 3) << r.out;
    EXPECT_NE(r.out.find("out.ply"), std::string::npos) << r.out;
    EXPECT_EQ(r.out.find(".pf-"), std::string::npos) << "the message names a temporary: " << r.out;
    EXPECT_TRUE(std::filesystem::is_directory(dir / "out.ply"));
    EXPECT_EQ(listing(dir.path()), std::set<std::string>{"out.ply"});
}

} // namespace
} // namespace pointform
