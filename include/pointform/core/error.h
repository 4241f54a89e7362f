// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>

namespace pointform {

/// \brief Base of every exception pointform throws on purpose.
class Error : public std::runtime_error
{
public:
    using std::runtime_error::runtime_error;
};

/// \brief Input that violates a documented precondition: too few points, NaN, bad options.
class InvalidInput : public Error
{
public:
    using Error::Error;
};

/// \brief A file could not be read or written. The message names the file and, where known,
/// the line (text formats) or byte offset (binary formats) at which the problem was found.
class IoError : public Error
{
public:
    /// \param path    the file concerned
    /// \param what    what is wrong, in words
    /// \param line    1-based line number for text formats, if known
    /// \param offset  byte offset for binary formats, if known
    IoError(const std::filesystem::path& path, const std::string& what,
            std::optional<std::uint64_t> line = std::nullopt,
            std::optional<std::uint64_t> offset = std::nullopt);

    [[nodiscard]] const std::filesystem::path& path() const { return path_; }
    [[nodiscard]] std::optional<std::uint64_t> line() const { return line_; }
    [[nodiscard]] std::optional<std::uint64_t> offset() const { return offset_; }

private:
    std::filesystem::path path_;
    std::optional<std::uint64_t> line_;
    std::optional<std::uint64_t> offset_;
};

/// \brief A numerical method failed to produce a usable answer.
class SolverError : public Error
{
public:
    using Error::Error;
};

/// \brief A mesh or graph does not have the topology an algorithm needs.
class TopologyError : public Error
{
public:
    using Error::Error;
};

/// \brief A progress callback asked a long-running algorithm to stop.
class Cancelled : public Error
{
public:
    using Error::Error;
};

} // namespace pointform

/// Internal invariant check; active unless NDEBUG is defined without PF_KEEP_ASSERTS.
#if !defined(NDEBUG) || defined(PF_KEEP_ASSERTS)
#define PF_ASSERT(cond)                                                  \
    do                                                                   \
    {                                                                    \
        if (!(cond))                                                     \
            ::pointform::detail::assert_fail(#cond, __FILE__, __LINE__); \
    } while (false)
#else
#define PF_ASSERT(cond) ((void)0)
#endif

namespace pointform::detail {
[[noreturn]] void assert_fail(const char* expr, const char* file, int line);
[[noreturn]] void throw_buffer_size(const char* function, const char* buffer, std::size_t size,
                                    std::size_t needed, bool exact);
} // namespace pointform::detail

namespace pointform {

/// \brief Checks, in every build, that a caller's buffer holds at least `needed` items, so that
/// a public function cannot read or write past it: once per call, not per item.
/// \throw InvalidInput naming the function, the buffer, its size and the size needed
inline void check_buffer_size(const char* function, const char* buffer, std::size_t size,
                              std::size_t needed)
{
    if (size < needed) [[unlikely]]
        detail::throw_buffer_size(function, buffer, size, needed, false);
}

/// \brief check_buffer_size() for a buffer that must hold exactly `expected` items (say, one
/// per query point).
inline void check_same_size(const char* function, const char* buffer, std::size_t size,
                            std::size_t expected)
{
    if (size != expected) [[unlikely]]
        detail::throw_buffer_size(function, buffer, size, expected, true);
}

} // namespace pointform
