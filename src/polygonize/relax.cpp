// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "relax.h"

#include "pointform/core/parallel.h"
#include "pointform/spatial/triangle_bvh.h"

#include <algorithm>
#include <limits>
#include <vector>

namespace pointform::detail {
namespace {

/// Free vertices per parallel block.
constexpr std::size_t relax_block = 512;

Vec3d area_normal(const Vec3d& a, const Vec3d& b, const Vec3d& c)
{
    return (b - a).cross(c - b);
}

} // namespace

void relax_tangentially(std::span<Vec3d> x, std::span<const Triangle> faces,
                        std::span<const std::uint32_t> ring_offsets,
                        std::span<const std::uint32_t> ring_adjacent,
                        std::span<const std::uint32_t> free, int rounds)
{
    std::vector<std::uint32_t> slot(x.size(), std::numeric_limits<std::uint32_t>::max());
    for (std::size_t i = 0; i < free.size(); ++i)
        slot[free[i]] = static_cast<std::uint32_t>(i);
    std::vector<std::uint32_t> touching;
    for (std::size_t f = 0; f < faces.size(); ++f)
        if (std::any_of(faces[f].begin(), faces[f].end(), [&slot](std::uint32_t v) {
                return slot[v] != std::numeric_limits<std::uint32_t>::max();
            }))
            touching.push_back(static_cast<std::uint32_t>(f));
    if (touching.empty())
        return;
    // The faired surface, which every moved vertex is put back on.
    TriMesh reference;
    {
        std::vector<std::uint32_t> local(x.size(), std::numeric_limits<std::uint32_t>::max());
        reference.triangles.reserve(touching.size());
        for (const std::uint32_t f : touching)
        {
            Triangle t{};
            for (std::size_t c = 0; c < 3; ++c)
            {
                const std::uint32_t v = faces[f][c];
                if (local[v] == std::numeric_limits<std::uint32_t>::max())
                {
                    local[v] = static_cast<std::uint32_t>(reference.vertices.positions.size());
                    reference.vertices.positions.push_back(x[v].cast<float>());
                }
                t[c] = local[v];
            }
            reference.triangles.push_back(t);
        }
    }
    const TriangleBvh surface(reference);
    std::vector<Vec3d> normal(free.size());
    std::vector<Vec3d> next(free.size());
    for (int round = 0; round < rounds; ++round)
    {
        const bool project = round + 1 == rounds;
        std::fill(normal.begin(), normal.end(), Vec3d::Zero());
        for (const std::uint32_t f : touching)
        {
            const Triangle& t = faces[f];
            const Vec3d n = area_normal(x[t[0]], x[t[1]], x[t[2]]);
            for (const std::uint32_t v : t)
                if (slot[v] != std::numeric_limits<std::uint32_t>::max())
                    normal[slot[v]] += n;
        }
        parallel_blocks(free.size(), relax_block, [&](std::size_t begin, std::size_t end) {
            for (std::size_t i = begin; i < end; ++i)
            {
                const std::uint32_t v = free[i];
                next[i] = x[v];
                const double length = normal[i].norm();
                if (!(length > 0.0) || ring_offsets[v + 1] == ring_offsets[v])
                    continue;
                const Vec3d n = normal[i] / length;
                Vec3d mean = Vec3d::Zero();
                for (std::uint32_t e = ring_offsets[v]; e < ring_offsets[v + 1]; ++e)
                    mean += x[ring_adjacent[e]];
                mean /= static_cast<double>(ring_offsets[v + 1] - ring_offsets[v]);
                const Vec3d move = mean - x[v];
                next[i] = x[v] + move - move.dot(n) * n;
                if (project)
                {
                    const TriangleBvh::Hit hit = surface.closest(next[i]);
                    if (hit.found())
                        next[i] = hit.point;
                }
            }
        });
        for (std::size_t i = 0; i < free.size(); ++i)
            x[free[i]] = next[i];
    }
}

} // namespace pointform::detail
