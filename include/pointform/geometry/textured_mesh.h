// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include "pointform/core/types.h"
#include "pointform/geometry/tri_mesh.h"

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace pointform {

/// \brief Texture coordinates: u to the right, v down from the image's top-left corner (glTF's
/// convention; OBJ writers flip v).
using Vec2f = Eigen::Vector2f;
using Vec2d = Eigen::Vector2d;

/// \brief An 8-bit image, rows top to bottom, `channels` bytes a pixel (3: RGB, 4: RGBA).
struct TextureImage
{
    int width = 0;
    int height = 0;
    int channels = 3;
    std::vector<std::uint8_t> pixels; ///< width × height × channels

    [[nodiscard]] bool empty() const { return pixels.empty(); }
};

/// \brief A textured triangle mesh with levels of detail that share one vertex buffer: the
/// export form of a hierarchy (glTF binary, OBJ + MTL + PNG).
///
/// Level i uses the vertices [0, lod_vertex_counts[i]) only, so each level's vertices are a
/// prefix of the next's (as in a MultiresMesh, with the vertices on UV seams duplicated per
/// chart); lods[i] are its triangles, counter-clockwise seen from outside. Levels are ordered
/// coarse to fine.
struct TexturedMesh
{
    /// World position of vertex v = origin + positions[v].
    Vec3d origin = Vec3d::Zero();
    std::vector<Vec3f> positions;
    /// Unit vertex normals, one per vertex, or empty.
    std::vector<Vec3f> normals;
    /// Texture coordinates in [0, 1]², one per vertex, or empty (then no texture is used).
    std::vector<Vec2f> uvs;
    /// Tangent-space frames for the normal map (xyz: unit tangent along +u; w: ±1, the sign of
    /// the bitangent, glTF's TANGENT), one per vertex, or empty.
    std::vector<Eigen::Vector4f> tangents;
    std::vector<std::vector<Triangle>> lods;
    std::vector<std::size_t> lod_vertex_counts;
    /// Level of the hierarchy each entry of `lods` comes from (for names), or empty.
    std::vector<std::size_t> lod_levels;
    TextureImage base_color; ///< empty: no colour texture
    TextureImage normal_map; ///< tangent-space, empty: none
    std::string name = "pointform";
};

} // namespace pointform
