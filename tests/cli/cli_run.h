// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// Runs the command-line tool (PF_CLI_PATH) and captures what it prints and its exit code.

#pragma once

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <string>

namespace pointform::test {

struct RunResult
{
    int exit_code = -1;
    std::string out; ///< stdout and stderr together
};

inline RunResult run(const std::string& arguments)
{
    const std::string command = std::string(PF_CLI_PATH) + " " + arguments + " 2>&1";
    RunResult result;
    FILE* pipe = ::popen(command.c_str(), "r");
    if (pipe == nullptr)
    {
        return result;
    }
    std::array<char, 4096> buffer{};
    std::size_t n = 0;
    while ((n = std::fread(buffer.data(), 1, buffer.size(), pipe)) > 0)
    {
        result.out.append(buffer.data(), n);
    }
    const int status = ::pclose(pipe);
    result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return result;
}

inline std::string quoted(const std::filesystem::path& path)
{
    return "'" + path.string() + "'";
}

/// \brief How many entries `dir` holds (no output written, no temporary left behind).
inline std::size_t file_count(const std::filesystem::path& dir)
{
    std::size_t n = 0;
    for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator(dir))
        ++n;
    return n;
}

} // namespace pointform::test
