// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/geometry/mesh_topology.h"

#include "pointform/core/disjoint_sets.h"
#include "pointform/core/error.h"

#include <algorithm>
#include <limits>
#include <string>
#include <vector>

namespace pointform {

namespace {

constexpr std::uint32_t unset = std::numeric_limits<std::uint32_t>::max();

/// Halfedge 3f + j (of triangle f, from corner j to corner j + 1), keyed by its undirected edge
/// (lo, hi) packed as lo · 2³² + hi, so that sorting compares two integers.
struct HalfEdge
{
    std::uint64_t key;
    std::uint32_t index; ///< 3 · face + slot
    bool forward;        ///< traversed lo → hi

    [[nodiscard]] std::uint32_t lo() const { return static_cast<std::uint32_t>(key >> 32U); }
    [[nodiscard]] std::uint32_t hi() const { return static_cast<std::uint32_t>(key); }
    [[nodiscard]] std::uint32_t face() const { return index / 3; }
    /// The corner (3 · face + slot) of the triangle at the edge's lower end, and at its upper.
    [[nodiscard]] std::size_t lo_corner() const
    {
        return forward ? index : index - index % 3 + (index % 3 + 1) % 3;
    }
    [[nodiscard]] std::size_t hi_corner() const
    {
        return forward ? index - index % 3 + (index % 3 + 1) % 3 : index;
    }
};

bool is_degenerate(const Triangle& t)
{
    return t[0] == t[1] || t[1] == t[2] || t[2] == t[0];
}

/// Throws unless every index is a vertex and the corners fit 32-bit union-find indices.
void check_indices(std::span<const Triangle> triangles, std::size_t nv)
{
    if (triangles.size() >= std::numeric_limits<std::uint32_t>::max() / 3)
        throw InvalidInput("mesh: " + std::to_string(triangles.size()) +
                           " triangles, too many for 32-bit corner indices");
    for (std::size_t f = 0; f < triangles.size(); ++f)
        for (const std::uint32_t v : triangles[f])
            if (v >= nv)
                throw InvalidInput("mesh: triangle " + std::to_string(f) + " references vertex " +
                                   std::to_string(v) + " of " + std::to_string(nv));
}

/// The halfedges of the non-degenerate triangles, sorted by edge, then triangle, then slot, so
/// that the halfedges of one edge are adjacent: a counting sort by the edge's lower end (linear),
/// then a sort of each vertex's bucket by the upper end (buckets hold a vertex's valence, so
/// this costs O(Σ d log d) ≤ O(F log F)). `nv` bounds every index.
std::vector<HalfEdge> sorted_halfedges(std::span<const Triangle> triangles, std::size_t nv)
{
    std::vector<std::size_t> start(nv + 1, 0);
    for (const Triangle& t : triangles)
        if (!is_degenerate(t))
            for (std::size_t j = 0; j < 3; ++j)
                ++start[std::min(t[j], t[(j + 1) % 3]) + 1];
    for (std::size_t v = 0; v < nv; ++v)
        start[v + 1] += start[v];
    std::vector<HalfEdge> half(start[nv]);
    {
        std::vector<std::size_t> fill(start.begin(), start.end() - 1);
        for (std::size_t f = 0; f < triangles.size(); ++f)
        {
            const Triangle& t = triangles[f];
            if (is_degenerate(t))
                continue;
            for (std::size_t j = 0; j < 3; ++j)
            {
                const std::uint32_t a = t[j];
                const std::uint32_t b = t[(j + 1) % 3];
                half[fill[std::min(a, b)]++] = {
                    (std::uint64_t{std::min(a, b)} << 32U) | std::max(a, b),
                    static_cast<std::uint32_t>(3 * f + j), a < b};
            }
        }
    }
    for (std::size_t v = 0; v < nv; ++v)
        if (start[v + 1] - start[v] > 1)
            std::sort(half.begin() + static_cast<std::ptrdiff_t>(start[v]),
                      half.begin() + static_cast<std::ptrdiff_t>(start[v + 1]),
                      [](const HalfEdge& x, const HalfEdge& y) {
                          return x.key != y.key ? x.key < y.key : x.index < y.index;
                      });
    return half;
}

/// Calls visit(begin, end) for every run of halfedges of one edge in `half` (sorted).
template <typename Visit>
void for_each_edge(const std::vector<HalfEdge>& half, Visit&& visit)
{
    for (std::size_t i = 0; i < half.size();)
    {
        std::size_t j = i + 1;
        while (j < half.size() && half[j].key == half[i].key)
            ++j;
        visit(i, j);
        i = j;
    }
}

/// The fans from the sorted halfedges: the corners of two triangles at vertex v are joined
/// when the triangles share an edge (v, x), which makes each fan one union-find set of corners
/// (corners at different vertices are never joined). Linear in the halfedges, up to the
/// inverse-Ackermann factor.
VertexFans fans_from(std::span<const Triangle> triangles, std::size_t nv,
                     const std::vector<HalfEdge>& half)
{
    const std::size_t nf = triangles.size();
    DisjointSets corners(3 * nf);
    for_each_edge(half, [&](std::size_t i, std::size_t j) {
        for (std::size_t k = i + 1; k < j; ++k)
        {
            corners.unite(half[i].lo_corner(), half[k].lo_corner());
            corners.unite(half[i].hi_corner(), half[k].hi_corner());
        }
    });

    VertexFans out;
    out.offsets.assign(nv + 1, 0);
    for (const Triangle& t : triangles)
        if (!is_degenerate(t))
            for (const std::uint32_t v : t)
                ++out.offsets[v + 1];
    for (std::size_t v = 0; v < nv; ++v)
        out.offsets[v + 1] += out.offsets[v];
    // Corner ids (3f + slot) per vertex, in triangle order.
    std::vector<std::uint32_t> corner(out.offsets.back());
    out.faces.resize(out.offsets.back());
    {
        std::vector<std::size_t> fill(out.offsets.begin(), out.offsets.end() - 1);
        for (std::size_t f = 0; f < nf; ++f)
        {
            if (is_degenerate(triangles[f]))
                continue;
            for (std::size_t k = 0; k < 3; ++k)
            {
                const std::size_t at = fill[triangles[f][k]]++;
                corner[at] = static_cast<std::uint32_t>(3 * f + k);
                out.faces[at] = static_cast<std::uint32_t>(f);
            }
        }
    }
    out.fan.resize(corner.size());
    out.fan_count.assign(nv, 0);
    std::vector<std::uint32_t> number(3 * nf, unset); // fan number of each set's root
    for (std::size_t v = 0; v < nv; ++v)
    {
        for (std::size_t c = out.offsets[v]; c < out.offsets[v + 1]; ++c)
        {
            const std::size_t root = corners.find(corner[c]);
            if (number[root] == unset)
                number[root] = out.fan_count[v]++;
            out.fan[c] = number[root];
        }
    }
    return out;
}

} // namespace

VertexFans vertex_fans(std::span<const Triangle> triangles, std::size_t vertex_count)
{
    check_indices(triangles, vertex_count);
    return fans_from(triangles, vertex_count, sorted_halfedges(triangles, vertex_count));
}

MeshTopology analyze_topology(const TriMesh& mesh)
{
    MeshTopology topo;
    const std::size_t nv = mesh.vertex_count();
    const std::size_t nf = mesh.face_count();
    const std::span<const Triangle> triangles = mesh.triangles;
    check_indices(triangles, nv);
    topo.faces = nf;

    std::vector<bool> used(nv, false);
    for (const Triangle& t : triangles)
    {
        for (const std::uint32_t v : t)
            used[v] = true;
        if (is_degenerate(t))
            ++topo.degenerate_faces;
    }
    topo.vertices = static_cast<std::size_t>(std::count(used.begin(), used.end(), true));
    const std::vector<HalfEdge> half = sorted_halfedges(triangles, nv);

    DisjointSets faces(nf);
    // Boundary edges, joined into loops through their vertices.
    DisjointSets boundary(nv);
    std::vector<std::uint32_t> boundary_degree(nv, 0);
    for_each_edge(half, [&](std::size_t i, std::size_t j) {
        const std::size_t count = j - i;
        ++topo.edges;
        if (count == 1)
        {
            ++topo.boundary_edges;
            boundary.unite(half[i].lo(), half[i].hi());
            ++boundary_degree[half[i].lo()];
            ++boundary_degree[half[i].hi()];
        }
        else if (count == 2)
        {
            if (half[i].forward == half[i + 1].forward)
                ++topo.misoriented_edges;
            faces.unite(half[i].face(), half[i + 1].face());
        }
        else
        {
            ++topo.non_manifold_edges;
            for (std::size_t k = i + 1; k < j; ++k)
                faces.unite(half[i].face(), half[k].face());
        }
    });

    // Components of non-degenerate faces.
    std::vector<bool> root(nf, false);
    for (std::size_t f = 0; f < nf; ++f)
        if (!is_degenerate(triangles[f]))
            root[faces.find(f)] = true;
    topo.components = static_cast<std::size_t>(std::count(root.begin(), root.end(), true));

    // Boundary loops: components of the boundary-edge graph (a vertex where two loops touch
    // makes them one, and is counted as non-manifold below).
    std::vector<bool> loop_root(nv, false);
    for (std::size_t v = 0; v < nv; ++v)
        if (boundary_degree[v] > 0)
            loop_root[boundary.find(v)] = true;
    topo.boundary_loops =
        static_cast<std::size_t>(std::count(loop_root.begin(), loop_root.end(), true));

    const VertexFans fans = fans_from(triangles, nv, half);
    topo.non_manifold_vertices = static_cast<std::size_t>(std::count_if(
        fans.fan_count.begin(), fans.fan_count.end(), [](std::uint32_t n) { return n > 1; }));

    topo.euler_characteristic = static_cast<std::int64_t>(topo.vertices) -
                                static_cast<std::int64_t>(topo.edges) +
                                static_cast<std::int64_t>(topo.faces - topo.degenerate_faces);
    return topo;
}

std::size_t split_nonmanifold_vertices(TriMesh& mesh)
{
    const std::size_t nv = mesh.vertex_count();
    const VertexFans fans = vertex_fans(mesh.triangles, nv);
    std::size_t added = 0;
    PointCloud& v = mesh.vertices;
    for (std::size_t i = 0; i < nv; ++i)
    {
        const std::uint32_t count = fans.fan_count[i];
        if (count < 2)
            continue;
        const auto first_new = static_cast<std::uint32_t>(v.size());
        for (std::uint32_t extra = 1; extra < count; ++extra)
        {
            v.positions.push_back(v.positions[i]);
            if (v.has_normals())
                v.normals.push_back(v.normals[i]);
            if (v.has_colors())
                v.colors.push_back(v.colors[i]);
            if (v.has_radii())
                v.radii.push_back(v.radii[i]);
            ++added;
        }
        const auto faces = fans.faces_of(i);
        const auto fan = fans.fans_of(i);
        for (std::size_t a = 0; a < faces.size(); ++a)
        {
            if (fan[a] == 0)
                continue;
            for (std::uint32_t& corner : mesh.triangles[faces[a]])
                if (corner == i)
                    corner = first_new + fan[a] - 1;
        }
    }
    return added;
}

std::size_t keep_faces(TriMesh& mesh, std::span<const std::uint8_t> keep)
{
    PF_ASSERT(keep.size() == mesh.face_count());
    std::vector<std::uint8_t> used(mesh.vertex_count(), 0);
    std::size_t kept = 0;
    for (std::size_t f = 0; f < mesh.face_count(); ++f)
        if (keep[f] != 0)
        {
            mesh.triangles[kept++] = mesh.triangles[f];
            for (const std::uint32_t v : mesh.triangles[f])
                used[v] = 1;
        }
    const std::size_t removed = mesh.face_count() - kept;
    mesh.triangles.resize(kept);
    if (removed == 0)
        return 0;
    std::vector<std::uint32_t> remap(used.size()); // new index of each used vertex
    std::uint32_t next = 0;
    for (std::size_t v = 0; v < used.size(); ++v)
    {
        remap[v] = next;
        next += used[v];
    }
    for (Triangle& t : mesh.triangles)
        for (std::uint32_t& v : t)
            v = remap[v];
    keep_points(mesh.vertices, used);
    return removed;
}

} // namespace pointform
