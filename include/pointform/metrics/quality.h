// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include "pointform/core/types.h"
#include "pointform/geometry/tri_mesh.h"

#include <cstddef>

namespace pointform {

/// \brief The smallest interior angle of triangle abc, in radians (atan2 of the edge vectors'
/// cross and dot products, accurate near 0 and π); 0 for a triangle with a zero-length edge.
[[nodiscard]] double triangle_min_angle(const Vec3d& a, const Vec3d& b, const Vec3d& c);

/// Triangles whose smallest angle is below this are slivers in AngleQuality.
inline constexpr double default_sliver_degrees = 20.0;

/// \brief The shape of a mesh's triangles by their smallest angles, in degrees.
struct AngleQuality
{
    std::size_t faces = 0;
    /// Smallest angle of any triangle (180 for a mesh without triangles).
    double min_degrees = 180.0;
    /// Mean over the triangles of each one's smallest angle.
    double mean_min_degrees = 0.0;
    /// Share of the triangles whose smallest angle is below the sliver bound (slivers).
    double sliver_share = 0.0;
    /// Triangles with no vertex on the boundary (a vertex on an edge that one triangle uses).
    std::size_t interior_faces = 0;
    /// The sliver share among those: what the rims of holes do not explain.
    double interior_sliver_share = 0.0;
};

/// \brief Measures the smallest angles of every triangle (triangle_min_angle).
/// \param sliver_degrees  the sliver bound, degrees
/// \throw InvalidInput if a triangle refers to a vertex out of range
[[nodiscard]] AngleQuality angle_quality(const TriMesh& mesh,
                                         double sliver_degrees = default_sliver_degrees);

} // namespace pointform
