// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include "pointform/core/types.h"
#include "pointform/geometry/tri_mesh.h"

#include <algorithm>
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

/// \brief The first three channels of `image` at texture coordinates `uv` (u right, v down, in
/// [0, 1]; clamped at the borders), bilinear between texel centres, 0 … 255 each (a grey image's
/// channel is repeated). \pre a non-empty image
[[nodiscard]] inline Vec3d sample_texture(const TextureImage& image, const Eigen::Vector2d& uv)
{
    const double x = std::clamp(uv.x() * image.width - 0.5, 0.0, image.width - 1.0);
    const double y = std::clamp(uv.y() * image.height - 0.5, 0.0, image.height - 1.0);
    const int x0 = static_cast<int>(x);
    const int y0 = static_cast<int>(y);
    const int x1 = std::min(x0 + 1, image.width - 1);
    const int y1 = std::min(y0 + 1, image.height - 1);
    const double fx = x - x0;
    const double fy = y - y0;
    const auto at = [&](int px, int py, int channel) {
        return static_cast<double>(
            image.pixels[(static_cast<std::size_t>(py) * static_cast<std::size_t>(image.width) +
                          static_cast<std::size_t>(px)) *
                             static_cast<std::size_t>(image.channels) +
                         static_cast<std::size_t>(std::min(channel, image.channels - 1))]);
    };
    Vec3d out;
    for (int c = 0; c < 3; ++c)
        out[c] = (1 - fy) * ((1 - fx) * at(x0, y0, c) + fx * at(x1, y0, c)) +
                 fy * ((1 - fx) * at(x0, y1, c) + fx * at(x1, y1, c));
    return out;
}

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
