// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include "pointform/core/types.h"
#include "pointform/geometry/multires_mesh.h"

#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

namespace pointform {

/// \brief The halfedge connectivity of level i of a MultiresMesh and how level i + 1 splits it:
/// what the refinement (§5.2) and the Level 3 operators (details, deformation) walk.
///
/// Halfedge h = 3f + k of level i goes from corner k to corner k + 1 of face f.
struct LevelTopology
{
    /// No halfedge or vertex (a boundary halfedge's twin, an unused vertex's outgoing halfedge).
    static constexpr std::uint32_t none = std::numeric_limits<std::uint32_t>::max();

    std::vector<Triangle> faces;            ///< faces of level i
    std::vector<std::uint32_t> edge_vertex; ///< halfedge → vertex of level i + 1 on its edge
    std::vector<std::uint32_t> twin;        ///< halfedge → opposite halfedge, or none
    /// New vertex j (vertex first_new + j of level i + 1) → its one or two halfedges; the first
    /// is the first met going through the faces (h1), the second its twin or none.
    std::vector<std::array<std::uint32_t, 2>> halfedges;
    /// Vertex of level i → an outgoing halfedge (a boundary one on the boundary), or none.
    std::vector<std::uint32_t> outgoing;
    std::uint32_t first_new = 0; ///< index of the first vertex of level i + 1

    [[nodiscard]] static constexpr std::uint32_t next_of(std::uint32_t h)
    {
        return h - h % 3 + (h % 3 + 1) % 3;
    }
    [[nodiscard]] static constexpr std::uint32_t prev_of(std::uint32_t h)
    {
        return h - h % 3 + (h % 3 + 2) % 3;
    }
    [[nodiscard]] std::uint32_t from(std::uint32_t h) const { return faces[h / 3][h % 3]; }
    [[nodiscard]] std::uint32_t to(std::uint32_t h) const { return from(next_of(h)); }
    /// \brief The vertex of h's face opposite h.
    [[nodiscard]] std::uint32_t opposite(std::uint32_t h) const { return from(prev_of(h)); }

    /// \brief The 1-ring of a vertex in counter-clockwise order, starting with the end of its
    /// outgoing halfedge `start`; `closed` says whether the vertex is interior. For a boundary
    /// vertex `start` must be its boundary halfedge (as `outgoing` holds).
    void ring(std::uint32_t start, std::vector<std::uint32_t>& out, bool& closed) const;
};

/// \brief The topology of level `level` and its split into level + 1.
/// \throw InvalidInput unless level < mesh.finest_level()
[[nodiscard]] LevelTopology level_topology(const MultiresMesh& mesh, std::size_t level);

/// \brief The topology of the level that MultiresMesh::split() just split (taking its faces and
/// edge vertices).
[[nodiscard]] LevelTopology level_topology(const MultiresMesh& mesh,
                                           MultiresMesh::SplitResult split);

/// \brief One term of a prediction: weight × position of a vertex of level i.
struct StencilTerm
{
    std::uint32_t vertex = 0;
    double weight = 0.0;
};

/// \brief Appends to `out` (cleared first) the stencil by which `predictor` places new vertex j
/// (vertex first_new + j) from the positions `x` of level i: Midpoint {(a, ½), (b, ½)} for its
/// parent edge (a, b) = (from(h1), to(h1)); Butterfly as Predictor documents. The weights sum to
/// 1, so predictions commute with affine maps. `ring` is scratch space. The stencil depends on
/// the connectivity only.
void prediction_stencil(const LevelTopology& level, std::size_t j, Predictor predictor,
                        std::vector<StencilTerm>& out, std::vector<std::uint32_t>& ring);

/// \brief Σ weight · x[vertex] over a stencil.
[[nodiscard]] inline Vec3d apply_stencil(std::span<const StencilTerm> stencil,
                                         std::span<const Vec3d> x)
{
    Vec3d p = Vec3d::Zero();
    for (const StencilTerm& term : stencil)
        p += term.weight * x[term.vertex];
    return p;
}

} // namespace pointform
