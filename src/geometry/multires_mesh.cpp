// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/geometry/multires_mesh.h"

#include "pointform/core/error.h"
#include "pointform/geometry/mesh_topology.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

namespace pointform {

namespace {

constexpr std::size_t max_index = std::numeric_limits<std::uint32_t>::max() - 1;

std::string edge_name(std::uint32_t a, std::uint32_t b)
{
    return "(" + std::to_string(a) + ", " + std::to_string(b) + ")";
}

/// Number of undirected edges of an oriented manifold with these faces (each edge has one or
/// two halfedges, in opposite directions): interior edges are counted from their halfedge with
/// a < b, boundary edges from their only halfedge.
std::size_t count_edges(std::span<const Triangle> faces)
{
    std::vector<std::uint64_t> keys;
    keys.reserve(3 * faces.size());
    for (const Triangle& t : faces)
        for (int k = 0; k < 3; ++k)
        {
            const std::uint32_t a = t[static_cast<std::size_t>(k)];
            const std::uint32_t b = t[static_cast<std::size_t>((k + 1) % 3)];
            keys.push_back((std::uint64_t{std::min(a, b)} << 32) | std::max(a, b));
        }
    std::sort(keys.begin(), keys.end());
    return static_cast<std::size_t>(std::unique(keys.begin(), keys.end()) - keys.begin());
}

/// For each halfedge of `faces` (a level with `level_vertices` vertices), the vertex among
/// `parents` (those of the next level, the first being `first_vertex`) that splits its edge.
/// Throws unless the parents name every edge of `faces` exactly once and nothing else.
std::vector<std::uint32_t> match_edge_vertices(std::span<const Triangle> faces,
                                               std::size_t level_vertices,
                                               std::span<const ParentEdge> parents,
                                               std::size_t first_vertex, std::size_t level)
{
    const std::string where = "multires mesh level " + std::to_string(level + 1) + ": ";
    // Bucket the new vertices by the lower end of their parent edge (CSR), each bucket sorted
    // by the upper end, so a lookup is a binary search even in a hostile file.
    std::vector<std::size_t> start(level_vertices + 1, 0);
    for (std::size_t i = 0; i < parents.size(); ++i)
    {
        const ParentEdge& e = parents[i];
        const std::size_t v = first_vertex + i;
        if (e.a >= level_vertices || e.b >= level_vertices)
            throw InvalidInput(where + "vertex " + std::to_string(v) + " has parent edge " +
                               edge_name(e.a, e.b) + " with an end outside level " +
                               std::to_string(level) + " (" + std::to_string(level_vertices) +
                               " vertices)");
        if (e.a == e.b)
            throw InvalidInput(where + "vertex " + std::to_string(v) + " has a degenerate parent " +
                               "edge " + edge_name(e.a, e.b));
        ++start[std::min(e.a, e.b) + 1];
    }
    for (std::size_t i = 0; i < level_vertices; ++i)
        start[i + 1] += start[i];
    std::vector<std::pair<std::uint32_t, std::uint32_t>> bucket(parents.size()); // (upper, v)
    {
        std::vector<std::size_t> fill(start.begin(), start.end() - 1);
        for (std::size_t i = 0; i < parents.size(); ++i)
        {
            const ParentEdge& e = parents[i];
            bucket[fill[std::min(e.a, e.b)]++] = {std::max(e.a, e.b),
                                                  static_cast<std::uint32_t>(first_vertex + i)};
        }
    }
    for (std::size_t lo = 0; lo < level_vertices; ++lo)
    {
        const auto begin = bucket.begin() + static_cast<std::ptrdiff_t>(start[lo]);
        const auto end = bucket.begin() + static_cast<std::ptrdiff_t>(start[lo + 1]);
        std::sort(begin, end);
        const auto dup = std::adjacent_find(
            begin, end, [](const auto& x, const auto& y) { return x.first == y.first; });
        if (dup != end)
            throw InvalidInput(where + "vertices " + std::to_string(dup->second) + " and " +
                               std::to_string((dup + 1)->second) + " split the same edge " +
                               edge_name(static_cast<std::uint32_t>(lo), dup->first));
    }

    std::vector<std::uint32_t> result(3 * faces.size());
    std::vector<char> used(parents.size(), 0);
    for (std::size_t f = 0; f < faces.size(); ++f)
        for (std::size_t k = 0; k < 3; ++k)
        {
            const std::uint32_t a = faces[f][k];
            const std::uint32_t b = faces[f][(k + 1) % 3];
            const std::uint32_t lo = std::min(a, b);
            const std::uint32_t hi = std::max(a, b);
            const auto begin = bucket.begin() + static_cast<std::ptrdiff_t>(start[lo]);
            const auto end = bucket.begin() + static_cast<std::ptrdiff_t>(start[lo + 1]);
            const auto it = std::lower_bound(
                begin, end, hi, [](const auto& x, std::uint32_t value) { return x.first < value; });
            if (it == end || it->first != hi)
                throw InvalidInput(where + "edge " + edge_name(a, b) + " of level " +
                                   std::to_string(level) + " has no vertex splitting it");
            result[3 * f + k] = it->second;
            used[it->second - first_vertex] = 1;
        }
    for (std::size_t i = 0; i < parents.size(); ++i)
        if (used[i] == 0)
            throw InvalidInput(where + "vertex " + std::to_string(first_vertex + i) +
                               " has parent edge " + edge_name(parents[i].a, parents[i].b) +
                               ", which is not an edge of level " + std::to_string(level));
    return result;
}

/// The 1-to-4 split of `faces` given the vertex of each halfedge.
std::vector<Triangle> split_faces(std::span<const Triangle> faces,
                                  std::span<const std::uint32_t> edge_vertex)
{
    std::vector<Triangle> out(4 * faces.size());
    for (std::size_t f = 0; f < faces.size(); ++f)
    {
        const auto [a, b, c] = faces[f];
        const std::uint32_t ab = edge_vertex[3 * f];
        const std::uint32_t bc = edge_vertex[3 * f + 1];
        const std::uint32_t ca = edge_vertex[3 * f + 2];
        out[4 * f] = {a, ab, ca};
        out[4 * f + 1] = {ab, b, bc};
        out[4 * f + 2] = {ca, bc, c};
        out[4 * f + 3] = {ab, bc, ca};
    }
    return out;
}

} // namespace

Predictor parse_predictor(std::string_view text)
{
    if (text == "midpoint")
        return Predictor::Midpoint;
    if (text == "butterfly")
        return Predictor::Butterfly;
    throw InvalidInput("unknown predictor '" + std::string(text) +
                       "' (expected midpoint or butterfly)");
}

std::string_view to_string(Predictor predictor)
{
    return predictor == Predictor::Butterfly ? "butterfly" : "midpoint";
}

MultiresMesh::MultiresMesh(const TriMesh& base)
{
    parts_.origin = base.vertices.origin;
    parts_.positions.reserve(base.vertex_count());
    for (const Vec3f& p : base.vertices.positions)
        parts_.positions.push_back(p.cast<double>());
    parts_.base_faces = base.triangles;
    parts_.level_offsets = {0, base.vertex_count()};
    validate();
}

MultiresMesh::MultiresMesh(MultiresParts parts) : parts_(std::move(parts))
{
    validate();
}

void MultiresMesh::validate() const
{
    const std::string where = "multires mesh: ";
    const MultiresParts& p = parts_;
    if (!p.origin.allFinite())
        throw InvalidInput(where + "the origin is not finite");
    if (p.level_offsets.size() < 2)
        throw InvalidInput(where + "no level (level offsets need at least 2 entries, got " +
                           std::to_string(p.level_offsets.size()) + ")");
    if (p.level_offsets[0] != 0)
        throw InvalidInput(where + "the first level offset must be 0");
    for (std::size_t i = 1; i < p.level_offsets.size(); ++i)
        if (p.level_offsets[i] <= p.level_offsets[i - 1])
            throw InvalidInput(where + "level offsets must increase (entry " + std::to_string(i) +
                               " is " + std::to_string(p.level_offsets[i]) + ")");
    if (p.level_offsets.back() != p.positions.size())
        throw InvalidInput(where + "the last level offset (" +
                           std::to_string(p.level_offsets.back()) + ") differs from the " +
                           "number of positions (" + std::to_string(p.positions.size()) + ")");
    if (p.positions.size() > max_index)
        throw InvalidInput(where + "too many vertices for 32-bit indices");
    const std::size_t base_vertices = p.level_offsets[1];
    if (p.parent_edges.size() != p.positions.size() - base_vertices)
        throw InvalidInput(where + "expected " +
                           std::to_string(p.positions.size() - base_vertices) +
                           " parent edges (one per non-base vertex), got " +
                           std::to_string(p.parent_edges.size()));
    for (std::size_t v = 0; v < p.positions.size(); ++v)
        if (!p.positions[v].allFinite())
            throw InvalidInput(where + "position of vertex " + std::to_string(v) +
                               " is not finite");

    // The base: an oriented manifold using every one of its vertices.
    if (p.base_faces.empty())
        throw InvalidInput(where + "the base mesh has no faces");
    std::vector<char> used(base_vertices, 0);
    for (std::size_t f = 0; f < p.base_faces.size(); ++f)
    {
        const Triangle& t = p.base_faces[f];
        for (const std::uint32_t v : t)
        {
            if (v >= base_vertices)
                throw InvalidInput(where + "base face " + std::to_string(f) +
                                   " references vertex " + std::to_string(v) + " of " +
                                   std::to_string(base_vertices));
            used[v] = 1;
        }
        if (t[0] == t[1] || t[1] == t[2] || t[2] == t[0])
            throw InvalidInput(where + "base face " + std::to_string(f) + " is degenerate");
    }
    for (std::size_t v = 0; v < base_vertices; ++v)
        if (used[v] == 0)
            throw InvalidInput(where + "base vertex " + std::to_string(v) + " is in no face");
    {
        TriMesh combinatorial;
        combinatorial.vertices.positions.assign(base_vertices, Vec3f::Zero());
        combinatorial.triangles = p.base_faces;
        const MeshTopology topology = analyze_topology(combinatorial);
        if (!topology.is_oriented_manifold())
            throw InvalidInput(
                where + "the base mesh is not an oriented manifold (" +
                std::to_string(topology.non_manifold_edges) + " non-manifold edges, " +
                std::to_string(topology.non_manifold_vertices) + " non-manifold vertices, " +
                std::to_string(topology.misoriented_edges) + " misoriented edges)");
    }

    // Counts first (cheap), then the parent edges level by level.
    const std::size_t levels = p.level_offsets.size() - 1;
    std::size_t faces = p.base_faces.size();
    std::size_t edges = count_edges(p.base_faces);
    for (std::size_t level = 1; level < levels; ++level)
    {
        const std::size_t added = p.level_offsets[level + 1] - p.level_offsets[level];
        if (added != edges)
            throw InvalidInput(where + "level " + std::to_string(level) + " adds " +
                               std::to_string(added) + " vertices, but level " +
                               std::to_string(level - 1) + " has " + std::to_string(edges) +
                               " edges (wrong level offsets)");
        if (faces > max_index / 4)
            throw InvalidInput(where + "too many faces for 32-bit indices");
        edges = 2 * edges + 3 * faces;
        faces *= 4;
    }
    std::vector<Triangle> level_faces = p.base_faces;
    for (std::size_t level = 0; level + 1 < levels; ++level)
    {
        const std::span<const ParentEdge> parents(
            p.parent_edges.data() + (p.level_offsets[level + 1] - base_vertices),
            p.level_offsets[level + 2] - p.level_offsets[level + 1]);
        const std::vector<std::uint32_t> ev = match_edge_vertices(
            level_faces, p.level_offsets[level + 1], parents, p.level_offsets[level + 1], level);
        if (level + 2 < levels)
            level_faces = split_faces(level_faces, ev);
    }
}

std::size_t MultiresMesh::vertex_count(std::size_t level) const
{
    if (level >= level_count())
        throw InvalidInput("multires mesh: no level " + std::to_string(level) + " (" +
                           std::to_string(level_count()) + " levels)");
    return parts_.level_offsets[level + 1];
}

std::size_t MultiresMesh::face_count(std::size_t level) const
{
    if (level >= level_count())
        throw InvalidInput("multires mesh: no level " + std::to_string(level) + " (" +
                           std::to_string(level_count()) + " levels)");
    return parts_.base_faces.size() << (2 * level);
}

std::size_t MultiresMesh::level_of_vertex(std::uint32_t v) const
{
    if (v >= parts_.positions.size())
        throw InvalidInput("multires mesh: no vertex " + std::to_string(v));
    const auto it =
        std::upper_bound(parts_.level_offsets.begin() + 1, parts_.level_offsets.end(), v);
    return static_cast<std::size_t>(it - parts_.level_offsets.begin()) - 1;
}

ParentEdge MultiresMesh::parent_edge(std::uint32_t v) const
{
    if (level_count() == 0 || v >= parts_.positions.size() || v < parts_.level_offsets[1])
        throw InvalidInput("multires mesh: vertex " + std::to_string(v) +
                           " has no parent edge (base vertex or out of range)");
    return parts_.parent_edges[v - parts_.level_offsets[1]];
}

std::vector<std::uint32_t> MultiresMesh::edge_vertices(std::size_t level) const
{
    if (level_count() == 0 || level >= finest_level())
        throw InvalidInput("multires mesh: edge vertices of level " + std::to_string(level) +
                           " need a level above it");
    const std::vector<Triangle> level_faces = faces(level);
    const std::size_t first = parts_.level_offsets[level + 1];
    const std::span<const ParentEdge> parents(
        parts_.parent_edges.data() + (first - parts_.level_offsets[1]),
        parts_.level_offsets[level + 2] - first);
    return match_edge_vertices(level_faces, first, parents, first, level);
}

std::vector<Triangle> MultiresMesh::faces(std::size_t level) const
{
    if (level >= level_count())
        throw InvalidInput("multires mesh: no level " + std::to_string(level) + " (" +
                           std::to_string(level_count()) + " levels)");
    std::vector<Triangle> result = parts_.base_faces;
    for (std::size_t l = 0; l < level; ++l)
    {
        const std::size_t first = parts_.level_offsets[l + 1];
        const std::span<const ParentEdge> parents(
            parts_.parent_edges.data() + (first - parts_.level_offsets[1]),
            parts_.level_offsets[l + 2] - first);
        result = split_faces(result, match_edge_vertices(result, first, parents, first, l));
    }
    return result;
}

TriMesh MultiresMesh::level_mesh(std::size_t level) const
{
    TriMesh mesh;
    mesh.triangles = faces(level);
    mesh.vertices.origin = parts_.origin;
    const std::size_t n = vertex_count(level);
    mesh.vertices.positions.reserve(n);
    for (std::size_t v = 0; v < n; ++v)
        mesh.vertices.positions.push_back(parts_.positions[v].cast<float>());
    return mesh;
}

MultiresMesh::SplitResult MultiresMesh::split()
{
    if (level_count() == 0)
        throw InvalidInput("multires mesh: cannot split an empty hierarchy");
    const std::size_t level = finest_level();
    std::vector<Triangle> level_faces = faces(level);
    const std::size_t halfedges = 3 * level_faces.size();
    if (level_faces.size() > max_index / 4)
        throw InvalidInput("multires mesh: level " + std::to_string(level + 1) +
                           " would have more faces than 32-bit indices allow");

    // Group the halfedges of each edge (sorted by edge key, then halfedge index), so that the
    // first halfedge of each group in face order names the edge.
    std::vector<std::pair<std::uint64_t, std::uint32_t>> keyed(halfedges);
    for (std::size_t f = 0; f < level_faces.size(); ++f)
        for (std::size_t k = 0; k < 3; ++k)
        {
            const std::uint32_t a = level_faces[f][k];
            const std::uint32_t b = level_faces[f][(k + 1) % 3];
            keyed[3 * f + k] = {(std::uint64_t{std::min(a, b)} << 32) | std::max(a, b),
                                static_cast<std::uint32_t>(3 * f + k)};
        }
    std::sort(keyed.begin(), keyed.end());
    std::vector<std::uint32_t> representative(halfedges);
    for (std::size_t i = 0; i < halfedges;)
    {
        std::size_t j = i;
        while (j < halfedges && keyed[j].first == keyed[i].first)
            representative[keyed[j++].second] = keyed[i].second;
        i = j;
    }
    const std::size_t first = parts_.positions.size();
    std::size_t edges = 0;
    for (std::size_t h = 0; h < halfedges; ++h)
        if (representative[h] == h)
            ++edges;
    if (first + edges > max_index)
        throw InvalidInput("multires mesh: level " + std::to_string(level + 1) +
                           " would have more vertices than 32-bit indices allow");

    std::vector<std::uint32_t> vertex_of(halfedges);
    parts_.positions.reserve(first + edges);
    parts_.parent_edges.reserve(parts_.parent_edges.size() + edges);
    for (std::size_t h = 0; h < halfedges; ++h)
    {
        if (representative[h] != h)
        {
            vertex_of[h] = vertex_of[representative[h]];
            continue;
        }
        const std::uint32_t a = level_faces[h / 3][h % 3];
        const std::uint32_t b = level_faces[h / 3][(h % 3 + 1) % 3];
        vertex_of[h] = static_cast<std::uint32_t>(parts_.positions.size());
        parts_.positions.push_back(0.5 * (parts_.positions[a] + parts_.positions[b]));
        parts_.parent_edges.push_back({a, b});
    }
    parts_.level_offsets.push_back(parts_.positions.size());
    return {level + 1, std::move(level_faces), std::move(vertex_of)};
}

std::span<Vec3d> MultiresMesh::finest_new_positions()
{
    if (level_count() < 2)
        return {};
    const std::size_t first = parts_.level_offsets[level_count() - 1];
    return {parts_.positions.data() + first, parts_.positions.size() - first};
}

void MultiresMesh::truncate(std::size_t level)
{
    if (level >= level_count())
        throw InvalidInput("multires mesh: no level " + std::to_string(level) + " (" +
                           std::to_string(level_count()) + " levels)");
    parts_.level_offsets.resize(level + 2);
    parts_.positions.resize(parts_.level_offsets.back());
    parts_.parent_edges.resize(parts_.positions.size() - parts_.level_offsets[1]);
}

} // namespace pointform
