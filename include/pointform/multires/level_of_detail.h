// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

/// \file
/// \brief Level 3's hierarchy and its levels of detail. The hierarchy type, MultiresMesh, lives
/// in the geometry module because the refinement (polygonize) builds it; this header is its
/// home for Level 3 users, with the extraction of one level as a mesh (what `pointform lod`
/// writes).

#include "pointform/geometry/mesh_topology.h"
#include "pointform/geometry/multires_mesh.h"
#include "pointform/geometry/tri_mesh.h"

#include <cstddef>
#include <span>
#include <string>
#include <vector>

namespace pointform {

/// \brief One level of a hierarchy as an indexed mesh, with its topology.
struct LevelOfDetail
{
    std::size_t level = 0;
    TriMesh mesh;          ///< as MultiresMesh::level_mesh()
    MeshTopology topology; ///< components, boundary loops, Euler characteristic, manifoldness
};

/// \brief Throws unless `level` is a level of `mesh`, with a message that lists the levels.
/// \throw InvalidInput "level L does not exist: the hierarchy has N levels (0 to J)"
void check_level(const MultiresMesh& mesh, std::size_t level);

/// \brief Throws unless `levels` names at least one level, every one a level of `mesh`, in
/// strictly increasing order. \throw InvalidInput saying which rule a level breaks
void check_levels(const MultiresMesh& mesh, std::span<const std::size_t> levels);

/// \brief Area-weighted unit vertex normals of vertices 0 … vertex_count − 1 over `faces`,
/// summed in face order (the same whatever the thread count); a vertex whose faces' normals
/// cancel gets the faces' overall normal (+z if that cancels too).
[[nodiscard]] std::vector<Vec3d> vertex_normals(std::span<const Vec3d> positions,
                                                std::span<const Triangle> faces,
                                                std::size_t vertex_count);

/// \brief Level `level` of `mesh` and its topology. \throw InvalidInput as check_level()
[[nodiscard]] LevelOfDetail extract_level(const MultiresMesh& mesh, std::size_t level);

} // namespace pointform
