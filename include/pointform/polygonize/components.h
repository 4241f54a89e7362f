// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include "pointform/geometry/point_cloud.h"
#include "pointform/geometry/tri_mesh.h"

#include <cstddef>

namespace pointform {

/// \brief What remove_unsupported_components() did.
struct ComponentFilterReport
{
    std::size_t components = 0;         ///< vertex-connected components before
    std::size_t removed_components = 0; ///< components removed
    std::size_t removed_faces = 0;      ///< their faces
    std::size_t min_samples = 0;        ///< the support a component needed
};

/// \brief The support a component of a reconstruction needs by default: 0.1% of the samples,
/// and at least 32 (two neighbourhoods of 16).
[[nodiscard]] std::size_t default_min_component_samples(std::size_t samples);

/// \brief Removes the connected components of `mesh` that fewer than `min_samples` of `samples`
/// have as their nearest part of the mesh (exact closest point on the triangles): the debris of
/// a field around a few stray samples or a flipped normal, which the samples do not describe as
/// a surface. Vertices of removed components are dropped and the rest renumbered in order
/// (every vertex attribute kept); components are vertex-connected. Deterministic whatever the
/// thread count. `min_samples` = 0 keeps every component.
ComponentFilterReport remove_unsupported_components(TriMesh& mesh, const PointCloud& samples,
                                                    std::size_t min_samples);

} // namespace pointform
