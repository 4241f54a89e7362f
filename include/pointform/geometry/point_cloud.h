// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include "pointform/core/types.h"
#include "pointform/geometry/aabb.h"

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

namespace pointform {

/// \brief Level 1: unstructured samples S (§3), with the attributes a file may carry.
///
/// Positions are float32, stored relative to a double-precision `origin`, so that georeferenced
/// coordinates (LiDAR, UTM) keep their precision: world position i = origin + positions[i].
/// Optional attributes are parallel arrays that are either empty or hold one entry a point.
struct PointCloud
{
    Vec3d origin = Vec3d::Zero();
    std::vector<Vec3f> positions; ///< N, relative to origin
    std::vector<Vec3f> normals;   ///< empty or N; unit length when read from a file that has them
    std::vector<Color> colors;    ///< empty or N
    std::vector<float> radii;     ///< empty or N; influence radius in world units (§4.1)
    /// Where the points were seen from, in world units, when the file says they are one view
    /// of a sensor (an organized depth image: PCD with HEIGHT > 1 and its VIEWPOINT): normals
    /// estimated for them face it (OrientMode::Auto). Empty for other clouds.
    std::optional<Vec3d> sensor;

    [[nodiscard]] std::size_t size() const { return positions.size(); }
    [[nodiscard]] bool empty() const { return positions.empty(); }
    [[nodiscard]] bool has_normals() const { return !normals.empty(); }
    [[nodiscard]] bool has_colors() const { return !colors.empty(); }
    [[nodiscard]] bool has_radii() const { return !radii.empty(); }

    /// \brief World position of point i, in double precision.
    [[nodiscard]] Vec3d world(std::size_t i) const { return origin + positions[i].cast<double>(); }
    /// \brief Bounding box in world units.
    [[nodiscard]] Aabb bounds() const { return bounding_box(positions, origin); }
};

/// \brief A point cloud's arrays held elsewhere, read only: what the library's functions that
/// only read samples take, so that a caller's own storage (a numpy array, a memory-mapped file)
/// is used in place. A PointCloud converts to it implicitly; the arrays must outlive the view.
struct PointCloudView
{
    Vec3d origin = Vec3d::Zero();
    std::span<const Vec3f> positions; ///< N, relative to origin
    std::span<const Vec3f> normals;   ///< empty or N
    std::span<const Color> colors;    ///< empty or N
    std::span<const float> radii;     ///< empty or N
    std::optional<Vec3d> sensor;      ///< PointCloud::sensor

    PointCloudView() = default;
    // NOLINTNEXTLINE(google-explicit-constructor): a cloud is its own view
    PointCloudView(const PointCloud& cloud)
        : origin(cloud.origin),
          positions(cloud.positions),
          normals(cloud.normals),
          colors(cloud.colors),
          radii(cloud.radii),
          sensor(cloud.sensor)
    {}

    [[nodiscard]] std::size_t size() const { return positions.size(); }
    [[nodiscard]] bool empty() const { return positions.empty(); }
    [[nodiscard]] bool has_normals() const { return !normals.empty(); }
    [[nodiscard]] bool has_colors() const { return !colors.empty(); }
    [[nodiscard]] bool has_radii() const { return !radii.empty(); }
    [[nodiscard]] Vec3d world(std::size_t i) const { return origin + positions[i].cast<double>(); }
    [[nodiscard]] Aabb bounds() const { return bounding_box(positions, origin); }
};

/// \brief A cloud that owns copies of the view's arrays.
[[nodiscard]] PointCloud to_point_cloud(const PointCloudView& view);

/// \brief Keeps the points whose `keep[i]` is non-zero, in order, with every attribute.
/// \pre keep.size() == cloud.size()
/// \return the number of points removed
std::size_t keep_points(PointCloud& cloud, std::span<const std::uint8_t> keep);

/// \brief Puts the points in the order `order` gives (point j becomes point order[j]'s), with
/// every attribute.
/// \pre `order` is a permutation of the cloud's indices
void reorder_points(PointCloud& cloud, std::span<const std::uint32_t> order);

/// \brief Picks the float storage origin for a cloud whose first point is `first`: the point
/// rounded to whole units, so that small models (within about ±0.5 unit of zero) keep origin 0
/// and float inputs round-trip exactly, while georeferenced ones are re-centred.
[[nodiscard]] Vec3d choose_origin(const Vec3d& first);

/// \brief Checks that every attribute array is empty or of the cloud's size.
/// \throw InvalidInput naming the offending attribute.
void validate(const PointCloudView& cloud);

} // namespace pointform
