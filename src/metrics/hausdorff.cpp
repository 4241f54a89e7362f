// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/metrics/hausdorff.h"

#include "pointform/core/error.h"
#include "pointform/core/parallel.h"
#include "pointform/metrics/surface_sampling.h"
#include "pointform/spatial/kd_tree.h"
#include "pointform/spatial/triangle_bvh.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace pointform {
namespace {

constexpr std::size_t query_block = 2048;

void check_finite(const PointCloudView& cloud, const char* what)
{
    if (!cloud.origin.allFinite())
        throw InvalidInput(std::string(what) + ": the origin is not finite");
    for (std::size_t i = 0; i < cloud.size(); ++i)
        if (!cloud.positions[i].allFinite())
            throw InvalidInput(std::string(what) + ": point " + std::to_string(i) +
                               " has a non-finite coordinate");
}

/// Percentile q in [0, 1] of sorted values, interpolating between neighbouring ranks.
double percentile(const std::vector<double>& sorted, double q)
{
    const double position = q * static_cast<double>(sorted.size() - 1);
    const auto lo = static_cast<std::size_t>(std::floor(position));
    const std::size_t hi = std::min(lo + 1, sorted.size() - 1);
    const double t = position - static_cast<double>(lo);
    return sorted[lo] + t * (sorted[hi] - sorted[lo]);
}

/// The points a shape is measured by: a surface's samples (made into `storage`), or a point set
/// itself.
PointCloudView samples_of(const ShapeRef& shape, std::size_t count, std::uint64_t seed,
                          bool include_vertices, const char* name, PointCloud& storage)
{
    if (shape.points.empty())
        throw InvalidInput(std::string("compare: ") + name + " has no points");
    if (shape.mesh == nullptr)
    {
        check_finite(shape.points, name);
        PointCloudView points;
        points.origin = shape.points.origin;
        points.positions = shape.points.positions;
        return points;
    }
    if (count == 0 && !include_vertices)
        throw InvalidInput(std::string("compare: ") + name +
                           " is a mesh and would get no samples (0 samples, no vertices)");
    storage = sample_surface(*shape.mesh,
                             {.count = count, .seed = seed, .include_vertices = include_vertices});
    return storage;
}

std::vector<double> distances_to_shape(const PointCloudView& points, const ShapeRef& shape,
                                       const ProgressCallback& progress)
{
    if (shape.mesh != nullptr)
        return distances_to_mesh(points, *shape.mesh, {.progress = progress});
    return distances_to_points(points, shape.points, {.progress = progress});
}

DistanceSummary summary_of(const std::vector<double>& a_to_b, const std::vector<double>& b_to_a)
{
    DistanceSummary s;
    s.a_to_b = summarize_distances(a_to_b);
    s.b_to_a = summarize_distances(b_to_a);
    std::vector<double> both;
    both.reserve(a_to_b.size() + b_to_a.size());
    both.insert(both.end(), a_to_b.begin(), a_to_b.end());
    both.insert(both.end(), b_to_a.begin(), b_to_a.end());
    s.symmetric = summarize_distances(both);
    s.hausdorff = std::max(s.a_to_b.max, s.b_to_a.max);
    s.chamfer = s.a_to_b.mean + s.b_to_a.mean;
    return s;
}

} // namespace

std::vector<double> distances_to_mesh(const PointCloudView& points, const TriMesh& mesh,
                                      const DistanceOptions& options)
{
    check_finite(points, "point-to-mesh distance");
    check_query_work(mesh, points.size(), "point-to-mesh distance");
    const TriangleBvh bvh(mesh);
    return distances_to_mesh(bvh, points, {.progress = options.progress});
}

std::vector<double> distances_to_points(const PointCloudView& points, const PointCloudView& targets,
                                        const DistanceOptions& options)
{
    if (targets.empty())
        throw InvalidInput("point-to-point distance: the target point set is empty");
    check_finite(points, "point-to-point distance");
    check_finite(targets, "point-to-point distance (targets)");
    const KdTree tree(targets.positions);
    const Vec3d shift = points.origin - targets.origin;
    std::vector<double> distances(points.size());
    ProgressReporter progress(options.progress, "point-to-point distance");
    parallel_blocks(
        points.size(), query_block,
        [&](std::size_t begin, std::size_t end) {
            for (std::size_t i = begin; i < end; ++i)
            {
                const Vec3d local = shift + points.positions[i].cast<double>();
                const PointId nearest = tree.nearest(local.cast<float>());
                distances[i] = (local - targets.positions[nearest.value].cast<double>()).norm();
            }
        },
        &progress);
    progress.finish();
    return distances;
}

DistanceStats summarize_distances(std::span<const double> distances)
{
    if (distances.empty())
        throw InvalidInput("distance statistics: no distances");
    std::vector<double> sorted(distances.begin(), distances.end());
    for (const double d : sorted)
        if (!(d >= 0.0) || !std::isfinite(d))
            throw InvalidInput("distance statistics: a distance is negative or not finite");
    std::sort(sorted.begin(), sorted.end());
    double sum = 0.0;
    double sum2 = 0.0;
    for (const double d : sorted)
    {
        sum += d;
        sum2 += d * d;
    }
    const auto n = static_cast<double>(sorted.size());
    DistanceStats stats;
    stats.count = sorted.size();
    stats.min = sorted.front();
    stats.max = sorted.back();
    stats.mean = sum / n;
    stats.rms = std::sqrt(sum2 / n);
    stats.p50 = percentile(sorted, 0.50);
    stats.p90 = percentile(sorted, 0.90);
    stats.p99 = percentile(sorted, 0.99);
    return stats;
}

DistanceStats scaled(const DistanceStats& stats, double factor)
{
    DistanceStats s = stats;
    for (double* v : {&s.min, &s.max, &s.mean, &s.rms, &s.p50, &s.p90, &s.p99})
        *v *= factor;
    return s;
}

DistanceComparison compare(const ShapeRef& a, const ShapeRef& b, const CompareOptions& options)
{
    for (const double tau : options.fscore_thresholds)
        if (!(tau > 0.0 && std::isfinite(tau)))
            throw InvalidInput("F-score threshold must be positive and finite, got " +
                               std::to_string(tau));
    PointCloud storage_a;
    PointCloud storage_b;
    const PointCloudView samples_a =
        samples_of(a, options.samples, options.seed, options.include_vertices, "A", storage_a);
    const PointCloudView samples_b =
        samples_of(b, options.samples, options.seed ^ 0x5851F42D4C957F2DULL,
                   options.include_vertices, "B", storage_b);
    const std::vector<double> a_to_b = distances_to_shape(samples_a, b, options.progress);
    const std::vector<double> b_to_a = distances_to_shape(samples_b, a, options.progress);

    DistanceComparison result;
    result.absolute = summary_of(a_to_b, b_to_a);
    Aabb box = a.points.bounds();
    const Aabb box_b = b.points.bounds();
    box.extend(box_b.min);
    box.extend(box_b.max);
    result.diagonal = box.diagonal();
    const double factor = result.diagonal > 0.0 ? 1.0 / result.diagonal : 0.0;
    result.relative.a_to_b = scaled(result.absolute.a_to_b, factor);
    result.relative.b_to_a = scaled(result.absolute.b_to_a, factor);
    result.relative.symmetric = scaled(result.absolute.symmetric, factor);
    result.relative.hausdorff = result.absolute.hausdorff * factor;
    result.relative.chamfer = result.absolute.chamfer * factor;
    // The F-score's shares are of area: a mesh's area-uniform samples only (the first
    // options.samples; its vertices, added after them, measure its corners for the maxima but
    // would weigh the shares by vertex density). A point set counts every point.
    const auto area_samples = [&options](const ShapeRef& shape, const std::vector<double>& all) {
        const std::size_t count =
            shape.mesh != nullptr && options.samples > 0 ? options.samples : all.size();
        return std::span<const double>(all.data(), std::min(count, all.size()));
    };
    const std::span<const double> area_a_to_b = area_samples(a, a_to_b);
    const std::span<const double> area_b_to_a = area_samples(b, b_to_a);
    const auto share_within = [](std::span<const double> distances, double limit) {
        const auto within = std::count_if(distances.begin(), distances.end(),
                                          [limit](double d) { return d <= limit; });
        return static_cast<double>(within) / static_cast<double>(distances.size());
    };
    for (const double tau : options.fscore_thresholds)
    {
        FScore score;
        score.threshold = tau;
        score.absolute_threshold = tau * result.diagonal;
        score.precision = share_within(area_b_to_a, score.absolute_threshold);
        score.recall = share_within(area_a_to_b, score.absolute_threshold);
        const double sum = score.precision + score.recall;
        score.f = sum > 0.0 ? 2.0 * score.precision * score.recall / sum : 0.0;
        result.fscores.push_back(score);
    }
    return result;
}

std::size_t compare_sample_count(const ShapeRef& shape, std::size_t samples, bool include_vertices)
{
    if (shape.mesh == nullptr)
        return shape.points.size();
    if (!include_vertices)
        return samples;
    std::vector<bool> used(shape.mesh->vertex_count(), false);
    for (const Triangle& t : shape.mesh->triangles)
        for (const std::uint32_t v : t)
            used[v] = true;
    return samples + static_cast<std::size_t>(std::count(used.begin(), used.end(), true));
}

} // namespace pointform
