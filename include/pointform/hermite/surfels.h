// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include "pointform/core/progress.h"
#include "pointform/geometry/point_cloud.h"
#include "pointform/hermite/orientation.h"
#include "pointform/hermite/radius.h"

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

namespace pointform {

/// \brief How compute_surfels orients normals.
enum class OrientMode
{
    Mst,     ///< minimum-spanning-tree propagation, every component (default)
    None,    ///< keep PCA's arbitrary signs
    Towards, ///< towards a viewpoint
    Along,   ///< along a direction
    Flip,    ///< MST, then reversed (inward normals)
};

/// \brief Options for compute_surfels: Level 1 → Level 2 (§4).
struct SurfelOptions
{
    /// Neighbours of each point, besides itself, for PCA and the automatic radius (as CGAL counts
    /// them; Open3D's KNN(k) counts the point itself).
    std::size_t k = 16;
    /// Neighbours a point in the orientation graph; 0 = min(k, 10).
    std::size_t graph_k = 0;
    /// Orientation mode and its parameters.
    OrientMode orient = OrientMode::Mst;
    /// Towards: the viewpoint; Along: the direction. World coordinates.
    Vec3d orient_target = Vec3d::UnitZ();
    /// Orientation propagation rule (MST modes).
    OrientationRule rule = OrientationRule::Hoppe;
    /// Factor on the automatic influence radius (§4.1), > 0.
    double radius_scale = 1.0;
    /// User regions that set the radius (§4.1, interactive), applied after the automatic one.
    std::vector<RadiusRegion> radius_regions;
    /// Optional progress report.
    ProgressCallback progress;
};

/// \brief The surfels and a report of how they were made.
struct SurfelResult
{
    /// The input points (same order, same origin) with oriented unit normals and radii.
    PointCloud surfels;
    /// Orientation outcome (components, flipped, unoriented samples).
    OrientedNormals orientation;
    /// Samples whose neighbourhood was coincident or collinear (normal taken from a neighbour).
    std::size_t degenerate = 0;
    /// Wall-clock seconds by stage, in order: "spatial sort", "kd-tree", "knn", "normals",
    /// "orientation", "radius".
    std::vector<std::pair<std::string, double>> stage_seconds;
};

/// \brief Checks that points can carry surfels: more than `k` points (k ≥ 3), all finite, not all
/// coincident and not all on one line.
/// \throw InvalidInput saying which condition fails
void check_surfel_input(const PointCloud& cloud, std::size_t k);

/// \brief Level 1 → 2 (§4): k nearest neighbours, PCA normals, consistent orientation and
/// influence radii, for every sample, in parallel where it pays.
/// \throw InvalidInput as check_surfel_input, or for non-positive radius_scale
[[nodiscard]] SurfelResult compute_surfels(const PointCloud& cloud,
                                           const SurfelOptions& options = {});

} // namespace pointform
