// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// Small analytic meshes for tests: an icosphere, a box, a square grid.

#pragma once

#include "pointform/geometry/tri_mesh.h"

#include <cmath>
#include <cstdint>
#include <map>
#include <utility>

namespace pointform::test {

/// Icosahedron subdivided `levels` times, vertices projected on the sphere (centre, radius);
/// outward-oriented triangles.
inline TriMesh icosphere(int levels, const Vec3d& centre = Vec3d::Zero(), double radius = 1.0)
{
    const double g = (1.0 + std::sqrt(5.0)) / 2.0;
    std::vector<Vec3d> v = {{-1, g, 0}, {1, g, 0}, {-1, -g, 0}, {1, -g, 0},
                            {0, -1, g}, {0, 1, g}, {0, -1, -g}, {0, 1, -g},
                            {g, 0, -1}, {g, 0, 1}, {-g, 0, -1}, {-g, 0, 1}};
    for (auto& p : v)
        p.normalize();
    std::vector<Triangle> f = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                               {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                               {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                               {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
    for (int level = 0; level < levels; ++level)
    {
        std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> midpoints;
        const auto midpoint = [&](std::uint32_t a, std::uint32_t b) {
            const auto key = std::minmax(a, b);
            const auto it = midpoints.find(key);
            if (it != midpoints.end())
                return it->second;
            v.push_back((v[a] + v[b]).normalized());
            const auto index = static_cast<std::uint32_t>(v.size() - 1);
            midpoints.emplace(key, index);
            return index;
        };
        std::vector<Triangle> next;
        for (const auto& t : f)
        {
            const std::uint32_t ab = midpoint(t[0], t[1]);
            const std::uint32_t bc = midpoint(t[1], t[2]);
            const std::uint32_t ca = midpoint(t[2], t[0]);
            next.push_back({t[0], ab, ca});
            next.push_back({t[1], bc, ab});
            next.push_back({t[2], ca, bc});
            next.push_back({ab, bc, ca});
        }
        f = std::move(next);
    }
    TriMesh mesh;
    mesh.vertices.origin = centre;
    for (const auto& p : v)
        mesh.vertices.positions.push_back((radius * p).cast<float>());
    mesh.triangles = std::move(f);
    return mesh;
}

/// Axis-aligned box [lo, hi] as 12 outward triangles.
inline TriMesh box_mesh(const Vec3d& lo, const Vec3d& hi)
{
    TriMesh mesh;
    for (int i = 0; i < 8; ++i)
        mesh.vertices.positions.emplace_back(static_cast<float>((i & 1) != 0 ? hi.x() : lo.x()),
                                             static_cast<float>((i & 2) != 0 ? hi.y() : lo.y()),
                                             static_cast<float>((i & 4) != 0 ? hi.z() : lo.z()));
    mesh.triangles = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}, {0, 1, 5}, {0, 5, 4},
                      {2, 6, 7}, {2, 7, 3}, {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};
    return mesh;
}

/// The square [-1, 1]² at z = 0 as an n by n grid of triangle pairs.
inline TriMesh square_grid(std::uint32_t n)
{
    TriMesh mesh;
    for (std::uint32_t j = 0; j <= n; ++j)
        for (std::uint32_t i = 0; i <= n; ++i)
            mesh.vertices.positions.emplace_back(
                -1.0F + 2.0F * static_cast<float>(i) / static_cast<float>(n),
                -1.0F + 2.0F * static_cast<float>(j) / static_cast<float>(n), 0.0F);
    for (std::uint32_t j = 0; j < n; ++j)
        for (std::uint32_t i = 0; i < n; ++i)
        {
            const std::uint32_t v = j * (n + 1) + i;
            mesh.triangles.push_back({v, v + 1, v + n + 2});
            mesh.triangles.push_back({v, v + n + 2, v + n + 1});
        }
    return mesh;
}

} // namespace pointform::test
