// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/hermite/radius.h"

#include "pointform/core/error.h"
#include "pointform/core/parallel.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>
#include <sstream>

namespace pointform {
namespace {

using nlohmann::json;

double finite_number(const json& value, const std::string& what,
                     const std::filesystem::path& source)
{
    if (!value.is_number())
        throw IoError(source, what + " must be a number");
    const double x = value.get<double>();
    if (!std::isfinite(x))
        throw IoError(source, what + " must be finite");
    return x;
}

Vec3d vector3(const json& value, const std::string& what, const std::filesystem::path& source)
{
    if (!value.is_array() || value.size() != 3)
        throw IoError(source, what + " must be an array of 3 numbers");
    return {finite_number(value[0], what + "[0]", source),
            finite_number(value[1], what + "[1]", source),
            finite_number(value[2], what + "[2]", source)};
}

RadiusRegion parse_region(const json& item, std::size_t index, const std::filesystem::path& source)
{
    const std::string where = "regions[" + std::to_string(index) + "]";
    if (!item.is_object())
        throw IoError(source, where + " must be an object");
    RadiusRegion region;
    if (item.contains("ball") == item.contains("box"))
        throw IoError(source, where + " must have exactly one of \"ball\" or \"box\"");
    if (item.contains("ball"))
    {
        const json& ball = item["ball"];
        if (!ball.is_object() || !ball.contains("center") || !ball.contains("radius"))
            throw IoError(source, where + ".ball needs \"center\" and \"radius\"");
        region.kind = RadiusRegion::Kind::Ball;
        region.center = vector3(ball["center"], where + ".ball.center", source);
        region.ball_radius = finite_number(ball["radius"], where + ".ball.radius", source);
        if (region.ball_radius < 0.0)
            throw IoError(source, where + ".ball.radius must not be negative");
    }
    else
    {
        const json& box = item["box"];
        if (!box.is_object() || !box.contains("min") || !box.contains("max"))
            throw IoError(source, where + ".box needs \"min\" and \"max\"");
        region.kind = RadiusRegion::Kind::Box;
        region.box.min = vector3(box["min"], where + ".box.min", source);
        region.box.max = vector3(box["max"], where + ".box.max", source);
        if ((region.box.min.array() > region.box.max.array()).any())
            throw IoError(source, where + ".box.min must not exceed .box.max");
    }
    if (item.contains("set") == item.contains("scale"))
        throw IoError(source, where + " must have exactly one of \"set\" or \"scale\"");
    if (item.contains("set"))
    {
        region.radius = finite_number(item["set"], where + ".set", source);
        if (!(region.radius > 0.0))
            throw IoError(source, where + ".set must be positive");
    }
    else
    {
        region.scale = finite_number(item["scale"], where + ".scale", source);
        if (!(region.scale > 0.0))
            throw IoError(source, where + ".scale must be positive");
    }
    return region;
}

} // namespace

bool RadiusRegion::contains(const Vec3d& p) const
{
    if (kind == Kind::Ball)
        return (p - center).squaredNorm() <= ball_radius * ball_radius;
    return box.contains(p);
}

std::vector<float> influence_radii(const KnnTable& neighbors, double scale)
{
    if (!(scale > 0.0) || !std::isfinite(scale))
        throw InvalidInput("influence radius: scale must be positive and finite, got " +
                           std::to_string(scale));
    check_knn_table_shape(neighbors, neighbors.rows(), "influence_radii");
    std::vector<float> radii(neighbors.rows());
    for (std::size_t i = 0; i < radii.size(); ++i)
        radii[i] =
            static_cast<float>(scale * std::sqrt(static_cast<double>(neighbors.farthest2(i))));
    return radii;
}

std::vector<RadiusRegion> parse_radius_regions(const std::string& text,
                                               const std::filesystem::path& source)
{
    json document;
    try
    {
        document = json::parse(text);
    }
    catch (const json::parse_error& e)
    {
        // nlohmann reports the byte position; give the line and column too.
        std::size_t line = 1;
        std::size_t column = 1;
        for (std::size_t i = 0; i + 1 < e.byte && i < text.size(); ++i)
        {
            if (text[i] == '\n')
            {
                ++line;
                column = 1;
            }
            else
                ++column;
        }
        throw IoError(source, "invalid JSON at column " + std::to_string(column) + ": " + e.what(),
                      line);
    }
    if (!document.is_object() || !document.contains("regions") || !document["regions"].is_array())
        throw IoError(source, "expected an object with a \"regions\" array");
    std::vector<RadiusRegion> regions;
    const json& items = document["regions"];
    for (std::size_t i = 0; i < items.size(); ++i)
        regions.push_back(parse_region(items[i], i, source));
    return regions;
}

std::vector<RadiusRegion> read_radius_regions(const std::filesystem::path& path)
{
    std::ifstream in(path, std::ios::binary);
    if (!in)
        throw IoError(path, "cannot open radius regions file");
    std::ostringstream text;
    text << in.rdbuf();
    return parse_radius_regions(text.str(), path);
}

std::vector<float> apply_radius_regions(std::span<const Vec3f> positions, const Vec3d& origin,
                                        std::vector<float> radii,
                                        std::span<const RadiusRegion> regions)
{
    if (radii.size() != positions.size())
        throw InvalidInput("apply_radius_regions: " + std::to_string(radii.size()) + " radii for " +
                           std::to_string(positions.size()) + " points");
    if (regions.empty())
        return radii;
    parallel_blocks(positions.size(), 8192, [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i)
        {
            const Vec3d p = origin + positions[i].cast<double>();
            const float automatic = radii[i];
            for (const auto& region : regions)
                if (region.contains(p))
                    radii[i] =
                        region.scale > 0.0
                            ? static_cast<float>(region.scale * static_cast<double>(automatic))
                            : static_cast<float>(region.radius);
        }
    });
    return radii;
}

} // namespace pointform
