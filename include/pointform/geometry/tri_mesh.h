// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include "pointform/core/types.h"
#include "pointform/geometry/point_cloud.h"

#include <array>
#include <cstdint>
#include <vector>

namespace pointform {

/// \brief Vertex indices of one triangle, counter-clockwise seen from outside.
using Triangle = std::array<std::uint32_t, 3>;

/// \brief An indexed triangle mesh: vertices (a PointCloud, with the same origin convention and
/// optional attributes) plus a #F by 3 array of vertex indices.
struct TriMesh
{
    PointCloud vertices;
    std::vector<Triangle> triangles;

    [[nodiscard]] std::size_t vertex_count() const { return vertices.size(); }
    [[nodiscard]] std::size_t face_count() const { return triangles.size(); }
};

} // namespace pointform
