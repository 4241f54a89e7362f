// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/hermite/surfels.h"

#include "pointform/core/error.h"
#include "pointform/core/parallel.h"
#include "pointform/hermite/normals.h"
#include "pointform/spatial/kd_tree.h"
#include "pointform/spatial/spatial_sort.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>

namespace pointform {
namespace {

/// Second-largest over largest eigenvalue of the whole cloud's covariance below which all points
/// are taken to lie on one line. Relative, so unit-free; float storage noise is about 1e-14.
constexpr double global_collinear_ratio = 1e-12;

/// Samples a block when the cloud is put into Morton order and back.
constexpr std::size_t gather_block = 1U << 16U;

class StageTimer
{
public:
    explicit StageTimer(std::vector<std::pair<std::string, double>>& log) : log_(log) {}

    void lap(const std::string& stage)
    {
        const auto now = std::chrono::steady_clock::now();
        log_.emplace_back(stage, std::chrono::duration<double>(now - last_).count());
        last_ = now;
    }

private:
    std::vector<std::pair<std::string, double>>& log_;
    std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

} // namespace

void check_surfel_input(const PointCloudView& cloud, std::size_t k)
{
    validate(cloud);
    if (k < 3)
        throw InvalidInput("k = " + std::to_string(k) +
                           " is too small: a tangent plane needs at least 3 neighbours");
    if (cloud.size() <= k)
        throw InvalidInput("only " + std::to_string(cloud.size()) + " points, fewer than k + 1 = " +
                           std::to_string(k + 1) + " (a point and its k neighbours)");
    for (std::size_t i = 0; i < cloud.size(); ++i)
        if (!cloud.positions[i].allFinite())
            throw InvalidInput("point " + std::to_string(i) + " has a NaN or infinite coordinate");

    Vec3d mean = Vec3d::Zero();
    for (const auto& p : cloud.positions)
        mean += p.cast<double>();
    mean /= static_cast<double>(cloud.size());
    Mat3d covariance = Mat3d::Zero();
    for (const auto& p : cloud.positions)
    {
        const Vec3d d = p.cast<double>() - mean;
        covariance.noalias() += d * d.transpose();
    }
    const Eigen::SelfAdjointEigenSolver<Mat3d> solver(covariance, Eigen::EigenvaluesOnly);
    const Vec3d& lambda = solver.eigenvalues();
    if (!(lambda[2] > 0.0))
        throw InvalidInput("all " + std::to_string(cloud.size()) +
                           " points coincide: no surface to estimate");
    if (lambda[1] <= global_collinear_ratio * lambda[2])
        throw InvalidInput("all points lie on one line: no surface normal is defined");
}

SurfelResult compute_surfels(const PointCloudView& cloud, const SurfelOptions& options)
{
    check_surfel_input(cloud, options.k);
    if (!(options.radius_scale > 0.0) || !std::isfinite(options.radius_scale))
        throw InvalidInput("radius scale must be positive and finite");

    SurfelResult result;
    StageTimer timer(result.stage_seconds);
    const std::size_t n = cloud.size();

    // Work on the points in Morton order, so that neighbours are close in memory; map back at
    // the end. The order depends only on the positions, so results do not depend on threads.
    const std::vector<std::uint32_t> order = spatial_order(cloud.positions);
    std::vector<Vec3f> sorted(n);
    parallel_blocks(n, gather_block, [&](std::size_t begin, std::size_t end) {
        for (std::size_t j = begin; j < end; ++j)
            sorted[j] = cloud.positions[order[j]];
    });
    const std::span<const Vec3f> positions = sorted;
    timer.lap("spatial sort");

    // Only the k-th distance is needed (radii, the orientation's flux); the tree goes once the
    // table is made.
    KnnTable table;
    {
        const KdTree tree(positions);
        timer.lap("kd-tree");
        table = knn_batch(tree, positions, options.k + 1,
                          {.farthest_distance_only = true, .progress = options.progress});
    }
    timer.lap("knn");
    Normals normals = estimate_normals(positions, table, options.progress);
    result.degenerate = normals.degenerate.size();
    timer.lap("normals");

    OrientedNormals oriented;
    switch (options.orient)
    {
        case OrientMode::Mst:
        case OrientMode::Flip:
        {
            const std::size_t graph_k =
                options.graph_k == 0 ? std::min<std::size_t>(options.k, 10) : options.graph_k;
            oriented = orient_normals_mst(
                positions, normals.normals, table,
                {.k = graph_k, .rule = options.rule, .progress = options.progress});
            if (options.orient == OrientMode::Flip)
            {
                OrientedNormals flipped = flip_normals(oriented.normals);
                oriented.normals = std::move(flipped.normals);
                oriented.flipped = n - oriented.flipped;
            }
            break;
        }
        case OrientMode::None:
            oriented.normals = normals.normals;
            break;
        case OrientMode::Towards:
            oriented = orient_normals_towards(positions, normals.normals,
                                              options.orient_target - cloud.origin);
            break;
        case OrientMode::Along:
            oriented = orient_normals_along(normals.normals, options.orient_target);
            break;
    }
    timer.lap("orientation");

    std::vector<float> radii = influence_radii(table, options.radius_scale);
    radii = apply_radius_regions(positions, cloud.origin, std::move(radii), options.radius_regions);
    timer.lap("radius");

    // Back to the input order.
    result.surfels.origin = cloud.origin;
    result.surfels.positions.assign(cloud.positions.begin(), cloud.positions.end());
    result.surfels.colors.assign(cloud.colors.begin(), cloud.colors.end());
    result.surfels.normals.resize(n);
    result.surfels.radii.resize(n);
    parallel_blocks(n, gather_block, [&](std::size_t begin, std::size_t end) {
        for (std::size_t j = begin; j < end; ++j)
        {
            result.surfels.normals[order[j]] = oriented.normals[j];
            result.surfels.radii[order[j]] = radii[j];
        }
    });
    result.orientation = std::move(oriented);
    result.orientation.normals = result.surfels.normals;
    for (auto& index : result.orientation.unoriented)
        index = order[index];
    std::sort(result.orientation.unoriented.begin(), result.orientation.unoriented.end());
    return result;
}

} // namespace pointform
