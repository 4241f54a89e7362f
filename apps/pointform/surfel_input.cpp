// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "surfel_input.h"

#include "pointform/core/error.h"
#include "pointform/hermite/radius.h"
#include "pointform/io/io.h"
#include "pointform/spatial/kd_tree.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace pointform::cli {

namespace {

/// Removes samples without a usable normal (zero or not finite): they carry no plane.
std::size_t drop_unoriented(PointCloud& cloud)
{
    std::size_t kept = 0;
    for (std::size_t i = 0; i < cloud.size(); ++i)
    {
        const float norm = cloud.normals[i].norm();
        if (!(norm > 0.5F) || !std::isfinite(norm))
        {
            continue;
        }
        cloud.positions[kept] = cloud.positions[i];
        cloud.normals[kept] = cloud.normals[i];
        if (cloud.has_colors())
        {
            cloud.colors[kept] = cloud.colors[i];
        }
        if (cloud.has_radii())
        {
            cloud.radii[kept] = cloud.radii[i];
        }
        ++kept;
    }
    const std::size_t dropped = cloud.size() - kept;
    cloud.positions.resize(kept);
    cloud.normals.resize(kept);
    if (cloud.has_colors())
    {
        cloud.colors.resize(kept);
    }
    if (cloud.has_radii())
    {
        cloud.radii.resize(kept);
    }
    return dropped;
}

} // namespace

void add_surfel_input_options(CLI::App& cmd, SurfelInputOptions& options)
{
    cmd.add_option("-k", options.k,
                   "Neighbours of each point, besides itself, for normals and the radius")
        ->capture_default_str()
        ->check(CLI::Range(3, 1000));
    cmd.add_option("--radius-scale", options.radius_scale,
                   "Factor on the automatic influence radius (distance to the k-th neighbour); "
                   "larger values close larger holes")
        ->capture_default_str()
        ->check(CLI::PositiveNumber);
    cmd.add_option("--radius-regions", options.radius_regions,
                   "JSON file of balls and boxes that set the radius (see `pointform normals`)");
    cmd.add_flag("--reestimate", options.reestimate,
                 "Estimate and orient normals even if the input has them");
}

SurfelInput load_surfels(const std::string& path, const SurfelInputOptions& options,
                         const ProgressCallback& progress)
{
    SurfelInput out;
    PointCloud cloud = read_point_cloud(path);
    std::vector<RadiusRegion> regions;
    if (!options.radius_regions.empty())
    {
        regions = read_radius_regions(options.radius_regions);
    }
    if (!cloud.has_normals() || options.reestimate)
    {
        cloud.normals.clear();
        cloud.radii.clear();
        SurfelOptions surfel_options{.k = options.k,
                                     .radius_scale = options.radius_scale,
                                     .radius_regions = regions,
                                     .progress = progress};
        SurfelResult result = compute_surfels(cloud, surfel_options);
        out.surfels = std::move(result.surfels);
        out.estimated_normals = true;
        out.estimated_radii = true;
        out.components = result.orientation.components;
        out.unoriented = result.orientation.unoriented.size();
        drop_unoriented(out.surfels);
        return out;
    }
    check_surfel_input(cloud, options.k);
    out.unoriented = drop_unoriented(cloud);
    if (cloud.size() <= options.k)
    {
        throw InvalidInput(path + ": " + std::to_string(out.unoriented) +
                           " samples have a zero or non-finite normal, and too few usable ones "
                           "are left; orient the samples (pointform normals) or pass "
                           "--reestimate");
    }
    if (!cloud.has_radii())
    {
        const KdTree tree(cloud.positions);
        const KnnTable knn = knn_batch(tree, cloud.positions, options.k + 1);
        cloud.radii = influence_radii(knn, options.radius_scale);
        cloud.radii =
            apply_radius_regions(cloud.positions, cloud.origin, std::move(cloud.radii), regions);
        out.estimated_radii = true;
    }
    out.surfels = std::move(cloud);
    return out;
}

void warn_unoriented(const std::string& path, std::size_t unoriented)
{
    if (unoriented > 0)
    {
        std::fprintf(stderr, "pointform: warning: %s: %zu samples without a normal were left out\n",
                     path.c_str(), unoriented);
    }
}

} // namespace pointform::cli
