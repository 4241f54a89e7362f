// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include "pointform/geometry/tri_mesh.h"

#include <cstddef>
#include <cstdint>

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
/// \throw InvalidInput if a triangle references a vertex that does not exist
[[nodiscard]] MeshTopology analyze_topology(const TriMesh& mesh);

/// \brief Gives every vertex whose triangles form several fans (two sheets touching at one
/// point, e.g. where two holes meet) one copy per extra fan, so that every vertex is a manifold
/// one. Copies keep the vertex's attributes and are appended.
/// \return the number of vertices added
std::size_t split_nonmanifold_vertices(TriMesh& mesh);

} // namespace pointform
