// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// The CLI's OutputTransaction on its own: staged files appear only on commit, and a commit that
// fails halfway puts back the files it had already replaced.

#include "output_transaction.h"

#include "support/test_support.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <stdexcept>
#include <string>

namespace pointform::cli {
namespace {

using test::read_file;
using test::write_file;

std::set<std::string> listing(const std::filesystem::path& dir)
{
    std::set<std::string> names;
    for (const auto& entry : std::filesystem::directory_iterator(dir))
    {
        names.insert(entry.path().filename().string());
    }
    return names;
}

void write_text(const std::filesystem::path& path, const std::string& text)
{
    write_file(path, text);
}

TEST(OutputTransaction, NothingAppearsBeforeCommitAndEverythingAfter)
{
    test::TempDir dir;
    write_file(dir / "a.ply", "old a");
    {
        OutputTransaction t;
        t.stage(dir / "a.ply", [](const std::filesystem::path& p) { write_text(p, "new a"); });
        t.stage(dir / "b.ply", [](const std::filesystem::path& p) { write_text(p, "new b"); });
        EXPECT_EQ(read_file(dir / "a.ply"), "old a");
        EXPECT_FALSE(std::filesystem::exists(dir / "b.ply"));
        t.commit();
    }
    EXPECT_EQ(read_file(dir / "a.ply"), "new a");
    EXPECT_EQ(read_file(dir / "b.ply"), "new b");
    EXPECT_EQ(listing(dir.path()), (std::set<std::string>{"a.ply", "b.ply"}));
}

TEST(OutputTransaction, AWriterThatThrowsLeavesEveryFileAsItWas)
{
    test::TempDir dir;
    write_file(dir / "a.ply", "old a");
    {
        OutputTransaction t;
        t.stage(dir / "a.ply", [](const std::filesystem::path& p) { write_text(p, "new a"); });
        EXPECT_THROW(t.stage(dir / "b.ply",
                             [](const std::filesystem::path& p) {
                                 write_text(p, "half of b");
                                 throw std::runtime_error("disk full");
                             }),
                     std::runtime_error);
    } // never committed
    EXPECT_EQ(read_file(dir / "a.ply"), "old a");
    EXPECT_EQ(listing(dir.path()), std::set<std::string>{"a.ply"});
}

TEST(OutputTransaction, ACommitThatFailsHalfwayPutsBackWhatItReplaced)
{
    test::TempDir dir;
    write_file(dir / "a.ply", "old a");
    OutputTransaction t;
    t.stage(dir / "a.ply", [](const std::filesystem::path& p) { write_text(p, "new a"); });
    t.stage(dir / "b.ply", [](const std::filesystem::path& p) { write_text(p, "new b"); });
    t.stage(dir / "c.ply", [](const std::filesystem::path& p) { write_text(p, "new c"); });
    // Something else takes c.ply (a non-empty directory cannot be renamed over) after staging:
    // a.ply and b.ply are already in place when c.ply fails.
    std::filesystem::create_directories(dir / "c.ply" / "inside");
    EXPECT_THROW(t.commit(), IoError);
    EXPECT_EQ(read_file(dir / "a.ply"), "old a");
    EXPECT_FALSE(std::filesystem::exists(dir / "b.ply"));
    EXPECT_EQ(listing(dir.path()), (std::set<std::string>{"a.ply", "c.ply"}));
}

TEST(OutputTransaction, RejectsOneFileForTwoOutputsAndADirectory)
{
    test::TempDir dir;
    OutputTransaction t;
    t.stage(dir / "a.ply", [](const std::filesystem::path& p) { write_text(p, "a"); });
    EXPECT_THROW(t.stage(dir / "." / "a.ply", [](const std::filesystem::path&) {}), InvalidInput);
    std::filesystem::create_directory(dir / "d.ply");
    EXPECT_THROW(t.stage(dir / "d.ply", [](const std::filesystem::path&) {}), IoError);
    try
    {
        t.stage(dir / "missing" / "x.ply",
                [](const std::filesystem::path& p) { write_file(p, "x"); });
    }
    catch (const std::exception&)
    {}
    t.commit();
    EXPECT_EQ(read_file(dir / "a.ply"), "a");
    EXPECT_EQ(listing(dir.path()), (std::set<std::string>{"a.ply", "d.ply"}));
}

} // namespace
} // namespace pointform::cli
