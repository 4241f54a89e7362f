// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include "pointform/geometry/point_cloud.h"
#include "pointform/geometry/tri_mesh.h"
#include "pointform/hermite/scatter.h"
#include "pointform/spatial/kd_tree.h"

#include <cstddef>

namespace pointform {

/// \brief What remove_unsupported_components() did.
struct ComponentFilterReport
{
    std::size_t components = 0;         ///< vertex-connected components before
    std::size_t removed_components = 0; ///< components removed
    std::size_t removed_faces = 0;      ///< their faces
    std::size_t min_samples = 0;        ///< the support a component needed
    /// Of the removed components, those with support enough but held up by scattered samples
    /// (see remove_unsupported_components()).
    std::size_t scattered_components = 0;
};

/// \brief The support a component of a reconstruction needs by default: 0.1% of the samples,
/// and at least 32 (two neighbourhoods of 16).
[[nodiscard]] std::size_t default_min_component_samples(std::size_t samples);

/// \brief Removes the connected components of `mesh` that fewer than `min_samples` of `samples`
/// have as their nearest part of the mesh (exact closest point on the triangles): the debris of
/// a field around a few stray samples or a flipped normal, which the samples do not describe as
/// a surface. Also removed, but for the best-supported component, those whose support is mostly
/// scattered samples (ScatterTest: samples whose 16 nearest spread through a volume rather
/// than along a sheet and reach farther than scattered_reach times the cloud's median reach),
/// a spray of stray returns through the space around a scan, over which the field makes sheets
/// that no surface supports. (A noisy surface sampled as densely as the rest is not scattered,
/// nor is a sparse one whose samples lie on a sheet.) Up to 256 of a component's samples are
/// tested, spread evenly in index order. Vertices of removed components are dropped and the
/// rest renumbered in order (every vertex attribute kept); components are vertex-connected.
/// Deterministic whatever the thread count. `min_samples` = 0 keeps every component.
/// \param sample_tree  a kd-tree over samples.positions (as PointField::tree()), or null: one
///        is built when a component is to be tested
ComponentFilterReport remove_unsupported_components(TriMesh& mesh, const PointCloud& samples,
                                                    std::size_t min_samples,
                                                    const KdTree* sample_tree = nullptr);

} // namespace pointform
