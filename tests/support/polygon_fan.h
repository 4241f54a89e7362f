// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// One convex polygon of n vertices on the unit circle, as a mesh fan-triangulated from its first
// vertex (what the readers make of it: one vertex in n − 2 triangles) and as OFF, binary PLY
// and OBJ files that store it as a single n-gon. Hostile-input tests for valence.

#pragma once

#include "pointform/geometry/tri_mesh.h"

#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>

namespace pointform::test {

/// Vertex k of the n-gon: (cos 2πk/n, sin 2πk/n, 0), as a float (the precision files store).
inline Vec3f polygon_fan_vertex(std::size_t k, std::size_t n)
{
    const double angle = 2.0 * std::numbers::pi * static_cast<double>(k) / static_cast<double>(n);
    return {static_cast<float>(std::cos(angle)), static_cast<float>(std::sin(angle)), 0.0F};
}

/// The n-gon fan-triangulated from vertex 0: triangles (0, k − 1, k), k = 2 … n − 1,
/// counter-clockwise seen from +z. A disc: one component, one boundary loop, χ = 1.
inline TriMesh polygon_fan_mesh(std::size_t n)
{
    TriMesh mesh;
    mesh.vertices.positions.reserve(n);
    for (std::size_t k = 0; k < n; ++k)
        mesh.vertices.positions.push_back(polygon_fan_vertex(k, n));
    mesh.triangles.reserve(n - 2);
    for (std::size_t k = 2; k < n; ++k)
        mesh.triangles.push_back(
            {0, static_cast<std::uint32_t>(k - 1), static_cast<std::uint32_t>(k)});
    return mesh;
}

namespace detail {

inline void append_number(std::string& out, float value)
{
    char text[32];
    const auto end = std::to_chars(text, text + sizeof(text), value).ptr;
    out.append(text, end);
}

inline void append_number(std::string& out, std::size_t value)
{
    char text[32];
    const auto end = std::to_chars(text, text + sizeof(text), value).ptr;
    out.append(text, end);
}

inline void append_vertex_text(std::string& out, const Vec3f& p)
{
    append_number(out, p.x());
    out += ' ';
    append_number(out, p.y());
    out += ' ';
    append_number(out, p.z());
}

inline void write_bytes(const std::filesystem::path& path, const std::string& bytes)
{
    std::ofstream file(path, std::ios::binary);
    file.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

} // namespace detail

/// OFF: n vertices and one face of n vertices.
inline void write_polygon_fan_off(const std::filesystem::path& path, std::size_t n)
{
    std::string out = "OFF\n" + std::to_string(n) + " 1 0\n";
    for (std::size_t k = 0; k < n; ++k)
    {
        detail::append_vertex_text(out, polygon_fan_vertex(k, n));
        out += '\n';
    }
    detail::append_number(out, n);
    for (std::size_t k = 0; k < n; ++k)
    {
        out += ' ';
        detail::append_number(out, k);
    }
    out += '\n';
    detail::write_bytes(path, out);
}

/// OBJ: n `v` lines and one `f` line with n corners (1-based).
inline void write_polygon_fan_obj(const std::filesystem::path& path, std::size_t n)
{
    std::string out = "# one polygon\n";
    for (std::size_t k = 0; k < n; ++k)
    {
        out += "v ";
        detail::append_vertex_text(out, polygon_fan_vertex(k, n));
        out += '\n';
    }
    out += 'f';
    for (std::size_t k = 0; k < n; ++k)
    {
        out += ' ';
        detail::append_number(out, k + 1);
    }
    out += '\n';
    detail::write_bytes(path, out);
}

/// Binary little-endian PLY: float x y z, one face with a uint-counted list of int indices.
inline void write_polygon_fan_ply(const std::filesystem::path& path, std::size_t n)
{
    static_assert(std::endian::native == std::endian::little, "the test writes native bytes");
    std::string out = "ply\nformat binary_little_endian 1.0\nelement vertex " + std::to_string(n) +
                      "\nproperty float x\nproperty float y\nproperty float z\n"
                      "element face 1\nproperty list uint int vertex_indices\nend_header\n";
    const auto put = [&out](const auto value) {
        char raw[sizeof(value)];
        std::memcpy(raw, &value, sizeof(value));
        out.append(raw, sizeof(value));
    };
    for (std::size_t k = 0; k < n; ++k)
    {
        const Vec3f p = polygon_fan_vertex(k, n);
        put(p.x());
        put(p.y());
        put(p.z());
    }
    put(static_cast<std::uint32_t>(n));
    for (std::size_t k = 0; k < n; ++k)
        put(static_cast<std::int32_t>(k));
    detail::write_bytes(path, out);
}

} // namespace pointform::test
