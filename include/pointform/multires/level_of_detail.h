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
#include <string>

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

/// \brief Level `level` of `mesh` and its topology. \throw InvalidInput as check_level()
[[nodiscard]] LevelOfDetail extract_level(const MultiresMesh& mesh, std::size_t level);

} // namespace pointform
