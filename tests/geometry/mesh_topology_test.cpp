// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/geometry/mesh_topology.h"

#include "pointform/core/error.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <numeric>
#include <random>
#include <set>
#include <utility>
#include <vector>

namespace pointform {
namespace {

TriMesh mesh_of(std::size_t vertices, std::vector<Triangle> triangles)
{
    TriMesh mesh;
    mesh.vertices.positions.assign(vertices, Vec3f::Zero());
    mesh.triangles = std::move(triangles);
    return mesh;
}

/// A tetrahedron with outward faces.
TriMesh tetrahedron()
{
    return mesh_of(4, {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {2, 0, 3}});
}

TEST(MeshTopology, ClosedTetrahedron)
{
    const MeshTopology t = analyze_topology(tetrahedron());
    EXPECT_EQ(t.vertices, 4U);
    EXPECT_EQ(t.edges, 6U);
    EXPECT_EQ(t.faces, 4U);
    EXPECT_EQ(t.euler_characteristic, 2);
    EXPECT_TRUE(t.is_closed());
    EXPECT_TRUE(t.is_oriented_manifold());
    EXPECT_EQ(t.components, 1U);
    EXPECT_EQ(t.boundary_loops, 0U);
}

TEST(MeshTopology, OpenFanHasOneBoundaryLoop)
{
    // Tetrahedron minus one face: a disc.
    const MeshTopology t = analyze_topology(mesh_of(4, {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}}));
    EXPECT_EQ(t.boundary_edges, 3U);
    EXPECT_EQ(t.boundary_loops, 1U);
    EXPECT_EQ(t.euler_characteristic, 1);
    EXPECT_TRUE(t.is_oriented_manifold());
}

TEST(MeshTopology, FindsDefects)
{
    TriMesh flipped = tetrahedron();
    std::swap(flipped.triangles[0][0], flipped.triangles[0][1]);
    EXPECT_EQ(analyze_topology(flipped).misoriented_edges, 3U);

    // Three triangles on one edge.
    const MeshTopology fin = analyze_topology(mesh_of(5, {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}}));
    EXPECT_EQ(fin.non_manifold_edges, 1U);
    EXPECT_FALSE(fin.is_oriented_manifold());

    // Two triangles touching at one vertex: a bow tie.
    const MeshTopology bow = analyze_topology(mesh_of(5, {{0, 1, 2}, {0, 3, 4}}));
    EXPECT_EQ(bow.non_manifold_vertices, 1U);
    EXPECT_EQ(bow.components, 2U);
    TriMesh bow_tie = mesh_of(5, {{0, 1, 2}, {0, 3, 4}});
    EXPECT_EQ(split_nonmanifold_vertices(bow_tie), 1U);
    EXPECT_EQ(bow_tie.vertex_count(), 6U);
    const MeshTopology split = analyze_topology(bow_tie);
    EXPECT_TRUE(split.is_oriented_manifold());
    EXPECT_EQ(split.euler_characteristic, 2); // two separate triangles
    TriMesh closed = tetrahedron();
    EXPECT_EQ(split_nonmanifold_vertices(closed), 0U);

    EXPECT_EQ(analyze_topology(mesh_of(3, {{0, 1, 1}})).degenerate_faces, 1U);
    EXPECT_THROW((void)analyze_topology(mesh_of(3, {{0, 1, 3}})), InvalidInput);
}

TEST(MeshTopology, TwoDisjointTetrahedra)
{
    TriMesh two = tetrahedron();
    two.vertices.positions.resize(8, Vec3f::Zero());
    for (Triangle t : tetrahedron().triangles)
    {
        two.triangles.push_back({t[0] + 4, t[1] + 4, t[2] + 4});
    }
    const MeshTopology t = analyze_topology(two);
    EXPECT_EQ(t.components, 2U);
    EXPECT_EQ(t.euler_characteristic, 4);
}

TEST(MeshTopology, KeepFacesCompactsVerticesAndTheirAttributes)
{
    // Two tetrahedra; vertex i sits at (i, 0, 0) with radius i, so the survivors can be told apart.
    TriMesh two = tetrahedron();
    two.vertices.positions.resize(8);
    two.vertices.radii.resize(8);
    for (std::uint32_t v = 0; v < 8; ++v)
    {
        two.vertices.positions[v] = Vec3f(static_cast<float>(v), 0.0F, 0.0F);
        two.vertices.radii[v] = static_cast<float>(v);
    }
    for (Triangle t : tetrahedron().triangles)
        two.triangles.push_back({t[0] + 4, t[1] + 4, t[2] + 4});
    const std::vector<std::uint8_t> keep = {0, 0, 0, 0, 1, 0, 1, 1};
    EXPECT_EQ(keep_faces(two, keep), 5U);
    ASSERT_EQ(two.face_count(), 3U);
    ASSERT_EQ(two.vertex_count(), 4U); // the second tetrahedron's faces 0, 2, 3 use all four
    for (std::uint32_t v = 0; v < 4; ++v)
    {
        EXPECT_EQ(two.vertices.positions[v].x(), static_cast<float>(v + 4));
        EXPECT_EQ(two.vertices.radii[v], static_cast<float>(v + 4));
    }
    const std::vector<Triangle> tet = tetrahedron().triangles;
    EXPECT_EQ(two.triangles[0], tet[0]);
    EXPECT_EQ(two.triangles[1], tet[2]);
    EXPECT_EQ(two.triangles[2], tet[3]);

    const std::vector<std::uint8_t> all(3, 1);
    EXPECT_EQ(keep_faces(two, all), 0U);
    EXPECT_EQ(two.vertex_count(), 4U);
    const std::vector<std::uint8_t> none(3, 0);
    EXPECT_EQ(keep_faces(two, none), 3U);
    EXPECT_EQ(two.vertex_count(), 0U);
    EXPECT_TRUE(two.vertices.radii.empty());
}

/// The plain definitions, pair by pair (quadratic), to check analyze_topology, vertex_fans and
/// split_nonmanifold_vertices against.
struct Reference
{
    MeshTopology topology;
    std::vector<std::vector<std::uint32_t>> faces; ///< per vertex, its triangles in order
    std::vector<std::vector<std::uint32_t>> fans;  ///< per vertex, the fan of each, by appearance
};

bool degenerate(const Triangle& t)
{
    return t[0] == t[1] || t[1] == t[2] || t[2] == t[0];
}

/// Two triangles share an edge when they have two distinct vertices in common.
bool share_edge(const Triangle& a, const Triangle& b)
{
    int common = 0;
    for (const std::uint32_t x : a)
        common += std::count(b.begin(), b.end(), x) > 0 ? 1 : 0;
    return common >= 2;
}

/// Labels 0, 1, ... of the classes of `linked` over `items` by flood fill, numbered in order of
/// first appearance.
template <typename Linked>
std::vector<std::uint32_t> flood(std::size_t items, Linked&& linked)
{
    std::vector<std::uint32_t> label(items, UINT32_MAX);
    std::uint32_t next = 0;
    for (std::size_t seed = 0; seed < items; ++seed)
    {
        if (label[seed] != UINT32_MAX)
            continue;
        label[seed] = next;
        std::vector<std::size_t> stack = {seed};
        while (!stack.empty())
        {
            const std::size_t i = stack.back();
            stack.pop_back();
            for (std::size_t j = 0; j < items; ++j)
                if (label[j] == UINT32_MAX && linked(i, j))
                {
                    label[j] = next;
                    stack.push_back(j);
                }
        }
        ++next;
    }
    return label;
}

/// Number of classes of a flood() labelling.
std::uint32_t classes(const std::vector<std::uint32_t>& label)
{
    std::uint32_t count = 0;
    for (const std::uint32_t l : label)
        count = std::max(count, l + 1);
    return count;
}

Reference reference_topology(const TriMesh& mesh)
{
    Reference r;
    MeshTopology& t = r.topology;
    const auto& tris = mesh.triangles;
    const std::size_t nv = mesh.vertex_count();
    t.faces = tris.size();
    std::set<std::uint32_t> used;
    std::vector<std::size_t> live; // non-degenerate triangles
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::vector<int>> edges; // +1 lo→hi, −1
    for (std::size_t f = 0; f < tris.size(); ++f)
    {
        used.insert(tris[f].begin(), tris[f].end());
        if (degenerate(tris[f]))
        {
            ++t.degenerate_faces;
            continue;
        }
        live.push_back(f);
        for (int k = 0; k < 3; ++k)
        {
            const std::uint32_t a = tris[f][k];
            const std::uint32_t b = tris[f][(k + 1) % 3];
            edges[std::minmax(a, b)].push_back(a < b ? 1 : -1);
        }
    }
    t.vertices = used.size();
    t.edges = edges.size();
    std::vector<std::pair<std::uint32_t, std::uint32_t>> boundary;
    for (const auto& [e, uses] : edges)
    {
        if (uses.size() == 1)
            boundary.push_back(e);
        else if (uses.size() > 2)
            ++t.non_manifold_edges;
        else if (uses[0] == uses[1])
            ++t.misoriented_edges;
    }
    t.boundary_edges = boundary.size();
    const auto component = flood(live.size(), [&](std::size_t i, std::size_t j) {
        return share_edge(tris[live[i]], tris[live[j]]);
    });
    t.components = classes(component);
    std::vector<std::uint32_t> rim;
    for (const auto& [a, b] : boundary)
    {
        rim.push_back(a);
        rim.push_back(b);
    }
    std::sort(rim.begin(), rim.end());
    rim.erase(std::unique(rim.begin(), rim.end()), rim.end());
    const auto loop = flood(rim.size(), [&](std::size_t i, std::size_t j) {
        return std::find(boundary.begin(), boundary.end(),
                         std::pair<std::uint32_t, std::uint32_t>(std::minmax(rim[i], rim[j]))) !=
               boundary.end();
    });
    t.boundary_loops = classes(loop);
    r.faces.resize(nv);
    r.fans.resize(nv);
    for (std::uint32_t v = 0; v < nv; ++v)
    {
        for (const std::size_t f : live)
            if (std::count(tris[f].begin(), tris[f].end(), v) > 0)
                r.faces[v].push_back(static_cast<std::uint32_t>(f));
        const auto& around = r.faces[v];
        r.fans[v] = flood(around.size(), [&](std::size_t i, std::size_t j) {
            for (const std::uint32_t x : tris[around[i]])
                if (x != v && std::count(tris[around[j]].begin(), tris[around[j]].end(), x) > 0)
                    return true;
            return false;
        });
        if (classes(r.fans[v]) > 1)
            ++t.non_manifold_vertices;
    }
    t.euler_characteristic = static_cast<std::int64_t>(t.vertices) -
                             static_cast<std::int64_t>(t.edges) +
                             static_cast<std::int64_t>(live.size());
    return r;
}

/// A random mesh assembled from pieces that make every kind of defect: grid discs (boundaries),
/// closed octahedra, triangles with some flipped (inconsistent orientation), random triangles
/// over a few vertices (non-manifold edges and vertices, degenerate faces), vertices glued
/// together (several fans at a vertex), unused vertices; then vertices and triangles shuffled.
TriMesh random_mesh(std::mt19937& random)
{
    std::uniform_int_distribution<int> pick(0, 99);
    TriMesh mesh;
    std::uint32_t nv = 0;
    auto& tris = mesh.triangles;
    const int pieces = 1 + pick(random) % 4;
    for (int p = 0; p < pieces; ++p)
    {
        const int kind = pick(random) % 3;
        if (kind == 0) // grid disc
        {
            const std::uint32_t w = 2 + static_cast<std::uint32_t>(pick(random) % 4);
            const std::uint32_t h = 2 + static_cast<std::uint32_t>(pick(random) % 4);
            for (std::uint32_t i = 0; i + 1 < w; ++i)
                for (std::uint32_t j = 0; j + 1 < h; ++j)
                {
                    const std::uint32_t a = nv + i * h + j;
                    tris.push_back({a, a + h, a + 1});
                    tris.push_back({a + 1, a + h, a + h + 1});
                }
            nv += w * h;
        }
        else if (kind == 1) // octahedron
        {
            const std::vector<Triangle> octa = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4},
                                                {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
            for (const Triangle& t : octa)
                tris.push_back({t[0] + nv, t[1] + nv, t[2] + nv});
            nv += 6;
        }
        else // random triangles over a few vertices
        {
            const std::uint32_t pool = 3 + static_cast<std::uint32_t>(pick(random) % 5);
            const int count = 1 + pick(random) % 6;
            std::uniform_int_distribution<std::uint32_t> vertex(0, pool - 1);
            for (int i = 0; i < count; ++i)
            {
                Triangle t = {nv + vertex(random), nv + vertex(random), nv + vertex(random)};
                if (pick(random) < 80) // mostly non-degenerate
                    while (degenerate(t))
                        t = {nv + vertex(random), nv + vertex(random), nv + vertex(random)};
                tris.push_back(t);
            }
            nv += pool;
        }
    }
    for (Triangle& t : tris) // some flipped
        if (pick(random) < 8)
            std::swap(t[1], t[2]);
    const int glue = pick(random) % 4; // vertices glued together
    std::uniform_int_distribution<std::uint32_t> any(0, nv - 1);
    for (int g = 0; g < glue; ++g)
    {
        const std::uint32_t from = any(random);
        const std::uint32_t to = any(random);
        for (Triangle& t : tris)
            for (std::uint32_t& v : t)
                if (v == from)
                    v = to;
    }
    nv += static_cast<std::uint32_t>(pick(random) % 3); // unused vertices
    std::vector<std::uint32_t> permutation(nv);
    std::iota(permutation.begin(), permutation.end(), 0U);
    std::shuffle(permutation.begin(), permutation.end(), random);
    for (Triangle& t : tris)
    {
        for (std::uint32_t& v : t)
            v = permutation[v];
        std::rotate(t.begin(), t.begin() + pick(random) % 3, t.end()); // same orientation
    }
    std::shuffle(tris.begin(), tris.end(), random);
    mesh.vertices.positions.assign(nv, Vec3f::Zero());
    return mesh;
}

void expect_same(const MeshTopology& a, const MeshTopology& b)
{
    EXPECT_EQ(a.vertices, b.vertices);
    EXPECT_EQ(a.edges, b.edges);
    EXPECT_EQ(a.faces, b.faces);
    EXPECT_EQ(a.boundary_edges, b.boundary_edges);
    EXPECT_EQ(a.boundary_loops, b.boundary_loops);
    EXPECT_EQ(a.non_manifold_edges, b.non_manifold_edges);
    EXPECT_EQ(a.non_manifold_vertices, b.non_manifold_vertices);
    EXPECT_EQ(a.misoriented_edges, b.misoriented_edges);
    EXPECT_EQ(a.degenerate_faces, b.degenerate_faces);
    EXPECT_EQ(a.components, b.components);
    EXPECT_EQ(a.euler_characteristic, b.euler_characteristic);
}

TEST(MeshTopology, MatchesThePairwiseDefinitionsOnRandomMeshes)
{
    std::mt19937 random(20261124);
    MeshTopology seen; // how many meshes had each kind of feature, so the test covers them
    for (int trial = 0; trial < 400; ++trial)
    {
        SCOPED_TRACE("trial " + std::to_string(trial));
        TriMesh mesh = random_mesh(random);
        const Reference expected = reference_topology(mesh);
        const MeshTopology got = analyze_topology(mesh);
        expect_same(got, expected.topology);
        seen.boundary_loops += got.boundary_loops > 1 ? 1 : 0;
        seen.non_manifold_edges += got.non_manifold_edges > 0 ? 1 : 0;
        seen.non_manifold_vertices += got.non_manifold_vertices > 0 ? 1 : 0;
        seen.misoriented_edges += got.misoriented_edges > 0 ? 1 : 0;
        seen.degenerate_faces += got.degenerate_faces > 0 ? 1 : 0;
        seen.components += got.components > 1 ? 1 : 0;

        const VertexFans fans = vertex_fans(mesh.triangles, mesh.vertex_count());
        ASSERT_EQ(fans.offsets.size(), mesh.vertex_count() + 1);
        for (std::size_t v = 0; v < mesh.vertex_count(); ++v)
        {
            const auto faces = fans.faces_of(v);
            const auto fan = fans.fans_of(v);
            EXPECT_EQ(std::vector<std::uint32_t>(faces.begin(), faces.end()), expected.faces[v]);
            EXPECT_EQ(std::vector<std::uint32_t>(fan.begin(), fan.end()), expected.fans[v]);
            EXPECT_EQ(fans.fan_count[v], classes(expected.fans[v]));
        }

        // Splitting: one copy per extra fan, appended vertex by vertex, fan by fan.
        TriMesh split = mesh;
        std::uint32_t next = static_cast<std::uint32_t>(mesh.vertex_count());
        std::vector<Triangle> expected_triangles = mesh.triangles;
        for (std::uint32_t v = 0; v < mesh.vertex_count(); ++v)
        {
            const std::uint32_t first = next;
            std::uint32_t extra = 0;
            for (std::size_t a = 0; a < expected.faces[v].size(); ++a)
            {
                const std::uint32_t fan = expected.fans[v][a];
                extra = std::max(extra, fan);
                if (fan > 0)
                    for (std::uint32_t& corner : expected_triangles[expected.faces[v][a]])
                        if (corner == v)
                            corner = first + fan - 1;
            }
            next += extra;
        }
        EXPECT_EQ(split_nonmanifold_vertices(split), next - mesh.vertex_count());
        EXPECT_EQ(split.vertex_count(), next);
        EXPECT_EQ(split.triangles, expected_triangles);
        EXPECT_EQ(analyze_topology(split).non_manifold_vertices, 0U);
    }
    // Every kind of feature occurs many times among the 400 meshes.
    EXPECT_GT(seen.boundary_loops, 40U);
    EXPECT_GT(seen.non_manifold_edges, 40U);
    EXPECT_GT(seen.non_manifold_vertices, 40U);
    EXPECT_GT(seen.misoriented_edges, 40U);
    EXPECT_GT(seen.degenerate_faces, 40U);
    EXPECT_GT(seen.components, 40U);
}

TEST(MeshTopology, BowTieOfTwoHalfMillionFans)
{
    // Two fans of 499,999 triangles each that meet only at vertex 0: one non-manifold vertex
    // of valence ~10^6, both boundaries through it (one loop), two components.
    constexpr std::uint32_t n = 1'000'000;
    TriMesh mesh;
    mesh.vertices.positions.assign(n, Vec3f::Zero());
    for (std::uint32_t k = 2; k < n; ++k)
        if (k != n / 2 + 1)
            mesh.triangles.push_back({0, k - 1, k});
    const MeshTopology t = analyze_topology(mesh);
    EXPECT_EQ(t.vertices, n);
    EXPECT_EQ(t.faces, n - 3);
    EXPECT_EQ(t.components, 2U);
    EXPECT_EQ(t.non_manifold_vertices, 1U);
    EXPECT_EQ(t.non_manifold_edges, 0U);
    EXPECT_EQ(t.misoriented_edges, 0U);
    EXPECT_EQ(t.boundary_loops, 1U);
    EXPECT_EQ(t.euler_characteristic, 1); // n − (2n − 4) + (n − 3): two discs joined at a point
    EXPECT_EQ(split_nonmanifold_vertices(mesh), 1U);
    const MeshTopology s = analyze_topology(mesh);
    EXPECT_TRUE(s.is_oriented_manifold());
    EXPECT_EQ(s.components, 2U);
    EXPECT_EQ(s.boundary_loops, 2U);
    EXPECT_EQ(s.euler_characteristic, 2); // two discs
}

} // namespace
} // namespace pointform
