// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// Textured meshes for the export tests: a bumpy plate hierarchy whose uvs follow from x and y
// (no seams, so every level's vertices stay a prefix), a checker colour texture, a normal map
// and tangents; a closed sphere hierarchy without texture.

#pragma once

#include "pointform/geometry/multires_mesh.h"
#include "pointform/geometry/textured_mesh.h"

#include "support/test_meshes.h"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace pointform::test {

/// Height of the bumpy plate over (x, y) ∈ [-1, 1]².
inline double plate_height(double x, double y)
{
    return 0.05 * std::sin(3.0 * x) * std::cos(2.0 * y);
}

/// The plate [-1, 1]² (a 2 × 2 grid base, 8 faces, with a boundary), refined `levels` times,
/// every vertex lifted onto plate_height(), far from the world origin.
inline MultiresMesh plate_hierarchy(std::size_t levels, const Vec3d& origin = {1000.0, -20.0, 3.0})
{
    TriMesh base = square_grid(2);
    base.vertices.origin = origin;
    MultiresMesh mesh(base);
    for (std::size_t l = 0; l <= levels; ++l)
    {
        if (l > 0)
            (void)mesh.split();
        for (Vec3d& x : mesh.mutable_positions())
            x.z() = plate_height(x.x(), x.y());
    }
    return mesh;
}

/// A closed sphere hierarchy: an icosahedron and `levels` levels on the unit sphere.
inline MultiresMesh sphere_hierarchy(std::size_t levels)
{
    MultiresMesh mesh(icosphere(0));
    for (std::size_t l = 0; l < levels; ++l)
    {
        (void)mesh.split();
        for (Vec3d& x : mesh.finest_new_positions())
            x.normalize();
    }
    return mesh;
}

/// A `width` × `height` checker of `cell`-pixel squares, `channels` 3 or 4 (alpha varies by
/// column so that RGBA round trips are not all-opaque).
inline TextureImage checker_image(int width, int height, int channels, int cell = 8)
{
    TextureImage image{.width = width, .height = height, .channels = channels, .pixels = {}};
    image.pixels.reserve(std::size_t(width) * std::size_t(height) * std::size_t(channels));
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x)
        {
            const bool dark = ((x / cell) + (y / cell)) % 2 == 0;
            image.pixels.push_back(dark ? 40 : 230);
            image.pixels.push_back(static_cast<std::uint8_t>(dark ? 60 : (x * 255) / width));
            image.pixels.push_back(static_cast<std::uint8_t>(dark ? 90 : (y * 255) / height));
            if (channels == 4)
                image.pixels.push_back(static_cast<std::uint8_t>(255 - (x % 64)));
        }
    return image;
}

/// A tangent-space normal map of gentle ripples along u: (nx, 0, nz) encoded as RGB.
inline TextureImage ripple_normal_map(int width, int height)
{
    TextureImage image{.width = width, .height = height, .channels = 3, .pixels = {}};
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x)
        {
            const double nx = 0.3 * std::sin(2.0 * M_PI * 4.0 * x / width);
            const double nz = std::sqrt(1.0 - nx * nx);
            image.pixels.push_back(static_cast<std::uint8_t>(std::lround(127.5 * (nx + 1.0))));
            image.pixels.push_back(128);
            image.pixels.push_back(static_cast<std::uint8_t>(std::lround(127.5 * (nz + 1.0))));
        }
    return image;
}

/// Adds to a plate hierarchy's level chain what the texture pipeline would: uvs (u = (x + 1) / 2
/// to the right, v = (1 − y) / 2 down from the top-left corner), a checker colour texture, a
/// normal map and tangents (+x made orthogonal to the normal, w = +1).
inline void add_plate_texture(TexturedMesh& mesh)
{
    mesh.uvs.clear();
    mesh.tangents.clear();
    for (std::size_t v = 0; v < mesh.positions.size(); ++v)
    {
        const Vec3f& p = mesh.positions[v];
        mesh.uvs.emplace_back(0.5F * (p.x() + 1.0F), 0.5F * (1.0F - p.y()));
        const Vec3d n = mesh.normals[v].cast<double>();
        const Vec3d t = (Vec3d::UnitX() - n.dot(Vec3d::UnitX()) * n).normalized();
        mesh.tangents.emplace_back(static_cast<float>(t.x()), static_cast<float>(t.y()),
                                   static_cast<float>(t.z()), 1.0F);
    }
    mesh.base_color = checker_image(64, 48, 3);
    mesh.normal_map = ripple_normal_map(32, 32);
    mesh.name = "textured plate";
}

} // namespace pointform::test
