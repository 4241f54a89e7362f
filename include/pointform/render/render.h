// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include "pointform/core/types.h"
#include "pointform/geometry/aabb.h"
#include "pointform/geometry/point_cloud.h"
#include "pointform/geometry/textured_mesh.h"
#include "pointform/geometry/tri_mesh.h"

#include <cstdint>
#include <filesystem>
#include <optional>
#include <vector>

namespace pointform {

/// \brief How the camera projects the scene.
enum class Projection
{
    Perspective,  ///< pinhole camera with `field_of_view` (default)
    Orthographic, ///< parallel rays; areas on screen are exact projected areas
};

/// \brief Options for render_mesh and render_points: camera, shading and style.
///
/// The camera always frames the whole object: it looks at the object's bounding-box centre from
/// direction (azimuth, elevation) and is placed (perspective) or scaled (orthographic) so that
/// every vertex or sample lies inside the image, `margin` away from its border, with the object
/// centred in the image. Azimuth turns the camera counter-clockwise about `up` (seen from above);
/// azimuth 0 and elevation 0 look along -z when up is ±y (the camera on the +z side) and along +y
/// when up is ±z (the camera on the -y side), with +x to the right in both cases.
struct RenderOptions
{
    int width = 1024;        ///< image width in pixels, 1..16384
    int height = 768;        ///< image height in pixels, 1..16384
    double azimuth = 30.0;   ///< degrees about `up`
    double elevation = 20.0; ///< degrees above the plane perpendicular to `up`, -90..90
    /// The world direction that points up in the image; any non-zero vector. The shipped scans
    /// (data/bunny) are y-up.
    Vec3d up = Vec3d::UnitY();
    Projection projection = Projection::Perspective;
    /// Perspective only: full opening angle, in degrees, across the image's shorter side (0..170).
    double field_of_view = 30.0;
    /// Frame this world box (its eight corners) instead of the object: pictures of several
    /// objects, such as a shape before and after an edit, then share one camera. Finite, with
    /// min ≤ max on every axis.
    std::optional<Aabb> frame;
    /// Empty border around the object, as a fraction of the image's half-size, in [0, 0.9).
    double margin = 0.05;
    /// Anti-aliasing: samples per pixel along each axis (s×s samples a pixel, box filter), 1..8.
    int supersampling = 2;

    // Shading: two-sided Lambert, a key light fixed relative to the camera (upper left, in
    // front), a headlight and ambient light; intensity = ambient + key·|n·l| + headlight·|n·v|.
    double ambient = 0.15;   ///< ambient intensity, >= 0
    double key_light = 0.6;  ///< key light intensity, >= 0
    double headlight = 0.35; ///< headlight intensity, >= 0
    /// Colour of faces seen from their front (counter-clockwise) side, and of splats whose
    /// normal faces the camera.
    Color front_color{176, 196, 222};
    /// Colour of back faces and of splats whose normal points away from the camera: inside-out
    /// orientation and holes show up in this colour.
    Color back_color{222, 120, 92};
    Color background{245, 245, 242}; ///< never produced by shading the default colours
    /// Meshes: interpolate area-weighted vertex normals (true) or shade each face flat (false).
    bool smooth_shading = true;

    // Wireframe (meshes): the edges of visible faces drawn over the shading, anti-aliased, with
    // a width in pixels that does not depend on the size of the triangles.
    bool wireframe = false;
    double line_width = 0.8;   ///< pixels of the output image, > 0
    double line_opacity = 0.7; ///< in [0, 1]
    Color line_color{30, 34, 40};

    // Point clouds: each sample is an opaque disc (depth-tested, nearest wins) in its tangent
    // plane, shaded by its normal.
    /// Disc radius in world units; 0 = automatic, from the local sampling density (0.6 times the
    /// distance to the 8th nearest sample, kept within 0.25..4 times its median).
    double splat_radius = 0.0;
    /// Use the cloud's own radii (influence radii, §4.1) as disc radii when it has them.
    bool use_radii = false;
    /// Factor on every disc radius, > 0.
    double splat_scale = 1.0;
    /// Clouds without normals: estimate and orient them with compute_surfels (default k) and
    /// shade by them (true); or draw flat, camera-facing discs in `front_color` (false). Clouds
    /// too small or degenerate for compute_surfels are drawn flat either way.
    bool estimate_normals = true;
};

/// \brief An 8-bit RGB image, rows top to bottom, 3 bytes a pixel.
struct Image
{
    int width = 0;
    int height = 0;
    std::vector<std::uint8_t> rgb; ///< width * height * 3

    [[nodiscard]] Color pixel(int x, int y) const
    {
        const std::size_t i = (static_cast<std::size_t>(y) * static_cast<std::size_t>(width) +
                               static_cast<std::size_t>(x)) *
                              3;
        return {rgb[i], rgb[i + 1], rgb[i + 2]};
    }
};

/// \brief Checks the options. \throw InvalidInput naming the offending field and value.
void validate(const RenderOptions& options);

/// \brief Ray-casts a triangle mesh (Embree) and shades it; headless, on the CPU, in parallel
/// over image rows. Front faces in `front_color`, back faces in `back_color`, optionally with
/// the edges of the visible faces drawn over them (wireframe).
///
/// The output is the same whatever the thread count. Degenerate (zero-area) triangles are never
/// hit and so never drawn.
/// \param mesh  #V vertices (world = origin + position) and #F ≥ 1 triangles
/// \throw InvalidInput if the mesh has no triangles (render its vertices with render_points), a
///        vertex index is out of range, a vertex is not finite, or the options are invalid
/// \throw Error with Embree's message if Embree fails
[[nodiscard]] Image render_mesh(const TriMesh& mesh, const RenderOptions& options = {});

/// \brief Ray-casts level of detail `lod` of a textured mesh as render_mesh() does, its front
/// faces coloured by the colour texture (bilinear) and, when the mesh has a normal map, normals
/// and tangents, shaded with the normal map's normals (glTF's tangent frame): a coarse level
/// with a normal map shows the fine relief. Back faces keep `back_color`.
/// \throw InvalidInput if the level of detail does not exist or the mesh has no texture
///        coordinates or colour texture, or as render_mesh()
[[nodiscard]] Image render_textured_mesh(const TexturedMesh& mesh, std::size_t lod,
                                         const RenderOptions& options = {});

/// \brief Draws a point cloud as depth-tested discs (surface splats), shaded by normal; headless,
/// on the CPU, in parallel over bands of image rows. See RenderOptions for the disc radius and
/// for clouds without normals. The output is the same whatever the thread count.
/// \param cloud  N ≥ 1 finite samples; normals (N, or empty) need not be unit length; zero
///               normals are drawn as flat, camera-facing discs
/// \throw InvalidInput if the cloud is empty, a position is not finite, an attribute array has
///        the wrong size, the options are invalid, or the supersampled image would exceed 2²⁸
///        samples (its depth buffer is 8 bytes a sample)
[[nodiscard]] Image render_points(const PointCloudView& cloud, const RenderOptions& options = {});

/// \brief Encodes an image as PNG: encode_png(const TextureImage&) of pointform/io/png.h
/// (libpng), the one PNG writer. \throw InvalidInput for an inconsistent image (size does not
/// match width × height × 3, or a side ≤ 0).
[[nodiscard]] std::vector<std::uint8_t> encode_png(const Image& image);

/// \brief Writes an image as PNG, to a temporary file beside `path` renamed into place when
/// complete, so a failure never leaves a half-written file.
/// \throw IoError if the file cannot be written; InvalidInput as encode_png
void write_png(const std::filesystem::path& path, const Image& image);

} // namespace pointform
