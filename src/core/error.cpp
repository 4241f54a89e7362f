// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/core/error.h"

#include <cstdio>
#include <cstdlib>
#include <sstream>

namespace pointform {
namespace {

std::string describe(const std::filesystem::path& path, const std::string& what,
                     std::optional<std::uint64_t> line, std::optional<std::uint64_t> offset)
{
    std::ostringstream msg;
    msg << path.string();
    if (line)
        msg << ':' << *line;
    if (offset)
        msg << " (byte " << *offset << ')';
    msg << ": " << what;
    return msg.str();
}

} // namespace

IoError::IoError(const std::filesystem::path& path, const std::string& what,
                 std::optional<std::uint64_t> line, std::optional<std::uint64_t> offset)
    : Error(describe(path, what, line, offset)), path_(path), line_(line), offset_(offset)
{}

namespace detail {

void assert_fail(const char* expr, const char* file, int line)
{
    std::fprintf(stderr, "pointform: internal assertion failed: %s at %s:%d\n", expr, file, line);
    std::abort();
}

void throw_buffer_size(const char* function, const char* buffer, std::size_t size,
                       std::size_t needed, bool exact)
{
    throw InvalidInput(std::string(function) + ": " + buffer + " has " + std::to_string(size) +
                       " entries, " + (exact ? "expected " : "needs at least ") +
                       std::to_string(needed));
}

} // namespace detail
} // namespace pointform
