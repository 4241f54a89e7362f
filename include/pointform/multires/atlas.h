// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include "pointform/core/types.h"
#include "pointform/geometry/multires_mesh.h"
#include "pointform/geometry/textured_mesh.h"
#include "pointform/multires/parameterization.h"

#include <array>
#include <cstddef>
#include <span>
#include <vector>

namespace pointform {

/// \file
/// \brief A texture atlas over the base mesh: every base triangle is one chart, laid out in one
/// square texture in its own shape (a similarity of the base triangle, one scale for all), so
/// the parameterization's dyadic sub-triangles map to texture space without flips and the seams
/// run along base edges only.

/// \brief Texture sizes: at least 16, at most 16384 texels a side.
inline constexpr int min_atlas_size = 16;
inline constexpr int max_atlas_size = 16384;

struct AtlasOptions
{
    /// Texels a side; 0 = automatic: a power of two giving the level to texture about 8 texels
    /// a face and every chart at least 16 texels across, within 256 … 8192.
    int size = 0;
    /// Empty texels between charts (their colours are dilated into it: bilinear filtering and
    /// mip-maps then do not bleed across charts); 1 … 64.
    int gutter = 4;
};

/// \brief Where each base triangle lies in the texture.
struct Atlas
{
    int size = 0;   ///< texels a side
    int gutter = 0; ///< texels between charts
    /// Per base face, the texture coordinates (u right, v down, in [0, 1]) of its three corners,
    /// in the face's corner order; counter-clockwise with v pointing up, as on the surface.
    std::vector<std::array<Vec2d, 3>> corners;
    double texels_per_unit = 0.0; ///< the common scale: texels per world unit of the base mesh
    double texel_usage = 0.0;     ///< share of the texture's texels inside a chart

    /// \brief Texture coordinates of a point of the base face `face` at `barycentric`.
    [[nodiscard]] Vec2d uv(std::uint32_t face, const Vec3d& barycentric) const
    {
        const auto& c = corners[face];
        return barycentric.x() * c[0] + barycentric.y() * c[1] + barycentric.z() * c[2];
    }
};

/// \brief Lays the base triangles out as charts (longest edge along u, shelf-packed, the largest
/// scale that fits). `level` is the level that will be textured (for the automatic size).
/// \throw InvalidInput for an empty hierarchy, a level that does not exist, a size outside
///        min_atlas_size … max_atlas_size, a gutter outside 1 … 64, a base face of zero
///        area, or charts whose gutters fill the texture (the longest chart under a texel at
///        the largest scale that fits); also if the texture would not fit in memory
///        (check_memory)
[[nodiscard]] Atlas make_atlas(const MultiresMesh& mesh, std::size_t level,
                               const AtlasOptions& options = {});

/// \brief The levels `levels` (increasing, each existing) of `mesh` as one textured mesh: one
/// vertex per (vertex, chart) pair (vertices on base edges are duplicated per chart: the UV
/// seams), ordered by level so that each level's vertices are a prefix of the next's; texture
/// coordinates from the atlas; unit normals and tangent frames (along +u, sign of +v) from the
/// finest level given. No images are set.
/// \throw InvalidInput for levels that do not exist or are not increasing, or none
[[nodiscard]] TexturedMesh textured_levels(const MultiresMesh& mesh,
                                           const Parameterization& parameterization,
                                           const Atlas& atlas, std::span<const std::size_t> levels);

/// \brief How much the texture map of one level distorts, faces of level i against their images
/// in the texture (Sander et al. 2001: the singular values Γ ≥ γ of the map from texture to
/// surface, both normalised so the total areas match).
struct AtlasDistortion
{
    std::size_t level = 0;
    std::size_t faces = 0;
    double l2_stretch = 0.0;       ///< sqrt(Σ A (Γ² + γ²) / 2 / Σ A), 1 for an isometry
    double linf_stretch = 0.0;     ///< max Γ
    double angle_distortion = 0.0; ///< mean over faces of Γ / γ − 1 (0: conformal)
    double area_distortion = 0.0;  ///< mean over faces of |log(Γ γ)| (0: area-preserving)
    std::size_t flipped = 0;       ///< faces whose texture image is clockwise or degenerate
};

/// \brief The distortion of each of `levels`. \throw InvalidInput as textured_levels()
[[nodiscard]] std::vector<AtlasDistortion> atlas_distortion(
    const MultiresMesh& mesh, const Parameterization& parameterization, const Atlas& atlas,
    std::span<const std::size_t> levels);

} // namespace pointform
