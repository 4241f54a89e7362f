// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/geometry/mesh_topology.h"

#include "pointform/core/disjoint_sets.h"
#include "pointform/core/error.h"

#include <algorithm>
#include <limits>
#include <numeric>
#include <string>
#include <vector>

namespace pointform {

namespace {

struct HalfEdge
{
    std::uint32_t lo;
    std::uint32_t hi;
    bool forward; ///< traversed lo → hi
    std::uint32_t face;
};

/// The triangles around one vertex grouped into fans: two triangles are in one fan when a chain
/// of triangles sharing edges through the vertex joins them.
struct VertexFans
{
    std::vector<std::uint32_t> faces; ///< triangles using the vertex
    std::vector<std::uint32_t> fan;   ///< fan of each, numbered from 0 in order of appearance
    std::uint32_t count = 0;
};

bool is_degenerate(const Triangle& t)
{
    return t[0] == t[1] || t[1] == t[2] || t[2] == t[0];
}

std::vector<VertexFans> vertex_fans(const TriMesh& mesh)
{
    const std::size_t nv = mesh.vertex_count();
    std::vector<VertexFans> out(nv);
    for (std::size_t f = 0; f < mesh.face_count(); ++f)
    {
        if (!is_degenerate(mesh.triangles[f]))
        {
            for (const std::uint32_t v : mesh.triangles[f])
            {
                out[v].faces.push_back(static_cast<std::uint32_t>(f));
            }
        }
    }
    std::vector<std::size_t> parent;
    for (std::size_t v = 0; v < nv; ++v)
    {
        VertexFans& fans = out[v];
        const auto& around = fans.faces;
        parent.resize(around.size());
        std::iota(parent.begin(), parent.end(), 0);
        auto find = [&](std::size_t x) {
            while (parent[x] != x)
            {
                x = parent[x] = parent[parent[x]];
            }
            return x;
        };
        for (std::size_t a = 0; a < around.size(); ++a)
        {
            const Triangle& ta = mesh.triangles[around[a]];
            for (std::size_t b = a + 1; b < around.size(); ++b)
            {
                const Triangle& tb = mesh.triangles[around[b]];
                for (const std::uint32_t x : ta)
                {
                    if (x != v && std::find(tb.begin(), tb.end(), x) != tb.end())
                    {
                        parent[find(a)] = find(b);
                        break;
                    }
                }
            }
        }
        fans.fan.assign(around.size(), 0);
        std::vector<std::uint32_t> number(around.size(), std::numeric_limits<std::uint32_t>::max());
        for (std::size_t a = 0; a < around.size(); ++a)
        {
            const std::size_t r = find(a);
            if (number[r] == std::numeric_limits<std::uint32_t>::max())
            {
                number[r] = fans.count++;
            }
            fans.fan[a] = number[r];
        }
    }
    return out;
}

} // namespace

MeshTopology analyze_topology(const TriMesh& mesh)
{
    MeshTopology topo;
    const std::size_t nv = mesh.vertex_count();
    const std::size_t nf = mesh.face_count();
    topo.faces = nf;

    std::vector<HalfEdge> half;
    half.reserve(3 * nf);
    std::vector<bool> used(nv, false);
    for (std::size_t f = 0; f < nf; ++f)
    {
        const Triangle& t = mesh.triangles[f];
        for (const std::uint32_t v : t)
        {
            if (v >= nv)
            {
                throw InvalidInput("mesh: triangle " + std::to_string(f) + " references vertex " +
                                   std::to_string(v) + " of " + std::to_string(nv));
            }
            used[v] = true;
        }
        if (t[0] == t[1] || t[1] == t[2] || t[2] == t[0])
        {
            ++topo.degenerate_faces;
            continue;
        }
        for (std::size_t j = 0; j < 3; ++j)
        {
            const std::uint32_t a = t[j];
            const std::uint32_t b = t[(j + 1) % 3];
            half.push_back({std::min(a, b), std::max(a, b), a < b, static_cast<std::uint32_t>(f)});
        }
    }
    topo.vertices = static_cast<std::size_t>(std::count(used.begin(), used.end(), true));
    std::sort(half.begin(), half.end(), [](const HalfEdge& x, const HalfEdge& y) {
        return x.lo != y.lo ? x.lo < y.lo : x.hi != y.hi ? x.hi < y.hi : x.face < y.face;
    });

    DisjointSets faces(nf);
    // Boundary edges, joined into loops through their vertices.
    DisjointSets boundary(nv);
    std::vector<std::uint32_t> boundary_degree(nv, 0);
    for (std::size_t i = 0; i < half.size();)
    {
        std::size_t j = i;
        while (j < half.size() && half[j].lo == half[i].lo && half[j].hi == half[i].hi)
        {
            ++j;
        }
        const std::size_t count = j - i;
        ++topo.edges;
        if (count == 1)
        {
            ++topo.boundary_edges;
            boundary.unite(half[i].lo, half[i].hi);
            ++boundary_degree[half[i].lo];
            ++boundary_degree[half[i].hi];
        }
        else if (count == 2)
        {
            if (half[i].forward == half[i + 1].forward)
            {
                ++topo.misoriented_edges;
            }
            faces.unite(half[i].face, half[i + 1].face);
        }
        else
        {
            ++topo.non_manifold_edges;
            for (std::size_t k = i + 1; k < j; ++k)
            {
                faces.unite(half[i].face, half[k].face);
            }
        }
        i = j;
    }

    // Components of non-degenerate faces.
    std::vector<bool> root(nf, false);
    for (std::size_t f = 0; f < nf; ++f)
    {
        const Triangle& t = mesh.triangles[f];
        if (t[0] != t[1] && t[1] != t[2] && t[2] != t[0])
        {
            root[faces.find(f)] = true;
        }
    }
    topo.components = static_cast<std::size_t>(std::count(root.begin(), root.end(), true));

    // Boundary loops: components of the boundary-edge graph (a vertex where two loops touch
    // makes them one, and is counted as non-manifold below).
    std::vector<bool> loop_root(nv, false);
    for (std::size_t v = 0; v < nv; ++v)
    {
        if (boundary_degree[v] > 0)
        {
            loop_root[boundary.find(v)] = true;
        }
    }
    topo.boundary_loops =
        static_cast<std::size_t>(std::count(loop_root.begin(), loop_root.end(), true));

    for (const VertexFans& fans : vertex_fans(mesh))
    {
        if (fans.count > 1)
        {
            ++topo.non_manifold_vertices;
        }
    }

    topo.euler_characteristic = static_cast<std::int64_t>(topo.vertices) -
                                static_cast<std::int64_t>(topo.edges) +
                                static_cast<std::int64_t>(topo.faces - topo.degenerate_faces);
    return topo;
}

} // namespace pointform

namespace pointform {

std::size_t split_nonmanifold_vertices(TriMesh& mesh)
{
    const std::vector<VertexFans> all = vertex_fans(mesh);
    std::size_t added = 0;
    PointCloud& v = mesh.vertices;
    for (std::size_t i = 0; i < all.size(); ++i)
    {
        const VertexFans& fans = all[i];
        if (fans.count < 2)
        {
            continue;
        }
        const auto first_new = static_cast<std::uint32_t>(v.size());
        for (std::uint32_t extra = 1; extra < fans.count; ++extra)
        {
            v.positions.push_back(v.positions[i]);
            if (v.has_normals())
            {
                v.normals.push_back(v.normals[i]);
            }
            if (v.has_colors())
            {
                v.colors.push_back(v.colors[i]);
            }
            if (v.has_radii())
            {
                v.radii.push_back(v.radii[i]);
            }
            ++added;
        }
        for (std::size_t a = 0; a < fans.faces.size(); ++a)
        {
            if (fans.fan[a] == 0)
            {
                continue;
            }
            for (std::uint32_t& corner : mesh.triangles[fans.faces[a]])
            {
                if (corner == i)
                {
                    corner = first_new + fans.fan[a] - 1;
                }
            }
        }
    }
    return added;
}

} // namespace pointform
