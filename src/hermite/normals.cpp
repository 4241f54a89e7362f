// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/hermite/normals.h"

#include "pointform/core/error.h"
#include "pointform/core/parallel.h"
#include "pointform/spatial/kd_tree.h"

#include <Eigen/Eigenvalues>

#include <string>

namespace pointform {
namespace {

/// Below this ratio λ1/λ2 the neighbourhood is taken as a line (or a point): its normal is
/// undefined. Relative, so independent of units.
constexpr double collinear_ratio = 1e-10;

/// fit_plane() on indices known to be in range (a checked neighbour table), at least one.
LocalPlane fit_unchecked(std::span<const Vec3f> positions, std::span<const std::uint32_t> indices)
{
    LocalPlane fit;
    // Shift by the first point so the sums do not lose precision far from the origin.
    const Vec3d shift = positions[indices[0]].cast<double>();
    Vec3d sum = Vec3d::Zero();
    Mat3d outer = Mat3d::Zero();
    for (const auto index : indices)
    {
        const Vec3d p = positions[index].cast<double>() - shift;
        sum += p;
        outer.noalias() += p * p.transpose();
    }
    const double count = static_cast<double>(indices.size());
    const Vec3d mean = sum / count;
    const Mat3d covariance = outer / count - mean * mean.transpose();
    fit.centroid = mean + shift;

    Eigen::SelfAdjointEigenSolver<Mat3d> solver;
    solver.computeDirect(covariance);
    fit.eigenvalues = solver.eigenvalues().cwiseMax(0.0);
    const double largest = fit.eigenvalues[2];
    fit.degenerate = !(largest > 0.0) || fit.eigenvalues[1] <= collinear_ratio * largest ||
                     !solver.eigenvectors().allFinite();
    if (!fit.degenerate)
        fit.normal = solver.eigenvectors().col(0).normalized();
    return fit;
}

} // namespace

LocalPlane fit_plane(std::span<const Vec3f> positions, std::span<const std::uint32_t> indices)
{
    if (indices.empty())
        throw InvalidInput("fit_plane: no indices");
    for (const std::uint32_t index : indices)
        if (index >= positions.size())
            throw InvalidInput("fit_plane: index " + std::to_string(index) +
                               " is out of range for " + std::to_string(positions.size()) +
                               " points");
    return fit_unchecked(positions, indices);
}

Normals estimate_normals(std::span<const Vec3f> positions, const KnnTable& neighbors,
                         const ProgressCallback& progress)
{
    // The rows' indices are checked below as each fit reads them.
    check_knn_table_shape(neighbors, positions.size(), "estimate_normals");
    Normals result;
    result.normals.resize(positions.size());
    std::vector<std::uint8_t> degenerate(positions.size(), 0);
    ProgressReporter reporter(progress, "normals");
    parallel_blocks(
        positions.size(), 4096,
        [&](std::size_t begin, std::size_t end) {
            for (std::size_t i = begin; i < end; ++i)
            {
                const std::span<const std::uint32_t> row = neighbors.neighbors(i);
                for (const std::uint32_t index : row)
                    if (index >= positions.size())
                        throw InvalidInput("estimate_normals: neighbour " + std::to_string(index) +
                                           " of row " + std::to_string(i) +
                                           " is out of range for " +
                                           std::to_string(positions.size()) + " points");
                const LocalPlane fit = fit_unchecked(positions, row);
                result.normals[i] = fit.normal.cast<float>();
                degenerate[i] = fit.degenerate ? 1 : 0;
            }
        },
        &reporter);
    reporter.finish();
    for (std::size_t i = 0; i < degenerate.size(); ++i)
        if (degenerate[i] != 0)
            result.degenerate.push_back(static_cast<std::uint32_t>(i));
    return result;
}

Normals estimate_normals(std::span<const Vec3f> positions, const NormalOptions& options)
{
    if (options.k < 3)
        throw InvalidInput("estimate_normals: k = " + std::to_string(options.k) +
                           " is too small; a plane needs at least 3 neighbours");
    if (positions.size() <= options.k)
        throw InvalidInput("estimate_normals: " + std::to_string(positions.size()) +
                           " points are fewer than k + 1 = " + std::to_string(options.k + 1));
    const KdTree tree(positions);
    const KnnTable table =
        knn_batch(tree, positions, options.k + 1, {.progress = options.progress});
    return estimate_normals(positions, table, options.progress);
}

} // namespace pointform
