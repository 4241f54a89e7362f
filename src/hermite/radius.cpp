// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/hermite/radius.h"

#include "pointform/core/disjoint_sets.h"
#include "pointform/core/error.h"
#include "pointform/core/parallel.h"
#include "pointform/spatial/kd_tree.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <limits>
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
    parallel_blocks(radii.size(), 65536, [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i)
            radii[i] =
                static_cast<float>(scale * std::sqrt(static_cast<double>(neighbors.farthest2(i))));
    });
    return radii;
}

namespace {

/// Isolated groups that hold together at their own spacing in a whole of more samples than this
/// are a sparsely sampled sheet, not strays (isolated_samples()).
constexpr std::size_t sheet_samples = 128;

} // namespace

std::vector<std::uint32_t> isolated_samples(std::span<const Vec3f> positions,
                                            const KnnTable& neighbors)
{
    check_knn_table_shape(neighbors, positions.size(), "isolated_samples");
    const std::size_t n = positions.size();
    if (n == 0 || neighbors.k < 2)
        return {};
    constexpr std::size_t block = 65536;
    const std::size_t blocks = (n + block - 1) / block;
    // Two samples hold together when their gap is at most isolation_factor times the shorter of
    // their two reaches. A member i of a group of at most k samples has a row entry j outside
    // the group (the row has k + 1 entries); the link to j is broken although the gap is within
    // i's own reach, so the gap exceeds the factor times j's reach, and so does i's reach: only
    // samples whose reach exceeds the factor times the shortest reach in their row can belong to
    // such a group, and only rows of samples whose reach exceeds the factor times the least
    // reach of all are read.
    std::vector<float> least(blocks, std::numeric_limits<float>::infinity());
    parallel_blocks(n, block, [&](std::size_t begin, std::size_t end) {
        float low = std::numeric_limits<float>::infinity();
        for (std::size_t i = begin; i < end; ++i)
            low = std::min(low, neighbors.farthest2(i));
        least[begin / block] = low;
    });
    const float factor2 = isolation_factor * isolation_factor;
    const float long2 = factor2 * *std::min_element(least.begin(), least.end());
    const std::vector<std::uint32_t> candidates = parallel_collect<std::uint32_t>(
        n, block, [&](std::size_t begin, std::size_t end, std::vector<std::uint32_t>& out) {
            for (std::size_t i = begin; i < end; ++i)
            {
                const float reach2 = neighbors.farthest2(i);
                if (!(reach2 > long2))
                    continue;
                check_knn_row(neighbors, i, n, "isolated_samples");
                const auto row = neighbors.neighbors(i);
                if (std::any_of(row.begin(), row.end(), [&](std::uint32_t j) {
                        return j != i && reach2 > factor2 * neighbors.farthest2(j);
                    }))
                    out.push_back(static_cast<std::uint32_t>(i));
            }
        });
    if (candidates.empty())
        return {};
    const auto slot_of = [&](std::uint32_t j) {
        const auto at = std::lower_bound(candidates.begin(), candidates.end(), j);
        return at != candidates.end() && *at == j
                   ? static_cast<std::size_t>(at - candidates.begin())
                   : candidates.size();
    };
    // The links of each candidate's row: to a sample that is no candidate (the candidate is then
    // anchored to the rest), or to another candidate (an edge between their slots).
    const std::size_t c = candidates.size();
    std::vector<std::uint8_t> anchored(c, 0);
    const std::vector<std::pair<std::uint32_t, std::uint32_t>> links =
        parallel_collect<std::pair<std::uint32_t, std::uint32_t>>(
            c, 4096,
            [&](std::size_t begin, std::size_t end,
                std::vector<std::pair<std::uint32_t, std::uint32_t>>& out) {
                for (std::size_t s = begin; s < end; ++s)
                {
                    const std::uint32_t i = candidates[s];
                    const float reach_i = neighbors.farthest2(i);
                    for (const std::uint32_t j : neighbors.neighbors(i))
                    {
                        if (j == i)
                            continue;
                        const float gap2 = (positions[j] - positions[i]).squaredNorm();
                        if (gap2 > factor2 * std::min(reach_i, neighbors.farthest2(j)))
                            continue;
                        const std::size_t t = slot_of(j);
                        if (t == c)
                            anchored[s] = 1;
                        else
                            out.emplace_back(static_cast<std::uint32_t>(s),
                                             static_cast<std::uint32_t>(t));
                    }
                }
            });
    DisjointSets groups(c);
    for (const auto& [s, t] : links)
        groups.unite(s, t);
    std::vector<std::uint32_t> members(c, 0);
    std::vector<std::uint8_t> group_anchored(c, 0);
    for (std::size_t s = 0; s < c; ++s)
    {
        const std::size_t root = groups.find(s);
        ++members[root];
        group_anchored[root] |= anchored[s];
    }
    // A group that cannot hold a neighbourhood of its own (at most k samples, k + 1 with the
    // sample itself in each row) and holds to nothing else.
    const std::size_t largest = neighbors.k - 1;
    std::vector<std::uint8_t> stray(c, 0);
    for (std::size_t s = 0; s < c; ++s)
    {
        const std::size_t root = groups.find(s);
        stray[s] = group_anchored[root] == 0 && members[root] <= largest ? 1 : 0;
    }
    // Unless it is part of a sheet: a sheet sampled sparsely beside a dense one (the far face of
    // a thin part scanned from one side) has rows full of the dense sheet's samples, which its
    // links cannot reach, and its samples hold each other only at their own spacing. Such
    // samples hold together when their gap is at most the factor times the shorter of their
    // spacings among themselves (the distance to the seventh nearest other); a sheet makes a
    // large whole of them, stray groups a few of them at most.
    std::vector<std::uint32_t> strays;
    for (std::size_t s = 0; s < c; ++s)
        if (stray[s] != 0)
            strays.push_back(static_cast<std::uint32_t>(s));
    if (strays.size() > largest)
    {
        std::vector<Vec3f> at(strays.size());
        for (std::size_t u = 0; u < strays.size(); ++u)
            at[u] = positions[candidates[strays[u]]];
        const KdTree tree(at);
        const KnnTable near = knn_batch(tree, at, std::min<std::size_t>(8, strays.size()));
        DisjointSets wholes(strays.size());
        for (std::size_t u = 0; u < strays.size(); ++u)
            for (const std::uint32_t w : near.neighbors(u))
                if (w != u && (at[w] - at[u]).squaredNorm() <=
                                  factor2 * std::min(near.farthest2(u), near.farthest2(w)))
                    wholes.unite(u, w);
        std::vector<std::uint32_t> size(strays.size(), 0);
        for (std::size_t u = 0; u < strays.size(); ++u)
            ++size[wholes.find(u)];
        for (std::size_t u = 0; u < strays.size(); ++u)
            if (size[wholes.find(u)] > sheet_samples)
                stray[strays[u]] = 0;
    }
    std::vector<std::uint32_t> isolated;
    for (std::size_t s = 0; s < c; ++s)
        if (stray[s] != 0)
            isolated.push_back(candidates[s]);
    return isolated;
}

RadiusSummary summarize_radii(std::span<const float> radii)
{
    const std::size_t n = radii.size();
    if (n == 0)
        throw InvalidInput("summarize_radii: no radii");
    // Unsigned keys in the order of the values: the sign bit set on positive values, every bit
    // flipped on negative ones.
    const auto key_of = [](float value) {
        const auto bits = std::bit_cast<std::uint32_t>(value);
        return (bits & 0x80000000U) != 0 ? ~bits : bits | 0x80000000U;
    };
    const auto value_of = [](std::uint32_t key) {
        return std::bit_cast<float>((key & 0x80000000U) != 0 ? key & 0x7FFFFFFFU : ~key);
    };
    constexpr unsigned low_bits = 16;
    constexpr std::size_t buckets = std::size_t{1} << (32 - low_bits);
    // Blocks of at least a million values, at most 64 of them (their counts are 256 kB each).
    const std::size_t block = std::max<std::size_t>(std::size_t{1} << 20, (n + 63) / 64);
    const std::size_t blocks = (n + block - 1) / block;
    std::vector<std::uint32_t> counts(blocks * buckets, 0);
    std::vector<std::uint32_t> lowest(blocks);
    std::vector<std::uint32_t> highest(blocks);
    std::vector<std::uint8_t> has_nan(blocks, 0);
    parallel_blocks(n, block, [&](std::size_t begin, std::size_t end) {
        const std::size_t b = begin / block;
        std::uint32_t* count = counts.data() + b * buckets;
        std::uint32_t lo = std::numeric_limits<std::uint32_t>::max();
        std::uint32_t hi = 0;
        bool nan = false;
        for (std::size_t i = begin; i < end; ++i)
        {
            nan = nan || std::isnan(radii[i]);
            const std::uint32_t key = key_of(radii[i]);
            ++count[key >> low_bits];
            lo = std::min(lo, key);
            hi = std::max(hi, key);
        }
        lowest[b] = lo;
        highest[b] = hi;
        has_nan[b] = nan ? 1 : 0;
    });
    if (std::find(has_nan.begin(), has_nan.end(), 1) != has_nan.end())
        throw InvalidInput("summarize_radii: a radius is NaN");
    // The bucket that holds the value at n / 2, and that value's place in it.
    const std::size_t rank = n / 2;
    std::size_t below = 0;
    std::uint32_t middle = 0;
    for (std::size_t bucket = 0; bucket < buckets; ++bucket)
    {
        std::size_t count = 0;
        for (std::size_t b = 0; b < blocks; ++b)
            count += counts[b * buckets + bucket];
        if (below + count > rank)
        {
            middle = static_cast<std::uint32_t>(bucket);
            break;
        }
        below += count;
    }
    std::vector<std::uint32_t> keys = parallel_collect<std::uint32_t>(
        n, block, [&](std::size_t begin, std::size_t end, std::vector<std::uint32_t>& inside) {
            inside.reserve(counts[(begin / block) * buckets + middle]);
            for (std::size_t i = begin; i < end; ++i)
            {
                const std::uint32_t key = key_of(radii[i]);
                if (key >> low_bits == middle)
                    inside.push_back(key);
            }
        });
    const auto at = keys.begin() + static_cast<std::ptrdiff_t>(rank - below);
    std::nth_element(keys.begin(), at, keys.end());
    return {.min = value_of(*std::min_element(lowest.begin(), lowest.end())),
            .median = value_of(*at),
            .max = value_of(*std::max_element(highest.begin(), highest.end()))};
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
