// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// surfels_from_samples() and surfels_from_mesh(): the one way from samples of any kind, or from
// a mesh, to the surfels of a field.

#include "pointform/core/error.h"
#include "pointform/hermite/radius.h"
#include "pointform/hermite/scatter.h"
#include "pointform/hermite/surfels.h"
#include "pointform/metrics/surface_sampling.h"
#include "pointform/spatial/kd_tree.h"
#include "pointform/spatial/spatial_sort.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <string>
#include <utility>

namespace pointform {
namespace {

/// Removes the samples without a usable normal (zero or not finite): they carry no plane.
/// \return how many were removed
std::size_t drop_unoriented(PointCloud& cloud)
{
    std::vector<std::uint8_t> usable(cloud.size());
    for (std::size_t i = 0; i < cloud.size(); ++i)
    {
        const float norm = cloud.normals[i].norm();
        usable[i] = norm > 0.5F && std::isfinite(norm) ? 1 : 0;
    }
    return keep_points(cloud, usable);
}

void check_radius_scale(double scale)
{
    if (!(scale > 0.0) || !std::isfinite(scale))
        throw InvalidInput("radius scale must be positive and finite");
}

/// Removes the samples at `indices` (ascending). \return how many were removed
std::size_t drop_samples(PointCloud& cloud, std::span<const std::uint32_t> indices)
{
    if (indices.empty())
        return 0;
    std::vector<std::uint8_t> keep(cloud.size(), 1);
    for (const std::uint32_t i : indices)
        keep[i] = 0;
    return keep_points(cloud, keep);
}

/// Each point's k nearest (itself included) with only the farthest distance: what the
/// automatic radii (influence_radii()) and the isolated samples (isolated_samples()) read.
KnnTable reach_table(const PointCloudView& cloud, std::size_t k)
{
    const KdTree tree(cloud.positions);
    return knn_batch(tree, cloud.positions, k + 1, {.farthest_distance_only = true});
}

} // namespace

SurfelsFromSamples surfels_from_samples(const PointCloudView& samples,
                                        const SurfelsFromSamplesOptions& options)
{
    check_radius_scale(options.radius_scale);
    SurfelsFromSamples out;
    if (!samples.has_normals() || options.reestimate)
    {
        PointCloudView raw = samples;
        raw.normals = {};
        raw.radii = {};
        SurfelResult result = compute_surfels(raw, {.k = options.k,
                                                    .orient = options.orient,
                                                    .orient_target = options.orient_target,
                                                    .radius_scale = options.radius_scale,
                                                    .radius_regions = options.radius_regions,
                                                    .sharp_creases = options.sharp_creases,
                                                    .off_surface = !options.keep_off_surface,
                                                    .progress = options.progress});
        out.surfels = std::move(result.surfels);
        out.estimated_normals = true;
        out.estimated_radii = true;
        out.components = result.orientation.components;
        out.crease_refits = result.crease_refits;
        out.towards_sensor = result.towards_sensor;
        out.flipped = result.orientation.flipped;
        out.thin_parts = result.orientation.thin_parts;
        out.thin_part_turned = result.orientation.thin_part_turned;
        out.degenerate = result.degenerate;
        out.unoriented = result.orientation.unoriented.size();
        // The isolated samples, those off the surface and the copies first (their indices are
        // the input's), then the unoriented.
        std::vector<std::uint32_t> apart;
        std::set_union(result.isolated.begin(), result.isolated.end(), result.off_surface.begin(),
                       result.off_surface.end(), std::back_inserter(apart));
        std::vector<std::uint32_t> left_out;
        std::set_union(apart.begin(), apart.end(), result.copies.begin(), result.copies.end(),
                       std::back_inserter(left_out));
        out.copies = result.copies.size();
        out.isolated = result.isolated.size();
        out.off_surface = apart.size() - result.isolated.size();
        drop_samples(out.surfels, left_out);
        drop_unoriented(out.surfels);
        return out;
    }
    check_surfel_input(samples, options.k);
    out.surfels = to_point_cloud(samples);
    out.unoriented = drop_unoriented(out.surfels);
    PointCloud& surfels = out.surfels;
    if (surfels.size() <= options.k)
        throw InvalidInput(std::to_string(out.unoriented) +
                           " samples have a zero or non-finite normal, and too few usable ones "
                           "are left; orient the samples (pointform normals) or estimate their "
                           "normals again (--reestimate)");
    if (!surfels.has_radii())
    {
        // Samples at one place are one surfel (the first of them, with its normal).
        std::vector<CoincidentCopy> found;
        (void)spatial_order(surfels.positions, found);
        if (!found.empty())
        {
            std::vector<std::uint32_t> copies(found.size());
            for (std::size_t c = 0; c < found.size(); ++c)
                copies[c] = found[c].copy;
            out.copies = drop_samples(surfels, copies);
            if (surfels.size() <= options.k)
                throw InvalidInput("only " + std::to_string(surfels.size()) +
                                   " distinct samples with usable normals (the others repeat "
                                   "their coordinates), fewer than k + 1 = " +
                                   std::to_string(options.k + 1));
        }
        const KnnTable reach = reach_table(surfels, options.k);
        surfels.radii = apply_radius_regions(surfels.positions, surfels.origin,
                                             influence_radii(reach, options.radius_scale),
                                             options.radius_regions);
        out.estimated_radii = true;
        const std::vector<std::uint32_t> isolated = isolated_samples(surfels.positions, reach);
        const std::vector<std::uint32_t> off_surface =
            options.keep_off_surface ? std::vector<std::uint32_t>()
                                     : off_surface_samples(surfels.positions, reach);
        std::vector<std::uint32_t> apart;
        std::set_union(isolated.begin(), isolated.end(), off_surface.begin(), off_surface.end(),
                       std::back_inserter(apart));
        out.isolated = isolated.size();
        out.off_surface = apart.size() - isolated.size();
        drop_samples(surfels, apart);
    }
    return out;
}

SurfelsFromMesh surfels_from_mesh(const TriMesh& mesh, const SurfelsFromMeshOptions& options)
{
    check_radius_scale(options.radius_scale);
    if (options.k < 3)
        throw InvalidInput("surfels from a mesh: k must be at least 3, not " +
                           std::to_string(options.k));
    const std::size_t count = options.samples > 0 ? options.samples : mesh.vertex_count();
    // The vertices first, with their area-weighted normals; then the area-uniform samples.
    PointCloud vertices = sample_surface(
        mesh, {.count = 0, .seed = options.seed, .include_vertices = true, .normals = true});
    PointCloud area = sample_surface(mesh, {.count = count, .seed = options.seed, .normals = true});
    SurfelsFromMesh out;
    out.surfels.origin = mesh.vertices.origin;
    drop_unoriented(vertices);
    out.vertex_surfels = vertices.size();
    out.area_surfels = area.size();
    out.surfels.positions = std::move(vertices.positions);
    out.surfels.normals = std::move(vertices.normals);
    out.surfels.positions.insert(out.surfels.positions.end(), area.positions.begin(),
                                 area.positions.end());
    out.surfels.normals.insert(out.surfels.normals.end(), area.normals.begin(), area.normals.end());
    if (out.surfels.size() <= options.k)
        throw InvalidInput("surfels from a mesh: too few vertices and samples (" +
                           std::to_string(out.surfels.size()) +
                           ") for k = " + std::to_string(options.k));
    out.surfels.radii = influence_radii(reach_table(out.surfels, options.k), options.radius_scale);
    return out;
}

} // namespace pointform
