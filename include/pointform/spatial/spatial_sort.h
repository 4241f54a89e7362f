// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include "pointform/core/types.h"

#include <cstdint>
#include <span>
#include <vector>

namespace pointform {

/// \brief A permutation that lists the points along a Morton (Z-order) curve over their
/// bounding box, so that points close in space are close in memory. Processing points in this
/// order makes neighbour queries, PCA and graph traversals cache-friendly (several times faster
/// on large scans stored in acquisition or random order).
/// \param positions  N points
/// \return N indices: result[j] is the original index of the j-th point along the curve. More
///         than 16 points in one grid cell (where a far outlier made the cells large) are
///         ordered again along a curve over their own box, and so on; points at one place keep
///         their original order, so the result is deterministic
[[nodiscard]] std::vector<std::uint32_t> spatial_order(std::span<const Vec3f> positions);

/// \brief A sample at the very place of an earlier one (the same coordinates), and the earliest
/// sample at that place.
struct CoincidentCopy
{
    std::uint32_t copy = 0;     ///< the later sample
    std::uint32_t original = 0; ///< the first sample at its place, < copy
};

/// \brief spatial_order(), and the samples that repeat an earlier sample's coordinates exactly
/// (a scan merged with itself, coordinates quantized by the scanner or the file format), each
/// with the first sample at its place, ascending by copy. Samples at one place share a key, so
/// only the runs of equal keys are compared (on a cloud without copies, a few pairs), in
/// parallel; the same whatever the thread count.
[[nodiscard]] std::vector<std::uint32_t> spatial_order(std::span<const Vec3f> positions,
                                                       std::vector<CoincidentCopy>& copies);

/// \brief The key spatial_order() sorts each point by: its cell of a grid of 2^21 cells an axis
/// over the points' bounding box (cubic cells, the largest extent's), the cell's coordinates'
/// bits interleaved from the top, z y x at each level (bit 3l + a is bit l of axis a). Points in
/// spatial_order() have non-decreasing keys. Fills `keys` (one a point) in parallel.
/// \throw InvalidInput if the sizes differ
void morton_keys(std::span<const Vec3f> positions, std::span<std::uint64_t> keys);

/// \brief The Morton key morton_keys() gives `point` when the points' box has its low corner
/// at `low` and `scale` = (2^21 - 1) / (the box's largest extent), or 0 if that extent is 0.
/// Non-finite coordinates take cell 0.
[[nodiscard]] std::uint64_t morton_key(const Vec3f& point, const Vec3d& low, double scale);

/// \brief The `scale` of morton_key() for a box of these extents.
[[nodiscard]] double morton_scale(const Vec3d& extent);

/// \brief Orders `indices` (of points of `positions`) along a Morton curve over those points' own
/// bounding box, ties by index, and sets `keys` (as many) to their keys on it: how the points of
/// one crowded grid cell (a far outlier makes a whole cloud's cells large) are ordered again, by
/// spatial_order() and by the kd-tree of Morton-ordered points.
/// \return false, and nothing changed, when the points all lie at one place or one of their
///         coordinates is not finite
bool order_in_own_box(std::span<const Vec3f> positions, std::span<std::uint32_t> indices,
                      std::span<std::uint64_t> keys);

} // namespace pointform
