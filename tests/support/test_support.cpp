// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "support/test_support.h"

#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <fstream>
#include <numbers>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace pointform::test {

TempDir::TempDir()
{
    static std::atomic<int> counter{0};
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string name = info != nullptr ? std::string(info->test_suite_name()) + "." + info->name()
                                       : std::string("pointform");
    for (auto& c : name)
        if (c == '/')
            c = '_';
    path_ =
        std::filesystem::temp_directory_path() / ("pf_" + name + "_" + std::to_string(::getpid()) +
                                                  "_" + std::to_string(counter.fetch_add(1)));
    std::filesystem::create_directories(path_);
}

TempDir::~TempDir()
{
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
}

std::filesystem::path data_path(const std::string& relative)
{
    return std::filesystem::path(PF_DATA_DIR) / relative;
}

std::filesystem::path fixture_path(const std::string& relative)
{
    return std::filesystem::path(PF_FIXTURES_DIR) / relative;
}

void write_file(const std::filesystem::path& path, const std::string& content)
{
    std::ofstream out(path, std::ios::binary);
    out.write(content.data(), static_cast<std::streamsize>(content.size()));
    if (!out)
        throw std::runtime_error("cannot write test file " + path.string());
}

std::string read_file(const std::filesystem::path& path)
{
    std::ifstream in(path, std::ios::binary);
    std::ostringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

double oriented_fraction(std::span<const Vec3f> estimated, std::span<const Vec3f> truth)
{
    EXPECT_EQ(estimated.size(), truth.size());
    std::size_t good = 0;
    for (std::size_t i = 0; i < std::min(estimated.size(), truth.size()); ++i)
        if (estimated[i].dot(truth[i]) > 0.0F)
            ++good;
    return truth.empty() ? 1.0 : static_cast<double>(good) / static_cast<double>(truth.size());
}

double line_angle_quantile_deg(std::span<const Vec3f> estimated, std::span<const Vec3f> truth,
                               double q)
{
    std::vector<double> angles;
    for (std::size_t i = 0; i < std::min(estimated.size(), truth.size()); ++i)
    {
        const double c = std::abs(
            estimated[i].cast<double>().normalized().dot(truth[i].cast<double>().normalized()));
        angles.push_back(std::acos(std::min(1.0, c)) * 180.0 / std::numbers::pi);
    }
    if (angles.empty())
        return 0.0;
    const auto at = static_cast<std::size_t>(q * static_cast<double>(angles.size() - 1));
    std::nth_element(angles.begin(), angles.begin() + static_cast<std::ptrdiff_t>(at),
                     angles.end());
    return angles[at];
}

PointCloud without_normals(PointCloud cloud)
{
    cloud.normals.clear();
    return cloud;
}

} // namespace pointform::test
