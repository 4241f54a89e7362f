// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include "pointform/geometry/tri_mesh.h"

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace pointform {

/// \brief The combinatorial structure of a triangle mesh.
struct MeshTopology
{
    std::size_t vertices = 0; ///< vertices used by at least one triangle
    std::size_t edges = 0;    ///< undirected edges
    std::size_t faces = 0;
    std::size_t boundary_edges = 0;        ///< edges with one triangle
    std::size_t boundary_loops = 0;        ///< closed chains of boundary edges
    std::size_t non_manifold_edges = 0;    ///< edges with more than two triangles
    std::size_t non_manifold_vertices = 0; ///< vertices whose triangles form more than one fan
    std::size_t misoriented_edges = 0;     ///< interior edges both triangles traverse the same way
    std::size_t degenerate_faces = 0;      ///< triangles that repeat a vertex index
    std::size_t components = 0;            ///< edge-connected components of triangles
    /// V − E + F over the used vertices.
    std::int64_t euler_characteristic = 0;

    /// \brief Every edge has one or two triangles, consistently oriented, and every vertex is a
    /// single fan.
    [[nodiscard]] bool is_oriented_manifold() const
    {
        return non_manifold_edges == 0 && non_manifold_vertices == 0 && misoriented_edges == 0 &&
               degenerate_faces == 0;
    }
    [[nodiscard]] bool is_closed() const { return boundary_edges == 0; }
};

/// \brief Counts the mesh's edges, boundary loops, components and defects.
///
/// O(F log F) whatever the valences: the halfedges are sorted by edge, and the fans around
/// each vertex come from a union-find over the triangle corners joined across their edges (no
/// pair of triangles around a vertex is ever compared).
/// \throw InvalidInput if a triangle references a vertex that does not exist, or if the mesh has
///        2³² / 3 triangles or more
[[nodiscard]] MeshTopology analyze_topology(const TriMesh& mesh);

/// \brief The triangles around each vertex grouped into fans, in CSR form. Two triangles around
/// v are in one fan when a chain of triangles, each sharing an edge through v with the next,
/// joins them. Degenerate triangles (a repeated index) belong to no fan and are left out.
struct VertexFans
{
    /// vertex_count + 1 entries: the corners of vertex v are [offsets[v], offsets[v + 1]).
    std::vector<std::size_t> offsets;
    /// The triangle of each corner, increasing within each vertex.
    std::vector<std::uint32_t> faces;
    /// The fan of each corner, numbered from 0 per vertex in order of first appearance (so the
    /// vertex's lowest triangle is in fan 0).
    std::vector<std::uint32_t> fan;
    /// Number of fans of each vertex (0 for a vertex in no triangle).
    std::vector<std::uint32_t> fan_count;

    [[nodiscard]] std::span<const std::uint32_t> faces_of(std::size_t v) const
    {
        return std::span<const std::uint32_t>(faces).subspan(offsets[v],
                                                             offsets[v + 1] - offsets[v]);
    }
    [[nodiscard]] std::span<const std::uint32_t> fans_of(std::size_t v) const
    {
        return std::span<const std::uint32_t>(fan).subspan(offsets[v], offsets[v + 1] - offsets[v]);
    }
};

/// \brief The fans of every vertex of `vertex_count` (see VertexFans). O(F log F) whatever the
/// valences. \throw InvalidInput as analyze_topology()
[[nodiscard]] VertexFans vertex_fans(std::span<const Triangle> triangles, std::size_t vertex_count);

/// \brief Gives every vertex whose triangles form several fans (two sheets touching at one
/// point, e.g. where two holes meet) one copy per extra fan, so that every vertex is a manifold
/// one. Copies keep the vertex's attributes and are appended.
/// \return the number of vertices added
std::size_t split_nonmanifold_vertices(TriMesh& mesh);

/// \brief Keeps the triangles whose `keep[f]` is non-zero (in order), then removes the vertices
/// no kept triangle uses, with their attributes, and renumbers the triangles.
/// \pre keep.size() == mesh.face_count()
/// \return the number of triangles removed
std::size_t keep_faces(TriMesh& mesh, std::span<const std::uint8_t> keep);

} // namespace pointform
