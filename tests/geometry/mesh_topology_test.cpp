// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/geometry/mesh_topology.h"

#include "pointform/core/error.h"

#include <gtest/gtest.h>

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

} // namespace
} // namespace pointform
