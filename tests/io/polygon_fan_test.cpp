// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// Hostile valence: one polygon of a million vertices in OFF, binary PLY and OBJ (a fan of
// 999,998 triangles around vertex 0 once triangulated), and a hierarchy file whose base mesh is
// such a fan. Each is read, validated and its topology computed, with the true values.

#include "support/polygon_fan.h"

#include "pointform/core/error.h"
#include "pointform/geometry/mesh_topology.h"
#include "pointform/geometry/multires_mesh.h"
#include "pointform/io/hierarchy.h"
#include "pointform/io/io.h"

#include "support/test_support.h"

#include <gtest/gtest.h>

#include <string>

namespace pointform {
namespace {

constexpr std::size_t n = 1'000'000;

/// The n-gon's fan: a disc with n vertices, n − 2 triangles, n boundary edges and n − 3
/// diagonals; vertex 0 is in n − 2 triangles, all one fan.
void expect_fan_topology(const TriMesh& mesh)
{
    ASSERT_EQ(mesh.vertex_count(), n);
    ASSERT_EQ(mesh.face_count(), n - 2);
    const MeshTopology t = analyze_topology(mesh);
    EXPECT_EQ(t.vertices, n);
    EXPECT_EQ(t.faces, n - 2);
    EXPECT_EQ(t.edges, 2 * n - 3);
    EXPECT_EQ(t.boundary_edges, n);
    EXPECT_EQ(t.boundary_loops, 1U);
    EXPECT_EQ(t.components, 1U);
    EXPECT_EQ(t.euler_characteristic, 1);
    EXPECT_EQ(t.non_manifold_edges, 0U);
    EXPECT_EQ(t.non_manifold_vertices, 0U);
    EXPECT_EQ(t.misoriented_edges, 0U);
    EXPECT_EQ(t.degenerate_faces, 0U);
    EXPECT_TRUE(t.is_oriented_manifold());

    const VertexFans fans = vertex_fans(mesh.triangles, mesh.vertex_count());
    EXPECT_EQ(fans.faces_of(0).size(), n - 2);
    EXPECT_EQ(fans.fan_count[0], 1U);
    EXPECT_EQ(fans.faces_of(n / 2).size(), 2U);
    EXPECT_EQ(fans.faces_of(1).size(), 1U);
}

/// The mesh read is the polygon's fan from vertex 0, its vertices those written to the rounding
/// of a float relative to the cloud's origin (coordinates below 2 from it: half an ulp of 2^-23).
void expect_fan_mesh(const TriMesh& mesh)
{
    const TriMesh expected = test::polygon_fan_mesh(n);
    ASSERT_EQ(mesh.triangles.size(), expected.triangles.size());
    EXPECT_TRUE(mesh.triangles == expected.triangles);
    for (const std::size_t k : {std::size_t{0}, std::size_t{1}, n / 3, n - 1})
        EXPECT_LE((mesh.vertices.world(k) - expected.vertices.world(k)).cwiseAbs().maxCoeff(),
                  0x1p-24)
            << "vertex " << k;
    expect_fan_topology(mesh);
}

TEST(PolygonFan, MillionGonOff)
{
    const test::TempDir dir;
    test::write_polygon_fan_off(dir / "fan.off", n);
    expect_fan_mesh(read_mesh(dir / "fan.off"));
}

TEST(PolygonFan, MillionGonBinaryPly)
{
    const test::TempDir dir;
    test::write_polygon_fan_ply(dir / "fan.ply", n);
    expect_fan_mesh(read_mesh(dir / "fan.ply"));
}

TEST(PolygonFan, MillionGonObj)
{
    const test::TempDir dir;
    test::write_polygon_fan_obj(dir / "fan.obj", n);
    expect_fan_mesh(read_mesh(dir / "fan.obj"));
}

TEST(PolygonFan, HierarchyWhoseBaseIsAFan)
{
    const test::TempDir dir;
    MultiresMesh hierarchy(test::polygon_fan_mesh(n));
    (void)hierarchy.split(); // level 1: every edge split, vertex 0 still in n − 2 triangles
    write_hierarchy(dir / "fan.pfh", hierarchy);

    const MultiresMesh read = read_hierarchy(dir / "fan.pfh"); // validates the base's topology
    ASSERT_EQ(read.level_count(), 2U);
    EXPECT_EQ(read.vertex_count(0), n);
    EXPECT_EQ(read.face_count(0), n - 2);
    EXPECT_EQ(read.vertex_count(1), n + (2 * n - 3));
    EXPECT_EQ(read.face_count(1), 4 * (n - 2));
    expect_fan_topology(read.level_mesh(0));

    // Level 1 is a disc too: V = 3n − 3, E = 2(2n − 3) + 3(n − 2), F = 4(n − 2), χ = 1.
    const MeshTopology t = analyze_topology(read.level_mesh(1));
    EXPECT_EQ(t.vertices, 3 * n - 3);
    EXPECT_EQ(t.edges, 2 * (2 * n - 3) + 3 * (n - 2));
    EXPECT_EQ(t.boundary_edges, 2 * n);
    EXPECT_EQ(t.boundary_loops, 1U);
    EXPECT_EQ(t.components, 1U);
    EXPECT_EQ(t.euler_characteristic, 1);
    EXPECT_TRUE(t.is_oriented_manifold());
}

TEST(PolygonFan, HierarchyWithTwoFansAtOneVertexIsRefused)
{
    // Two million-triangle fans meeting only at vertex 0 (a bow tie): not a manifold, refused
    // with the count of non-manifold vertices.
    TriMesh bow = test::polygon_fan_mesh(n);
    const std::size_t half = bow.triangles.size() / 2;
    bow.triangles.erase(bow.triangles.begin() + static_cast<std::ptrdiff_t>(half));
    MultiresParts parts;
    parts.positions.reserve(n);
    for (const Vec3f& p : bow.vertices.positions)
        parts.positions.push_back(p.cast<double>());
    parts.base_faces = bow.triangles;
    parts.level_offsets = {0, n};
    try
    {
        (void)MultiresMesh(std::move(parts));
        FAIL() << "a base with a non-manifold vertex was accepted";
    }
    catch (const InvalidInput& e)
    {
        EXPECT_NE(std::string(e.what()).find("1 non-manifold vertices"), std::string::npos)
            << e.what();
    }
}

} // namespace
} // namespace pointform
