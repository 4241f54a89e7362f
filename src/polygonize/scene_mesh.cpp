// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/polygonize/scene_mesh.h"

#include "pointform/core/error.h"
#include "pointform/core/memory.h"

#include <algorithm>
#include <chrono>
#include <cstdio>

namespace pointform {

SceneGrid choose_scene_grid(const Aabb& field_bounds, const SceneGridOptions& options,
                            std::span<const LoadedScan> scans)
{
    SceneGrid out;
    out.box = options.bounds ? *options.bounds : field_bounds;
    if (out.box.is_empty())
        throw InvalidInput(
            "the scene is empty: its bounds are empty (an intersection of shapes "
            "that do not overlap?)");
    if (!out.box.min.allFinite() || !out.box.max.allFinite())
        throw InvalidInput(
            "the scene is unbounded (a half_space that is not intersected with a "
            "bounded shape): pass --bounds xmin,ymin,zmin,xmax,ymax,zmax, or "
            "intersect it with a bounded shape");
    if (options.cell > 0.0)
    {
        out.cell = options.cell;
    }
    else if (options.resolution > 0)
    {
        out.cell = cell_for_resolution(out.box, options.resolution);
    }
    else if (!scans.empty())
    {
        out.cell = default_cell_size(*scans.front().field);
        for (const LoadedScan& scan : scans)
            out.cell = std::min(out.cell, default_cell_size(*scan.field));
    }
    else
    {
        out.cell = cell_for_resolution(out.box, 128);
    }
    out.grid = grid_over(out.box, out.cell);
    for (const LoadedScan& scan : scans)
        check_marching_cubes_memory(*scan.field, out.cell);
    if (scans.empty())
    {
        // Primitives alone: a convex surface inside the box has at most the box's area, so
        // take that as the surface the grid follows.
        const Vec3d size = out.box.size();
        const double area = 2.0 * (size.x() * size.y() + size.y() * size.z() + size.z() * size.x());
        char what[96];
        std::snprintf(what, sizeof what, "marching cubes of the scene at a cell of %g", out.cell);
        check_memory(estimate_marching_cubes_bytes(area, out.cell), what,
                     "use a larger --cell or a lower --resolution");
    }
    return out;
}

SceneMeshReport scene_mesh(const Field& field, std::span<const LoadedScan> scans,
                           const SceneMeshOptions& options)
{
    SceneMeshReport report;
    const auto start = std::chrono::steady_clock::now();
    report.grid = choose_scene_grid(field.bounds(), options.grid, scans);
    report.marching_cubes = marching_cubes(field, report.grid.grid, {.progress = options.progress});
    report.stage_seconds.emplace_back(
        "marching cubes",
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    if (report.marching_cubes.mesh.face_count() == 0)
        throw Error(
            "marching cubes made no triangles: the scene's surface does not cross the "
            "polygonized box, or the field is undefined there (check --bounds, try a "
            "smaller --cell or a larger --radius-scale)");
    if (!options.semi_regular)
        return report;
    SemiRegularOptions semi_regular = *options.semi_regular;
    if (!semi_regular.levels)
        semi_regular.levels = default_scene_levels;
    report.semi_regular =
        semi_regular_mesh(report.marching_cubes.mesh, field, nullptr, semi_regular,
                          default_scene_base_share, options.progress);
    const MultiresMesh& hierarchy = report.semi_regular->hierarchy;
    report.finest = hierarchy.level_mesh(hierarchy.finest_level());
    report.residual = field_residual_at_vertices(report.finest, field);
    report.stage_seconds.insert(report.stage_seconds.end(),
                                report.semi_regular->stage_seconds.begin(),
                                report.semi_regular->stage_seconds.end());
    return report;
}

} // namespace pointform
