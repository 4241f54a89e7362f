// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include "pointform/core/progress.h"
#include "pointform/geometry/point_cloud.h"
#include "pointform/geometry/tri_mesh.h"

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace pointform {

/// \brief Options for the distance functions.
struct DistanceOptions
{
    /// Optional progress report, called from one thread.
    ProgressCallback progress;
};

/// \brief Exact distance from every point to a triangle mesh (closest point on a triangle, found
/// through a TriangleBvh), in parallel, in world units. Same result whatever the thread count.
/// \cite §5.2.4: the one-sided Hausdorff distance from the samples S to a mesh is the max.
/// \param points  N points (world = origin + position)
/// \param mesh    F >= 1 triangles; degenerate triangles count as their edges or point
/// \return N distances, in the order of the points
/// \throw InvalidInput if the mesh has no triangles, an index is out of range, or a coordinate is
///        not finite
[[nodiscard]] std::vector<double> distances_to_mesh(const PointCloudView& points,
                                                    const TriMesh& mesh,
                                                    const DistanceOptions& options = {});

/// \brief Distance from every point to the nearest point of `targets` (kd-tree), in parallel.
///
/// The nearest target is searched in float precision relative to the targets' origin; the
/// distance to it is then computed exactly in double, in world units.
/// \return points.size() distances, in the order of the points
/// \throw InvalidInput if targets is empty or a coordinate is not finite
[[nodiscard]] std::vector<double> distances_to_points(const PointCloudView& points,
                                                      const PointCloudView& targets,
                                                      const DistanceOptions& options = {});

/// \brief Summary of a set of distances (all in the same unit).
///
/// Percentiles interpolate linearly between the two nearest order statistics (the default of
/// NumPy and R's type 7): p50 of {0, 1} is 0.5; p99 of N values is the value of rank 0.99 (N - 1).
struct DistanceStats
{
    std::size_t count = 0;
    double min = 0.0;
    double max = 0.0; ///< one-sided Hausdorff distance when the distances are point-to-set
    double mean = 0.0;
    double rms = 0.0; ///< √(mean of squares)
    double p50 = 0.0; ///< median
    double p90 = 0.0;
    double p99 = 0.0;
};

/// \brief Summarises distances; the order of the input does not matter.
/// \throw InvalidInput if `distances` is empty or holds a negative or non-finite value
[[nodiscard]] DistanceStats summarize_distances(std::span<const double> distances);

/// \brief Every statistic multiplied by `factor` (count unchanged): e.g. 1 / diagonal.
[[nodiscard]] DistanceStats scaled(const DistanceStats& stats, double factor);

/// \brief Options for compare.
struct CompareOptions
{
    /// Random area-uniform samples drawn on each input that is a mesh (B's generator is seeded
    /// from `seed` too, differently from A's). Point sets are used as they are. 0 = vertices only
    /// (then include_vertices must be set).
    std::size_t samples = 100000;
    /// Seed of the sampling; the same inputs, samples and seed give the same result.
    std::uint64_t seed = 1;
    /// Add a mesh's vertices to its samples, as Metro does (corners are then measured exactly).
    bool include_vertices = true;
    /// F-score thresholds τ, as fractions of the diagonal (DistanceComparison::diagonal), each
    /// > 0 and finite: see FScore.
    std::vector<double> fscore_thresholds;
    /// Optional progress report, called from one thread.
    ProgressCallback progress;
};

/// \brief F-score at a distance threshold τ, A taken as the reference (ground truth) and B as
/// the reconstruction (Knapitsch et al. 2017, Tanks and Temples): precision is the fraction of
/// B's samples within τ of A, recall the fraction of A's samples within τ of B, and F their
/// harmonic mean (0 when both are 0). A mesh's samples here are its area-uniform ones only
/// (CompareOptions::samples; not the vertices that include_vertices adds for the maxima), so
/// the fractions are of its area, whatever the density of its vertices.
struct FScore
{
    double threshold = 0.0;          ///< τ relative to the diagonal
    double absolute_threshold = 0.0; ///< τ in world units
    double precision = 0.0;
    double recall = 0.0;
    double f = 0.0;
};

/// \brief One direction, the other, and both together, all in one unit.
struct DistanceSummary
{
    DistanceStats a_to_b; ///< distances from the samples of A to B
    DistanceStats b_to_a; ///< distances from the samples of B to A
    /// Both distance sets pooled (a_to_b.count + b_to_a.count values): its max is the symmetric
    /// Hausdorff distance; its mean weighs each direction by its sample count.
    DistanceStats symmetric;
    double hausdorff = 0.0; ///< symmetric Hausdorff distance: max(a_to_b.max, b_to_a.max)
    /// Chamfer distance, defined here as mean(A→B) + mean(B→A) (unsquared distances; some
    /// authors halve it or use squared distances, which we do not).
    double chamfer = 0.0;
};

/// \brief Result of compare: the statistics in world units and relative to the diagonal.
struct DistanceComparison
{
    DistanceSummary absolute; ///< world units
    DistanceSummary relative; ///< absolute / diagonal (all zero when the diagonal is zero)
    /// Diagonal of the bounding box of A and B together (all points of both inputs, vertices
    /// for meshes), like the bounding box MeshLab's Metro uses for its "wrt bounding box
    /// diagonal" figures.
    double diagonal = 0.0;
    /// One per CompareOptions::fscore_thresholds, in that order.
    std::vector<FScore> fscores;
};

/// \brief A shape compare() measures, held by the caller: a surface (a TriMesh with triangles)
/// or a point set (a PointCloudView, or a TriMesh without triangles). Converts implicitly from
/// both; what it refers to must outlive it.
struct ShapeRef
{
    const TriMesh* mesh = nullptr; ///< the surface; null for a point set
    PointCloudView points;         ///< the mesh's vertices, or the point set

    // NOLINTNEXTLINE(google-explicit-constructor)
    ShapeRef(const TriMesh& m) : mesh(m.face_count() > 0 ? &m : nullptr), points(m.vertices) {}
    // NOLINTNEXTLINE(google-explicit-constructor)
    ShapeRef(const PointCloudView& p) : points(p) {}
};

/// \brief Compares two shapes the way MeshLab's Metro does: samples both, measures each set of
/// samples against the other shape, and reports one-sided and symmetric statistics.
///
/// A surface is sampled area-uniformly (options.samples random points plus, if
/// include_vertices, its vertices) and measured against exactly (point-to-triangle, through a
/// TriangleBvh); a point set is used as its own samples, in place, and measured against by
/// nearest point (kd-tree).
/// \throw InvalidInput if a shape has no points, a mesh has zero area or a bad index, a
///        coordinate is not finite, a mesh would get no samples, or an F-score threshold is not
///        positive and finite
[[nodiscard]] DistanceComparison compare(const ShapeRef& a, const ShapeRef& b,
                                         const CompareOptions& options = {});

/// \brief How many points measure `shape` in compare(): a point set's points, or a mesh's
/// `samples` area samples plus, with include_vertices, the vertices its triangles use.
[[nodiscard]] std::size_t compare_sample_count(const ShapeRef& shape, std::size_t samples,
                                               bool include_vertices = true);

} // namespace pointform
