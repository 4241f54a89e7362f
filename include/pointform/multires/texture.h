// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include "pointform/geometry/multires_mesh.h"
#include "pointform/geometry/point_cloud.h"
#include "pointform/geometry/textured_mesh.h"
#include "pointform/multires/atlas.h"
#include "pointform/multires/parameterization.h"

#include <cstddef>
#include <optional>
#include <vector>

namespace pointform {

/// \file
/// \brief Texture mapping through the parameterization (§5.3, Fig. 12): a checkerboard that
/// shows the map's distortion, an image used as the atlas, the colours of a coloured scan baked
/// into the atlas, and a tangent-space normal map baked from a fine level onto a coarse one.

/// \brief A checkerboard in texture space with squares of `square` texels (two greys): on the
/// surface the squares show how the map stretches. \pre atlas.size > 0; square ≥ 1
[[nodiscard]] TextureImage checker_texture(const Atlas& atlas, int square = 0);

/// \brief `image` resampled (bilinear) to the atlas's size: texel (u, v) shows the image at (u,
/// v). An image painted over an exported atlas (a checker or baked texture edited in a paint
/// program) goes back on the surface this way. \throw InvalidInput for an empty image
[[nodiscard]] TextureImage atlas_image(const Atlas& atlas, const TextureImage& image);

/// \brief Options of bake_colors().
struct BakeOptions
{
    /// Nearest samples blended per texel, weights 1 / (distance + ε)².
    std::size_t neighbors = 8;
};

/// \brief What bake_colors() did.
struct BakeReport
{
    std::size_t texels = 0;  ///< texels inside a chart, baked
    std::size_t dilated = 0; ///< gutter texels filled from their neighbours
    double mean_distance =
        0.0; ///< mean distance from a texel's surface point to its nearest sample
    /// RMS difference (0 … 255 per channel) between each sample's colour and the baked texture
    /// at the nearest vertex of the textured level (bilinear), over the samples.
    double rms_color_error = 0.0;
};

/// \brief Bakes the colours of `samples` into the atlas: each texel inside a chart is mapped
/// through the parameterization to its point on level `level`, coloured by its nearest samples
/// (inverse squared distance weights), and the gutters are dilated from the charts.
/// \throw InvalidInput if the samples have no colours, the level does not exist, or the
///        samples are empty
[[nodiscard]] TextureImage bake_colors(const MultiresMesh& mesh,
                                       const Parameterization& parameterization, const Atlas& atlas,
                                       std::size_t level, const PointCloudView& samples,
                                       const BakeOptions& options = {},
                                       BakeReport* report = nullptr);

/// \brief A tangent-space normal map (glTF's convention: +x along +u, +y image-up, +z the
/// interpolated normal) that gives `coarse` — the textured mesh of one level j, from
/// textured_levels(mesh, …, {j}) — the shading normals of level `fine` > j: each texel's point
/// on level j and on level `fine` share base coordinates; the fine normal is the interpolated
/// area-weighted vertex normal of level `fine`, expressed in the coarse mesh's interpolated
/// tangent frame. Gutters are dilated.
/// \throw InvalidInput if `coarse` is not a one-level textured mesh with normals and tangents, or
///        `fine` does not exist or is not finer than its level
[[nodiscard]] TextureImage bake_normal_map(const MultiresMesh& mesh,
                                           const Parameterization& parameterization,
                                           const Atlas& atlas, const TexturedMesh& coarse,
                                           std::size_t fine);

/// \brief Fills empty texels (mask 0) from filled 4-neighbours (their mean), `rounds` times;
/// returns how many were filled. \pre mask has one entry per texel
std::size_t dilate(TextureImage& image, std::vector<std::uint8_t>& mask, int rounds);

} // namespace pointform

namespace pointform {

/// \brief What `pointform texture` makes: the colour source, the levels, the atlas.
struct TextureRequest
{
    enum class Source
    {
        Checker,    ///< checker_texture()
        Image,      ///< atlas_image() of `image`
        BakeColors, ///< bake_colors() of the samples given to texture_hierarchy()
    };
    Source source = Source::Checker;
    TextureImage image;               ///< Source::Image
    std::optional<std::size_t> level; ///< the finest level textured (J); default: the finest
    /// A level j < J to export alone with a normal map baked from level J (a light level that
    /// renders with the fine relief); unset: levels 0 … J as levels of detail, no normal map.
    std::optional<std::size_t> normal_map_level;
    AtlasOptions atlas;
    BakeOptions bake;
};

/// \brief The textured mesh and the figures every front end reports.
struct TextureOutcome
{
    TexturedMesh mesh;
    Atlas atlas;
    std::vector<AtlasDistortion> distortion; ///< per exported level
    std::optional<BakeReport> bake;
    std::size_t level = 0; ///< J
};

/// \brief The one call behind `pointform texture` and Python's Hierarchy.texture(): the
/// parameterization, the atlas (sized for level J), the textured levels, the colour texture and,
/// if asked, the normal map. `samples` must be given (with colours) for Source::BakeColors.
/// \throw InvalidInput for a level that does not exist, j ≥ J, a bad atlas size, a missing or
///        colourless scan, an empty image
[[nodiscard]] TextureOutcome texture_hierarchy(const MultiresMesh& mesh,
                                               const TextureRequest& request,
                                               const PointCloudView* samples = nullptr);

} // namespace pointform
