// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include "pointform/core/progress.h"
#include "pointform/geometry/point_cloud.h"

#include <cstddef>

namespace pointform {

class KdTree;

/// \brief The sampling density of a point set: how far a sample is from its nearest other
/// sample. The one definition the library and the CLI use (`pointform info`, and the threshold
/// of the refinement's stop, §5.2.4).
struct SamplingDensity
{
    /// The median, over the measured samples, of the distance to the nearest distinct other
    /// sample (world units). This is "the sampling density".
    double median = 0.0;
    /// The mean of the same distances.
    double mean = 0.0;
    /// Samples measured: every sample up to max_sampling_density_queries, else that many
    /// spread evenly over the cloud (a fixed stride), less those with no distinct neighbour
    /// among their 8 nearest (coincident duplicates).
    std::size_t measured = 0;
};

/// Most samples measure_sampling_density() queries; above this it takes every n-th sample.
inline constexpr std::size_t max_sampling_density_queries = 100000;

/// \brief Measures the sampling density (SamplingDensity). Coincident duplicates are skipped:
/// a sample's distance is to its nearest sample at a positive distance (among its 8 nearest).
/// The result does not depend on the thread count.
/// \throw InvalidInput if the cloud has fewer than 2 points, or all are coincident
[[nodiscard]] SamplingDensity measure_sampling_density(const PointCloudView& samples,
                                                       const ProgressCallback& progress = {});

/// \brief measure_sampling_density() with a k-d tree of the samples' positions that the caller
/// has built (KdTree(samples.positions)), for a caller that queries it for more: the same result.
[[nodiscard]] SamplingDensity measure_sampling_density(const KdTree& tree,
                                                       const PointCloudView& samples,
                                                       const ProgressCallback& progress = {});

/// \brief measure_sampling_density(samples).median.
[[nodiscard]] double estimate_sampling_density(const PointCloudView& samples);

} // namespace pointform
