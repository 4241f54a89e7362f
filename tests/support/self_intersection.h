// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// Exact self-intersection check of a triangle mesh, on its stored float32 positions.

#pragma once

#include "pointform/geometry/tri_mesh.h"

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace pointform::test {

/// \brief The sign of the determinant | b−a, c−a, d−a | computed exactly (a floating-point filter,
/// then expansion arithmetic): +1, 0 or −1.
int orient3d_exact(const double* a, const double* b, const double* c, const double* d);

struct SelfIntersections
{
    /// Pairs of faces (i < j) whose closed triangles share a point that is not a vertex or edge
    /// they share by index.
    std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs;
    /// Faces whose three positions are exactly collinear (these are not tested).
    std::vector<std::uint32_t> degenerate;
    std::size_t candidate_pairs = 0; ///< pairs whose bounding boxes overlap
};

/// \brief Every pair of intersecting faces of `mesh`, exactly, on the positions as stored
/// (float32 relative to the origin). Triangles are closed sets; two faces that share a vertex
/// or an edge (by position: copies of a vertex at one point count as one) intersect only if
/// they overlap beyond it (coplanar folds, an edge lying inside the other face). Faces are binned
/// on a uniform grid by bounding box.
[[nodiscard]] SelfIntersections find_self_intersections(const TriMesh& mesh);

} // namespace pointform::test
