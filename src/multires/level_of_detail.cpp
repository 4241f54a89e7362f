// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/multires/level_of_detail.h"

#include "pointform/core/error.h"

namespace pointform {

void check_level(const MultiresMesh& mesh, std::size_t level)
{
    if (level < mesh.level_count())
        return;
    const std::size_t count = mesh.level_count();
    throw InvalidInput("level " + std::to_string(level) + " does not exist: the hierarchy has " +
                       std::to_string(count) +
                       (count == 0   ? " levels"
                        : count == 1 ? " level (level 0)"
                                     : " levels (0 to " + std::to_string(count - 1) + ")"));
}

LevelOfDetail extract_level(const MultiresMesh& mesh, std::size_t level)
{
    check_level(mesh, level);
    LevelOfDetail out;
    out.level = level;
    out.mesh = mesh.level_mesh(level);
    out.topology = analyze_topology(out.mesh);
    return out;
}

} // namespace pointform
