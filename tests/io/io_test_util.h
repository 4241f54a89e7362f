// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

// Helpers for the io tests: building file bytes by hand (either byte order), a literal-only LZF
// encoder, deterministic sample clouds and meshes, comparisons relative to the bbox diagonal, and
// checks that reading a file fails with the expected IoError (message, line or byte offset).

#include "pointform/core/error.h"
#include "pointform/geometry/point_cloud.h"
#include "pointform/geometry/tri_mesh.h"
#include "pointform/io/io.h"

#include "support/test_support.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace pointform::test {

/// Appends text and binary values in either byte order to a byte string.
class Bytes
{
public:
    Bytes& text(std::string_view s)
    {
        bytes_.append(s);
        return *this;
    }

    template <typename T>
    Bytes& le(T value)
    {
        return put(value, std::endian::little);
    }

    template <typename T>
    Bytes& be(T value)
    {
        return put(value, std::endian::big);
    }

    template <typename T>
    Bytes& put(T value, std::endian order)
    {
        char raw[sizeof(T)];
        std::memcpy(raw, &value, sizeof(T));
        if (order != std::endian::native)
            std::reverse(raw, raw + sizeof(T));
        bytes_.append(raw, sizeof(T));
        return *this;
    }

    Bytes& zeros(std::size_t n)
    {
        bytes_.append(n, '\0');
        return *this;
    }

    [[nodiscard]] const std::string& str() const { return bytes_; }
    [[nodiscard]] std::string& str() { return bytes_; }
    [[nodiscard]] std::size_t size() const { return bytes_.size(); }

private:
    std::string bytes_;
};

/// LZF stream made only of literal runs (at most 32 bytes each): valid LZF, no compression.
inline std::string lzf_literal_encode(std::string_view data)
{
    std::string out;
    for (std::size_t i = 0; i < data.size(); i += 32)
    {
        const std::size_t run = std::min<std::size_t>(32, data.size() - i);
        out.push_back(static_cast<char>(run - 1));
        out.append(data.substr(i, run));
    }
    return out;
}

/// n points on a sphere of radius `radius` around `center` (Fibonacci spiral), optionally with
/// outward normals, colors and radii. Positions are relative to `center`, which is the origin;
/// the default radius keeps every point within 0.5 of it, where choose_origin keeps origin 0.
inline PointCloud make_cloud(std::size_t n, bool normals, bool colors, bool radii,
                             const Vec3d& center = Vec3d::Zero(), double radius = 0.45)
{
    PointCloud cloud;
    cloud.origin = center;
    const double golden = 2.399963229728653;
    for (std::size_t i = 0; i < n; ++i)
    {
        const double z = 1.0 - 2.0 * (static_cast<double>(i) + 0.5) / static_cast<double>(n);
        const double r = std::sqrt(1.0 - z * z);
        const double phi = golden * static_cast<double>(i);
        const Vec3d u(r * std::cos(phi), r * std::sin(phi), z);
        cloud.positions.push_back((radius * u).cast<float>());
        if (normals)
            cloud.normals.push_back(u.cast<float>().normalized());
        if (colors)
            cloud.colors.push_back({static_cast<std::uint8_t>(i % 256),
                                    static_cast<std::uint8_t>((i * 7) % 256),
                                    static_cast<std::uint8_t>((i * 13) % 256)});
        if (radii)
            cloud.radii.push_back(0.01F + 0.001F * static_cast<float>(i % 10));
    }
    return cloud;
}

/// A (rows + 1) x (cols + 1) vertex grid on a wavy height field, two triangles per cell.
inline TriMesh make_grid_mesh(std::size_t rows, std::size_t cols,
                              const Vec3d& origin = Vec3d::Zero())
{
    TriMesh mesh;
    mesh.vertices.origin = origin;
    for (std::size_t r = 0; r <= rows; ++r)
        for (std::size_t c = 0; c <= cols; ++c)
        {
            const float x = static_cast<float>(c) / static_cast<float>(cols);
            const float y = static_cast<float>(r) / static_cast<float>(rows);
            mesh.vertices.positions.emplace_back(x, y,
                                                 0.1F * std::sin(6.0F * x) * std::cos(4.0F * y));
        }
    const auto id = [&](std::size_t r, std::size_t c) {
        return static_cast<std::uint32_t>(r * (cols + 1) + c);
    };
    for (std::size_t r = 0; r < rows; ++r)
        for (std::size_t c = 0; c < cols; ++c)
        {
            mesh.triangles.push_back({id(r, c), id(r, c + 1), id(r + 1, c + 1)});
            mesh.triangles.push_back({id(r, c), id(r + 1, c + 1), id(r + 1, c)});
        }
    return mesh;
}

/// Bounding-box diagonal in world units.
inline double diagonal(const PointCloud& cloud)
{
    return cloud.bounds().diagonal();
}

/// Checks that `actual` holds the points of `expected` in the same order: world positions within
/// `relative` times the bbox diagonal, normals within 1e-5, colors equal, radii within 1e-6.
inline void expect_same_cloud(const PointCloud& expected, const PointCloud& actual,
                              double relative = 1e-6)
{
    ASSERT_EQ(actual.size(), expected.size());
    EXPECT_EQ(actual.has_normals(), expected.has_normals());
    EXPECT_EQ(actual.has_colors(), expected.has_colors());
    EXPECT_EQ(actual.has_radii(), expected.has_radii());
    const double tolerance = relative * std::max(diagonal(expected), 1e-12);
    std::size_t bad = 0;
    for (std::size_t i = 0; i < expected.size() && bad < 5; ++i)
    {
        const double distance = (actual.world(i) - expected.world(i)).norm();
        if (distance > tolerance)
        {
            ++bad;
            ADD_FAILURE() << "point " << i << " is " << distance << " away (tolerance " << tolerance
                          << ")";
        }
        if (expected.has_normals() && actual.has_normals())
        {
            EXPECT_LT((actual.normals[i] - expected.normals[i]).norm(), 1e-5F) << "normal " << i;
        }
        if (expected.has_colors() && actual.has_colors())
        {
            EXPECT_EQ(actual.colors[i], expected.colors[i]) << "color " << i;
        }
        if (expected.has_radii() && actual.has_radii())
        {
            EXPECT_NEAR(actual.radii[i], expected.radii[i], 1e-6F) << "radius " << i;
        }
    }
}

/// Runs `f`, which must throw IoError whose message names `path` and contains `fragment`.
/// Returns the error (for its line and offset), or nothing after recording a failure.
template <typename F>
std::optional<IoError> expect_io_error(F&& f, const std::filesystem::path& path,
                                       std::string_view fragment = {})
{
    try
    {
        f();
    }
    catch (const IoError& e)
    {
        const std::string what = e.what();
        EXPECT_NE(what.find(path.string()), std::string::npos) << "message: " << what;
        EXPECT_NE(what.find(fragment), std::string::npos)
            << "message: " << what << "\nexpected to contain: " << fragment;
        EXPECT_EQ(e.path(), path);
        return e;
    }
    catch (const std::exception& e)
    {
        ADD_FAILURE() << "expected IoError, got another exception: " << e.what();
        return std::nullopt;
    }
    ADD_FAILURE() << "expected IoError, but nothing was thrown";
    return std::nullopt;
}

/// Checks that an error from expect_io_error names 1-based line `line`.
inline void expect_error_line(const std::optional<IoError>& e, std::uint64_t line,
                              const std::filesystem::path& path)
{
    ASSERT_TRUE(e && e->line()) << path;
    EXPECT_EQ(*e->line(), line) << path;
}

/// Checks that an error from expect_io_error names byte offset `offset`.
inline void expect_error_offset(const std::optional<IoError>& e, std::uint64_t offset,
                                const std::filesystem::path& path)
{
    ASSERT_TRUE(e && e->offset()) << path;
    EXPECT_EQ(*e->offset(), offset) << path;
}

/// Writes `content` to `path` and reads it with read_geometry, which must throw an IoError that
/// names `path` and contains `fragment`. Returns the error, or nothing after recording a failure.
inline std::optional<IoError> expect_file_error(const std::filesystem::path& path,
                                                const std::string& content,
                                                std::string_view fragment,
                                                const ReadOptions& options = {})
{
    write_file(path, content);
    return expect_io_error([&] { (void)read_geometry(path, options); }, path, fragment);
}

/// As expect_file_error, and the error must name 1-based line `line`.
inline std::optional<IoError> expect_file_error_at_line(const std::filesystem::path& path,
                                                        const std::string& content,
                                                        std::string_view fragment,
                                                        std::uint64_t line,
                                                        const ReadOptions& options = {})
{
    std::optional<IoError> e = expect_file_error(path, content, fragment, options);
    expect_error_line(e, line, path);
    return e;
}

/// As expect_file_error, and the error must name byte offset `offset`.
inline std::optional<IoError> expect_file_error_at_offset(const std::filesystem::path& path,
                                                          const std::string& content,
                                                          std::string_view fragment,
                                                          std::uint64_t offset,
                                                          const ReadOptions& options = {})
{
    std::optional<IoError> e = expect_file_error(path, content, fragment, options);
    expect_error_offset(e, offset, path);
    return e;
}

/// Files in a directory (names only), to check that failed writes leave nothing behind.
inline std::vector<std::string> list_directory(const std::filesystem::path& dir)
{
    std::vector<std::string> names;
    for (const auto& entry : std::filesystem::directory_iterator(dir))
        names.push_back(entry.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
}

} // namespace pointform::test
