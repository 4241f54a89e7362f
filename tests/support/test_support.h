// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include "pointform/core/types.h"
#include "pointform/geometry/point_cloud.h"

#include <filesystem>
#include <span>
#include <string>

namespace pointform::test {

/// \brief A directory under the system temp folder, unique per test, removed on destruction.
class TempDir
{
public:
    TempDir();
    ~TempDir();
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;

    [[nodiscard]] const std::filesystem::path& path() const { return path_; }
    [[nodiscard]] std::filesystem::path operator/(const std::string& name) const
    {
        return path_ / name;
    }

private:
    std::filesystem::path path_;
};

/// \brief Path of a file in the repository's data/ folder.
[[nodiscard]] std::filesystem::path data_path(const std::string& relative);

/// \brief Path of a file in tests/fixtures/ (inputs made for the tests; see its README.md).
[[nodiscard]] std::filesystem::path fixture_path(const std::string& relative);

/// \brief Writes `content` to `path` as raw bytes.
void write_file(const std::filesystem::path& path, const std::string& content);

/// \brief Reads a whole file as raw bytes.
[[nodiscard]] std::string read_file(const std::filesystem::path& path);

/// \brief The cloud without its normals: its positions (and anything else) as a scan gives them.
[[nodiscard]] PointCloud without_normals(PointCloud cloud);

/// \brief Fraction of normals whose sign agrees with the truth (dot product > 0).
[[nodiscard]] double oriented_fraction(std::span<const Vec3f> estimated,
                                       std::span<const Vec3f> truth);

/// \brief Angle in degrees between the lines two normals span (sign ignored), at quantile q of all
/// samples (q = 0.5: median; q = 1: maximum).
[[nodiscard]] double line_angle_quantile_deg(std::span<const Vec3f> estimated,
                                             std::span<const Vec3f> truth, double q);

} // namespace pointform::test
