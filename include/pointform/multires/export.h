// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

/// \file
/// \brief A hierarchy's levels as one TexturedMesh (levels of detail sharing one vertex buffer),
/// the form the glTF and OBJ writers take (pointform/io/textured_export.h), here with no
/// texture: what `pointform export` writes.

#include "pointform/geometry/multires_mesh.h"
#include "pointform/geometry/textured_mesh.h"

#include <cstddef>
#include <span>
#include <string_view>
#include <vector>

namespace pointform {

/// \brief The levels `levels` of `mesh` as levels of detail over one vertex buffer.
///
/// Since V^i ⊂ V^(i+1) (a level's vertices are a prefix of the next level's), one vertex array
/// serves every chosen level: the vertices of the finest chosen level, positions as float
/// relative to mesh.origin() (rounded as MultiresMesh::level_mesh() rounds them, so each level's
/// prefix is bit for bit that level's mesh). lods[k] are the faces of level levels[k],
/// lod_vertex_counts[k] = mesh.vertex_count(levels[k]), lod_levels = levels.
///
/// Normals: one unit normal per vertex, shared by every level of detail: the area-weighted
/// average of the face normals around the vertex at the FINEST chosen level (computed in
/// double). A coarse level therefore shades with the normals of the finest surface, which is
/// what a level-of-detail switch wants (the shading does not pop) and what one shared vertex
/// buffer allows. A vertex whose faces have no area (all degenerate) gets the area-weighted
/// normal of the whole level's faces instead, or +z if that is zero too.
/// No uvs, tangents or images (the lead's texture pipeline adds them).
/// \param levels  at least one level, each < mesh.level_count(), strictly increasing
/// \throw InvalidInput if `levels` is empty, names a level that does not exist, or is not
///        strictly increasing (the message names the offending entry)
[[nodiscard]] TexturedMesh level_chain(const MultiresMesh& mesh,
                                       std::span<const std::size_t> levels);

/// \brief Parses a level list as `pointform export --levels` takes it: "all" (every level, 0 to
/// J) or comma-separated level numbers "i,j,..." (decimal, no blanks), strictly increasing,
/// each < level_count.
/// \throw InvalidInput for an empty list or entry, a non-numeric entry, a level that does not
///        exist, or a list that repeats a level or is not in increasing order
[[nodiscard]] std::vector<std::size_t> parse_level_list(std::string_view text,
                                                        std::size_t level_count);

} // namespace pointform
