// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/multires/export.h"

#include "pointform/core/error.h"
#include "pointform/multires/level_of_detail.h"

#include <algorithm>
#include <charconv>
#include <string>

namespace pointform {

TexturedMesh level_chain(const MultiresMesh& mesh, std::span<const std::size_t> levels)
{
    check_levels(mesh, levels);
    TexturedMesh out;
    out.origin = mesh.origin();
    const std::size_t finest = levels.back();
    const std::size_t vertex_count = mesh.vertex_count(finest);
    const std::span<const Vec3d> positions = mesh.positions().first(vertex_count);
    out.positions.reserve(vertex_count);
    for (const Vec3d& p : positions)
        out.positions.push_back(p.cast<float>());
    out.lods.reserve(levels.size());
    for (const std::size_t level : levels)
    {
        out.lods.push_back(mesh.faces(level));
        out.lod_vertex_counts.push_back(mesh.vertex_count(level));
        out.lod_levels.push_back(level);
    }
    for (const Vec3d& n : vertex_normals(positions, out.lods.back(), vertex_count))
        out.normals.push_back(n.cast<float>());
    return out;
}

std::vector<std::size_t> parse_level_list(std::string_view text, std::size_t level_count)
{
    std::vector<std::size_t> levels;
    if (text == "all")
    {
        for (std::size_t level = 0; level < level_count; ++level)
            levels.push_back(level);
        if (levels.empty())
            throw InvalidInput("--levels all: the hierarchy has no levels");
        return levels;
    }
    const std::string quoted = "--levels '" + std::string(text) + "': ";
    if (text.empty())
        throw InvalidInput(quoted + "expected 'all' or level numbers separated by commas");
    std::size_t start = 0;
    while (start <= text.size())
    {
        const std::size_t comma = std::min(text.find(',', start), text.size());
        const std::string_view entry = text.substr(start, comma - start);
        std::size_t level = 0;
        const auto [end, error] = std::from_chars(entry.data(), entry.data() + entry.size(), level);
        if (entry.empty() || error != std::errc() || end != entry.data() + entry.size())
            throw InvalidInput(quoted + "'" + std::string(entry) +
                               "' is not a level number (expected 'all' or level numbers "
                               "separated by commas, such as 0,2,4)");
        if (level >= level_count)
            throw InvalidInput(quoted + "level " + std::to_string(level) +
                               " does not exist: the hierarchy has " + std::to_string(level_count) +
                               " levels (0 to " +
                               std::to_string(level_count == 0 ? 0 : level_count - 1) + ")");
        if (!levels.empty() && level <= levels.back())
            throw InvalidInput(quoted +
                               (level == levels.back()
                                    ? "level " + std::to_string(level) + " is named twice"
                                    : "level " + std::to_string(level) + " follows level " +
                                          std::to_string(levels.back()) +
                                          "; list levels in increasing order"));
        levels.push_back(level);
        start = comma + 1;
    }
    return levels;
}

} // namespace pointform
