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

void check_levels(const MultiresMesh& mesh, std::span<const std::size_t> levels)
{
    if (levels.empty())
        throw InvalidInput("no levels chosen: at least one is needed");
    for (std::size_t k = 0; k < levels.size(); ++k)
    {
        check_level(mesh, levels[k]);
        if (k > 0 && levels[k] <= levels[k - 1])
            throw InvalidInput("levels must be strictly increasing, but level " +
                               std::to_string(levels[k]) + " follows level " +
                               std::to_string(levels[k - 1]));
    }
}

std::vector<Vec3d> vertex_normals(std::span<const Vec3d> positions, std::span<const Triangle> faces,
                                  std::size_t vertex_count)
{
    std::vector<Vec3d> normals(vertex_count, Vec3d::Zero());
    Vec3d total = Vec3d::Zero();
    for (const Triangle& t : faces)
    {
        // |cross| is twice the area: summing crosses weights each face normal by its area.
        const Vec3d cross =
            (positions[t[1]] - positions[t[0]]).cross(positions[t[2]] - positions[t[0]]);
        for (const std::uint32_t v : t)
            normals[v] += cross;
        total += cross;
    }
    const Vec3d fallback = total.norm() > 0.0 ? Vec3d(total.normalized()) : Vec3d::UnitZ();
    for (Vec3d& n : normals)
    {
        const double length = n.norm();
        n = length > 0.0 ? Vec3d(n / length) : fallback;
    }
    return normals;
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
