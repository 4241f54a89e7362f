// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/geometry/level_topology.h"

#include "pointform/core/error.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <string>
#include <utility>

namespace pointform {

void LevelTopology::ring(std::uint32_t start, std::vector<std::uint32_t>& out, bool& closed) const
{
    out.clear();
    std::uint32_t h = start;
    closed = true;
    for (std::size_t guard = 0; guard <= faces.size(); ++guard)
    {
        out.push_back(to(h));
        const std::uint32_t p = prev_of(h);
        if (twin[p] == none)
        {
            out.push_back(from(p));
            closed = false;
            return;
        }
        h = twin[p];
        if (h == start)
            return;
    }
}

LevelTopology level_topology(const MultiresMesh& mesh, MultiresMesh::SplitResult split)
{
    constexpr std::uint32_t none = LevelTopology::none;
    const std::size_t i = split.level - 1;
    LevelTopology level;
    level.faces = std::move(split.faces);
    level.edge_vertex = std::move(split.edge_vertices);
    level.first_new = static_cast<std::uint32_t>(mesh.level_offsets()[i + 1]);
    const std::size_t added = mesh.vertex_count(i + 1) - level.first_new;
    const auto halfedge_count = static_cast<std::uint32_t>(level.edge_vertex.size());
    level.halfedges.assign(added, {none, none});
    for (std::uint32_t h = 0; h < halfedge_count; ++h)
    {
        auto& slot = level.halfedges[level.edge_vertex[h] - level.first_new];
        (slot[0] == none ? slot[0] : slot[1]) = h;
    }
    level.twin.assign(halfedge_count, none);
    for (const auto& [h1, h2] : level.halfedges)
        if (h2 != none)
        {
            level.twin[h1] = h2;
            level.twin[h2] = h1;
        }
    level.outgoing.assign(mesh.vertex_count(i), none);
    for (std::uint32_t h = 0; h < halfedge_count; ++h)
    {
        std::uint32_t& out = level.outgoing[level.from(h)];
        if (out == none || level.twin[h] == none)
            out = h;
    }
    return level;
}

LevelTopology level_topology(const MultiresMesh& mesh, std::size_t level)
{
    if (mesh.level_count() == 0 || level >= mesh.finest_level())
        throw InvalidInput("level_topology: level " + std::to_string(level) +
                           " has no finer level (the hierarchy has " +
                           std::to_string(mesh.level_count()) + " levels)");
    MultiresMesh::SplitResult split;
    split.level = level + 1;
    split.faces = mesh.faces(level);
    split.edge_vertices = mesh.edge_vertices(level);
    return level_topology(mesh, std::move(split));
}

namespace {

/// Weights of the modified butterfly's extraordinary-vertex stencil for valence n (Zorin et al.
/// 1996): the centre gets 3/4, ring vertex j (j = 0 the other end of the edge) gets s[j].
double extraordinary_weight(std::size_t n, std::size_t j)
{
    if (n == 3)
        return j == 0 ? 5.0 / 12.0 : -1.0 / 12.0;
    if (n == 4)
        return j == 0 ? 3.0 / 8.0 : (j == 2 ? -1.0 / 8.0 : 0.0);
    const double t = 2.0 * std::numbers::pi * static_cast<double>(j) / static_cast<double>(n);
    return (0.25 + std::cos(t) + 0.5 * std::cos(2.0 * t)) / static_cast<double>(n);
}

void butterfly_stencil(const LevelTopology& level, std::uint32_t h1, std::uint32_t h2,
                       std::vector<StencilTerm>& out, std::vector<std::uint32_t>& ring)
{
    constexpr std::uint32_t none = LevelTopology::none;
    using L = LevelTopology;
    const std::uint32_t a = level.from(h1);
    const std::uint32_t b = level.to(h1);
    const auto midpoint = [&] {
        out = {{a, 0.5}, {b, 0.5}};
    };
    if (h2 == none)
    {
        // Boundary edge: the 4-point rule along the boundary. The boundary vertex before a:
        // rotate clockwise around a to its incoming boundary halfedge; after b: b's outgoing
        // boundary halfedge.
        const std::uint32_t out_b = level.outgoing[b];
        if (out_b == none || level.twin[out_b] != none)
            return midpoint();
        const std::uint32_t next_vertex = level.to(out_b);
        std::uint32_t h = L::prev_of(h1); // into a
        for (std::size_t guard = 0; level.twin[h] != none && guard <= level.faces.size(); ++guard)
            h = L::prev_of(level.twin[h]);
        if (level.twin[h] != none)
            return midpoint();
        out = {{a, 9.0 / 16.0},
               {b, 9.0 / 16.0},
               {level.from(h), -1.0 / 16.0},
               {next_vertex, -1.0 / 16.0}};
        return;
    }

    // Interior edge: the stencil of each interior end, its ring starting at the other end.
    // Returns the valence, 0 if the end lies on the boundary; appends the terms × scale.
    const auto stencil = [&](std::uint32_t centre, std::uint32_t other, bool append,
                             double scale) -> std::size_t {
        bool closed = false;
        level.ring(level.outgoing[centre], ring, closed);
        if (!closed)
            return 0;
        const auto it = std::find(ring.begin(), ring.end(), other);
        if (it == ring.end())
            return 0;
        std::rotate(ring.begin(), it, ring.end());
        if (append)
        {
            out.push_back({centre, 0.75 * scale});
            for (std::size_t j = 0; j < ring.size(); ++j)
                out.push_back({ring[j], scale * extraordinary_weight(ring.size(), j)});
        }
        return ring.size();
    };
    out.clear();
    const std::size_t valence_a = stencil(a, b, false, 0.0);
    const std::size_t valence_b = stencil(b, a, false, 0.0);
    const bool regular_a = valence_a == 6;
    const bool regular_b = valence_b == 6;
    if ((regular_a && regular_b) || (regular_a && valence_b == 0) || (regular_b && valence_a == 0))
    {
        // Regular ends (one may lie on the boundary): the 8-point butterfly, if its wings exist.
        const std::array<std::uint32_t, 4> sides = {L::next_of(h1), L::prev_of(h1), L::next_of(h2),
                                                    L::prev_of(h2)};
        if (std::all_of(sides.begin(), sides.end(),
                        [&](std::uint32_t h) { return level.twin[h] != none; }))
        {
            out = {{a, 0.5}, {b, 0.5}, {level.opposite(h1), 0.125}, {level.opposite(h2), 0.125}};
            for (const std::uint32_t h : sides)
                out.push_back({level.opposite(level.twin[h]), -0.0625});
            return;
        }
        if (!(regular_a && regular_b))
            return midpoint();
        stencil(a, b, true, 0.5);
        stencil(b, a, true, 0.5);
        return;
    }
    // An irregular interior end: its stencil (both irregular: the average).
    const bool irregular_a = valence_a != 0 && !regular_a;
    const bool irregular_b = valence_b != 0 && !regular_b;
    if (irregular_a && irregular_b)
    {
        stencil(a, b, true, 0.5);
        stencil(b, a, true, 0.5);
    }
    else if (irregular_a)
        stencil(a, b, true, 1.0);
    else if (irregular_b)
        stencil(b, a, true, 1.0);
    else
        midpoint();
}

} // namespace

void prediction_stencil(const LevelTopology& level, std::size_t j, Predictor predictor,
                        std::vector<StencilTerm>& out, std::vector<std::uint32_t>& ring)
{
    const auto [h1, h2] = level.halfedges[j];
    if (predictor == Predictor::Butterfly)
        return butterfly_stencil(level, h1, h2, out, ring);
    out = {{level.from(h1), 0.5}, {level.to(h1), 0.5}};
}

} // namespace pointform
