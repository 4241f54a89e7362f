// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/geometry/multires_mesh.h"

#include "pointform/core/error.h"
#include "pointform/geometry/mesh_topology.h"

#include "support/test_meshes.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <utility>

namespace pointform {
namespace {

/// The unit octahedron, outward faces.
TriMesh octahedron()
{
    TriMesh mesh;
    mesh.vertices.positions = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    mesh.triangles = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4},
                      {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
    return mesh;
}

std::vector<std::size_t> valences(const TriMesh& mesh)
{
    std::set<std::pair<std::uint32_t, std::uint32_t>> edges;
    for (const Triangle& t : mesh.triangles)
        for (std::size_t k = 0; k < 3; ++k)
            edges.insert(std::minmax(t[k], t[(k + 1) % 3]));
    std::vector<std::size_t> valence(mesh.vertex_count(), 0);
    for (const auto& [a, b] : edges)
    {
        ++valence[a];
        ++valence[b];
    }
    return valence;
}

TEST(MultiresMesh, BaseOnly)
{
    const MultiresMesh mesh(octahedron());
    EXPECT_EQ(mesh.level_count(), 1U);
    EXPECT_EQ(mesh.finest_level(), 0U);
    EXPECT_EQ(mesh.vertex_count(0), 6U);
    EXPECT_EQ(mesh.face_count(0), 8U);
    EXPECT_TRUE(mesh.parent_edges().empty());
    EXPECT_TRUE(MultiresMesh().level_count() == 0);
    EXPECT_THROW((void)mesh.vertex_count(1), InvalidInput);
    EXPECT_THROW((void)mesh.parent_edge(0), InvalidInput);
    EXPECT_THROW((void)mesh.edge_vertices(0), InvalidInput);
}

TEST(MultiresMesh, SplitsOneToFourAndStaysNested)
{
    MultiresMesh mesh(octahedron());
    for (int i = 0; i < 4; ++i)
        EXPECT_EQ(mesh.split().level, static_cast<std::size_t>(i + 1));
    ASSERT_EQ(mesh.level_count(), 5U);

    const TriMesh finest = mesh.level_mesh(4);
    for (std::size_t level = 0; level < mesh.level_count(); ++level)
    {
        const TriMesh m = mesh.level_mesh(level);
        EXPECT_EQ(m.face_count(), 8U << (2 * level));
        EXPECT_EQ(m.face_count(), mesh.face_count(level));
        const MeshTopology t = analyze_topology(m);
        EXPECT_TRUE(t.is_oriented_manifold()) << "level " << level;
        EXPECT_TRUE(t.is_closed());
        EXPECT_EQ(t.euler_characteristic, 2);
        EXPECT_EQ(t.vertices, m.vertex_count()); // every vertex used
        // Nested: this level's vertices are a prefix of the finest level's, bit for bit.
        ASSERT_LE(m.vertex_count(), finest.vertex_count());
        EXPECT_TRUE(std::equal(m.vertices.positions.begin(), m.vertices.positions.end(),
                               finest.vertices.positions.begin()));
        if (level == 0)
            continue;
        // Every vertex the split added has valence 6; new vertices sit on their parent edge's
        // midpoint (the split places them there).
        const std::vector<std::size_t> valence = valences(m);
        for (std::size_t v = mesh.vertex_count(level - 1); v < m.vertex_count(); ++v)
        {
            EXPECT_EQ(valence[v], 6U);
            EXPECT_EQ(mesh.level_of_vertex(static_cast<std::uint32_t>(v)), level);
            const ParentEdge e = mesh.parent_edge(static_cast<std::uint32_t>(v));
            EXPECT_LT(e.a, mesh.vertex_count(level - 1));
            EXPECT_LT(e.b, mesh.vertex_count(level - 1));
            EXPECT_TRUE(mesh.positions()[v].isApprox(
                0.5 * (mesh.positions()[e.a] + mesh.positions()[e.b])));
        }
        // Children of face f are 4f..4f+3 and keep its corners in place.
        const std::vector<Triangle> parents = mesh.faces(level - 1);
        for (std::uint32_t f = 0; f < parents.size(); ++f)
        {
            const auto kids = MultiresMesh::child_faces(f);
            EXPECT_EQ(m.triangles[kids[0]][0], parents[f][0]);
            EXPECT_EQ(m.triangles[kids[1]][1], parents[f][1]);
            EXPECT_EQ(m.triangles[kids[2]][2], parents[f][2]);
            for (const std::uint32_t c : kids)
                EXPECT_EQ(MultiresMesh::parent_face(c), f);
        }
    }
}

TEST(MultiresMesh, EdgeVerticesMatchParentEdges)
{
    MultiresMesh mesh(test::icosphere(1));
    const MultiresMesh::SplitResult split = mesh.split();
    const std::vector<Triangle> faces = mesh.faces(0);
    const std::vector<std::uint32_t> ev = mesh.edge_vertices(0);
    EXPECT_EQ(split.faces, faces);
    EXPECT_EQ(split.edge_vertices, ev);
    ASSERT_EQ(ev.size(), 3 * faces.size());
    std::vector<int> uses(mesh.vertex_count(), 0);
    for (std::size_t h = 0; h < ev.size(); ++h)
    {
        const std::uint32_t a = faces[h / 3][h % 3];
        const std::uint32_t b = faces[h / 3][(h % 3 + 1) % 3];
        const ParentEdge e = mesh.parent_edge(ev[h]);
        EXPECT_EQ(std::minmax(e.a, e.b), std::minmax(a, b));
        ++uses[ev[h]];
    }
    // Closed mesh: each new vertex is named by exactly two halfedges.
    for (std::size_t v = mesh.vertex_count(0); v < mesh.vertex_count(); ++v)
        EXPECT_EQ(uses[v], 2);
}

TEST(MultiresMesh, OpenMeshKeepsItsBoundary)
{
    MultiresMesh mesh(test::square_grid(3));
    mesh.split();
    mesh.split();
    for (std::size_t level = 0; level < mesh.level_count(); ++level)
    {
        const MeshTopology t = analyze_topology(mesh.level_mesh(level));
        EXPECT_TRUE(t.is_oriented_manifold());
        EXPECT_EQ(t.boundary_loops, 1U);
        EXPECT_EQ(t.euler_characteristic, 1);
        // The boundary doubles its edge count per level: 12 · 2^level.
        EXPECT_EQ(t.boundary_edges, std::size_t{12} << level);
    }
}

TEST(MultiresMesh, RoundTripsThroughParts)
{
    MultiresMesh mesh(octahedron());
    mesh.split();
    mesh.split();
    mesh.finest_new_positions()[0] += Vec3d(0.1, 0.2, 0.3);
    const MultiresMesh copy(mesh.parts());
    EXPECT_EQ(copy.level_count(), mesh.level_count());
    EXPECT_EQ(copy.faces(2), mesh.faces(2));
    EXPECT_TRUE(
        std::equal(copy.positions().begin(), copy.positions().end(), mesh.positions().begin()));
}

TEST(MultiresMesh, FinestNewPositionsAreOnlyTheNewOnes)
{
    MultiresMesh mesh(octahedron());
    EXPECT_TRUE(mesh.finest_new_positions().empty());
    mesh.split();
    const std::vector<Vec3d> before(mesh.positions().begin(), mesh.positions().end());
    for (Vec3d& p : mesh.finest_new_positions())
        p *= 2.0;
    EXPECT_EQ(mesh.finest_new_positions().size(), 12U);
    for (std::size_t v = 0; v < 6; ++v)
        EXPECT_EQ(mesh.positions()[v], before[v]);
}

TEST(MultiresMesh, Truncates)
{
    MultiresMesh mesh(octahedron());
    mesh.split();
    mesh.split();
    mesh.truncate(1);
    EXPECT_EQ(mesh.level_count(), 2U);
    EXPECT_EQ(mesh.vertex_count(), 18U);
    EXPECT_NO_THROW(mesh.validate());
    EXPECT_THROW(mesh.truncate(2), InvalidInput);
}

/// A two-level hierarchy's parts, for corruption.
MultiresParts two_levels()
{
    MultiresMesh mesh(octahedron());
    mesh.split();
    mesh.split();
    return mesh.parts();
}

TEST(MultiresMesh, ValidateRejectsCorruption)
{
    const MultiresParts good = two_levels();
    EXPECT_NO_THROW(MultiresMesh{good});

    const auto rejects = [](MultiresParts parts) {
        EXPECT_THROW(MultiresMesh{std::move(parts)}, InvalidInput);
    };
    {
        MultiresParts p = good; // parent index out of range of its level
        p.parent_edges[3].b = 17;
        rejects(p);
    }
    {
        MultiresParts p = good; // parent index beyond every vertex
        p.parent_edges.back().a = 1000000;
        rejects(p);
    }
    {
        MultiresParts p = good; // a parent edge that is not an edge (two opposite poles)
        p.parent_edges[0] = {0, 1};
        rejects(p);
    }
    {
        MultiresParts p = good; // two vertices on the same edge
        p.parent_edges[1] = p.parent_edges[0];
        rejects(p);
    }
    {
        MultiresParts p = good; // degenerate parent edge
        p.parent_edges[2] = {3, 3};
        rejects(p);
    }
    {
        MultiresParts p = good; // wrong level offsets (same total)
        p.level_offsets[2] += 1;
        rejects(p);
    }
    {
        MultiresParts p = good; // decreasing offsets
        p.level_offsets[2] = 3;
        rejects(p);
    }
    {
        MultiresParts p = good; // truncated positions
        p.positions.pop_back();
        rejects(p);
    }
    {
        MultiresParts p = good; // missing parent edge
        p.parent_edges.pop_back();
        rejects(p);
    }
    {
        MultiresParts p = good;
        p.level_offsets[0] = 1;
        rejects(p);
    }
    {
        MultiresParts p = good;
        p.level_offsets = {0};
        rejects(p);
    }
    {
        MultiresParts p = good;
        p.positions[20].x() = std::numeric_limits<double>::quiet_NaN();
        rejects(p);
    }
    {
        MultiresParts p = good; // base face out of range
        p.base_faces[0][1] = 6;
        rejects(p);
    }
    {
        MultiresParts p = good; // degenerate base face
        p.base_faces[0][1] = p.base_faces[0][0];
        rejects(p);
    }
    {
        MultiresParts p = good; // misoriented base face
        std::swap(p.base_faces[0][0], p.base_faces[0][1]);
        rejects(p);
    }
    {
        MultiresParts p = good; // no base faces
        p.base_faces.clear();
        rejects(p);
    }
}

TEST(MultiresMesh, RejectsBadBase)
{
    TriMesh unused = octahedron();
    unused.vertices.positions.emplace_back(5.0F, 5.0F, 5.0F);
    EXPECT_THROW(MultiresMesh{unused}, InvalidInput);

    TriMesh fin = octahedron(); // a third face on edge (0, 2)
    fin.vertices.positions.emplace_back(1.0F, 1.0F, 0.0F);
    fin.triangles.push_back({0, 2, 6});
    EXPECT_THROW(MultiresMesh{fin}, InvalidInput);

    EXPECT_THROW(MultiresMesh{TriMesh{}}, InvalidInput);
}

} // namespace
} // namespace pointform
