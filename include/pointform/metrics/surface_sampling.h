// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include "pointform/geometry/point_cloud.h"
#include "pointform/geometry/tri_mesh.h"

#include <cstddef>
#include <cstdint>

namespace pointform {

/// \brief Options for sample_surface.
struct SurfaceSamplingOptions
{
    /// Number of random samples, drawn area-uniformly over the triangles. 0 is allowed (then only
    /// the vertices, if include_vertices is set).
    std::size_t count = 100000;
    /// Seed of the pseudo-random generator. The same mesh, count and seed give the same samples
    /// whatever the thread count.
    std::uint64_t seed = 1;
    /// Also append every vertex that a triangle uses (after the random samples), so that
    /// corners and sharp features are measured exactly, as MeshLab's Metro does.
    bool include_vertices = false;
    /// Also give every sample a unit normal: a random sample its triangle's, a vertex the
    /// area-weighted mean of the normals of the triangles around it (zero where those have no
    /// area, or cancel out).
    bool normals = false;
};

/// \brief Samples a triangle mesh uniformly by area.
///
/// Each sample picks a triangle with probability proportional to its area (inverse transform of
/// the cumulative areas) and a point uniformly inside it (u = 1 - √r1, v = √r1 (1 - r2),
/// w = √r1 r2). Zero-area triangles receive no samples. Samples are generated in fixed blocks,
/// each with its own generator seeded from (seed, block), so the result does not depend on the
/// number of threads.
/// \param mesh  V vertices and F >= 1 triangles of positive total area
/// \return count random samples followed (if include_vertices) by the used vertices in index
///         order; the cloud has the mesh's origin and no attributes but the normals asked for
/// \throw InvalidInput if the mesh has no triangles or zero total area, an index is out of range
///        or a position is not finite
[[nodiscard]] PointCloud sample_surface(const TriMesh& mesh,
                                        const SurfaceSamplingOptions& options = {});

/// \brief Total area of the triangles, in world units squared.
/// \throw InvalidInput if an index is out of range
[[nodiscard]] double surface_area(const TriMesh& mesh);

} // namespace pointform
