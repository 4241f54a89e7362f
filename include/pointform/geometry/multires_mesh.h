// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include "pointform/core/types.h"
#include "pointform/geometry/tri_mesh.h"

#include <array>
#include <compare>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

namespace pointform {

/// \brief Where a refinement first puts a new edge vertex, before projecting it (§5.2), and what
/// the details of a hierarchy are measured from (pointform/multires/details.h).
enum class Predictor
{
    /// The midpoint of the parent edge.
    Midpoint,
    /// The modified butterfly subdivision rule (Zorin, Schröder and Sweldens 1996): the 8-point
    /// stencil where the edge's interior ends are regular (valence 6; one end may lie on the
    /// boundary if the stencil's wings exist), the extraordinary-vertex stencil of an irregular
    /// interior end (averaged when both are irregular), the 4-point rule along boundary edges,
    /// and the midpoint for an interior edge whose two ends lie on the boundary (a simplification
    /// of Zorin's boundary rules). Projecting the prediction gives the paper's "displaced
    /// butterfly" refinement. The stencils are those of prediction_stencil()
    /// (pointform/geometry/level_topology.h).
    Butterfly,
};

/// \brief Parses "midpoint" or "butterfly". \throw InvalidInput otherwise
[[nodiscard]] Predictor parse_predictor(std::string_view text);
[[nodiscard]] std::string_view to_string(Predictor predictor);

/// \brief The two level-i vertices of the edge that a vertex of level i + 1 splits.
struct ParentEdge
{
    std::uint32_t a = 0;
    std::uint32_t b = 0;

    constexpr auto operator<=>(const ParentEdge&) const = default;
};

/// \brief The raw data of a MultiresMesh, laid out as a file stores it (see MultiresMesh).
struct MultiresParts
{
    /// World position of vertex v = origin + positions[v].
    Vec3d origin = Vec3d::Zero();
    /// Every vertex of every level, level by level: level i's vertices are the prefix
    /// [0, level_offsets[i + 1]).
    std::vector<Vec3d> positions;
    /// Triangles of the base mesh M0 over the vertices [0, level_offsets[1]), counter-clockwise
    /// seen from outside.
    std::vector<Triangle> base_faces;
    /// level_count + 1 entries: 0, then the number of vertices of each level; the vertices added
    /// by level i ≥ 1 are [level_offsets[i], level_offsets[i + 1]).
    std::vector<std::size_t> level_offsets;
    /// One entry per vertex added by a split, i.e. for vertex v ≥ level_offsets[1] the entry
    /// v − level_offsets[1]: the edge of level i it splits, where v belongs to level i + 1.
    std::vector<ParentEdge> parent_edges;
    /// The predictor the refinement used for every level above the base (hierarchy files of
    /// format version 1 did not record it and read as Midpoint).
    Predictor predictor = Predictor::Midpoint;
};

/// \brief Level 3: a semi-regular multiresolution triangle mesh, a base mesh M0 and its nested
/// 1-to-4 refinements M1 … MJ (§5.2).
///
/// Vertices are appended level by level, so V^i ⊂ V^(i+1) holds by construction: level i's
/// vertices are a prefix of level i+1's, and a refinement never moves them. Each vertex added at
/// level i+1 remembers its parent edge (two vertices of level i). The faces of level i are not
/// stored; they follow from the base faces and the parent edges by the 1-to-4 split: face f =
/// (a, b, c) of level i has the children, at indices 4f … 4f+3 of level i+1,
///
///     4f:   (a, m_ab, m_ca)      4f+1: (m_ab, b, m_bc)
///     4f+2: (m_ca, m_bc, c)      4f+3: (m_ab, m_bc, m_ca)
///
/// where m_xy is the vertex splitting edge xy. So child c of level i+1 has parent face c / 4,
/// level i has F0 · 4^i faces, and every vertex has a base face and barycentric coordinates.
/// The base mesh is an oriented manifold (boundaries allowed), hence so is every level.
class MultiresMesh
{
public:
    /// \brief An empty hierarchy (no levels).
    MultiresMesh() = default;

    /// \brief A hierarchy whose only level is `base`; the positions are taken in double
    /// precision with the base mesh's origin.
    /// \throw InvalidInput as validate()
    explicit MultiresMesh(const TriMesh& base);

    /// \brief A hierarchy from its raw data (as read from a file, never trusted).
    /// \throw InvalidInput as validate()
    explicit MultiresMesh(MultiresParts parts);

    /// \brief Checks every invariant: at least one base face, every base index in range, no
    /// degenerate base face, every base vertex used, the base an oriented manifold, level
    /// offsets starting 0 and growing, every level adding exactly one vertex per edge of the
    /// level below, each parent edge an edge of the level below named once, every position
    /// finite. Done by both constructors; hierarchies read from disk go through it.
    /// \throw InvalidInput saying what is wrong
    void validate() const;

    /// \brief Number of levels, J + 1 (0 for an empty hierarchy).
    [[nodiscard]] std::size_t level_count() const
    {
        return parts_.level_offsets.empty() ? 0 : parts_.level_offsets.size() - 1;
    }
    /// \brief Index J of the finest level. \pre level_count() > 0
    [[nodiscard]] std::size_t finest_level() const { return level_count() - 1; }
    /// \brief Vertices of level `level` (those of all coarser levels included).
    /// \throw InvalidInput if the level does not exist
    [[nodiscard]] std::size_t vertex_count(std::size_t level) const;
    /// \brief Vertices of the finest level.
    [[nodiscard]] std::size_t vertex_count() const { return parts_.positions.size(); }
    /// \brief Faces of level `level`: F0 · 4^level. \throw InvalidInput if it does not exist
    [[nodiscard]] std::size_t face_count(std::size_t level) const;
    /// \brief The level at which vertex v was added (0 for base vertices).
    /// \throw InvalidInput if v is out of range
    [[nodiscard]] std::size_t level_of_vertex(std::uint32_t v) const;

    [[nodiscard]] const Vec3d& origin() const { return parts_.origin; }
    /// \brief Every position, relative to origin(), level by level.
    [[nodiscard]] std::span<const Vec3d> positions() const { return parts_.positions; }
    /// \brief World position of vertex v.
    [[nodiscard]] Vec3d world(std::uint32_t v) const { return parts_.origin + parts_.positions[v]; }
    [[nodiscard]] std::span<const Triangle> base_faces() const { return parts_.base_faces; }
    [[nodiscard]] std::span<const std::size_t> level_offsets() const
    {
        return parts_.level_offsets;
    }
    /// \brief The parent edge of vertex v. \throw InvalidInput if v is a base vertex or out of
    /// range
    [[nodiscard]] ParentEdge parent_edge(std::uint32_t v) const;
    /// \brief The parent edges of every non-base vertex (entry v − vertex_count(0)).
    [[nodiscard]] std::span<const ParentEdge> parent_edges() const { return parts_.parent_edges; }
    /// \brief The predictor the refinement used, which the details are measured from.
    [[nodiscard]] Predictor predictor() const { return parts_.predictor; }
    /// \brief Records the predictor of the levels above the base (refine_once() does).
    void set_predictor(Predictor predictor) { parts_.predictor = predictor; }
    /// \brief The raw data, e.g. to write it to a file.
    [[nodiscard]] const MultiresParts& parts() const { return parts_; }

    /// \brief Faces of level `level`, derived from the base faces by the 1-to-4 splits.
    /// \throw InvalidInput if the level does not exist
    [[nodiscard]] std::vector<Triangle> faces(std::size_t level) const;
    /// \brief For each halfedge 3f + k of faces(level) (from corner k to corner k + 1 of face
    /// f), the vertex of level + 1 that splits its edge. Both halfedges of an interior edge get
    /// the same vertex. \throw InvalidInput unless level < finest_level()
    [[nodiscard]] std::vector<std::uint32_t> edge_vertices(std::size_t level) const;
    /// \brief Level `level` as an indexed mesh: its vertices (positions rounded to float,
    /// relative to origin(), so every level's vertex prefix is bit for bit that of the coarser
    /// levels) and faces. \throw InvalidInput if the level does not exist
    [[nodiscard]] TriMesh level_mesh(std::size_t level) const;

    /// \brief The four children of face f of some level, in the next level: 4f … 4f+3.
    [[nodiscard]] static std::array<std::uint32_t, 4> child_faces(std::uint32_t f)
    {
        return {4 * f, 4 * f + 1, 4 * f + 2, 4 * f + 3};
    }
    /// \brief The parent (in the level below) of face c of some level ≥ 1.
    [[nodiscard]] static std::uint32_t parent_face(std::uint32_t c) { return c / 4; }

    /// \brief What split() made, besides the new level: the connectivity a refinement needs.
    struct SplitResult
    {
        std::size_t level = 0;                    ///< index of the new level, J + 1
        std::vector<Triangle> faces;              ///< faces of level J (the parents)
        std::vector<std::uint32_t> edge_vertices; ///< as edge_vertices(J)
    };

    /// \brief Appends level J + 1 by the topological 1-to-4 split of level J: one new vertex
    /// per edge, numbered in the order in which the edges are first met going through faces(J)
    /// and their halfedges 3f, 3f+1, 3f+2, placed at the edge's midpoint (the refinement then
    /// moves it).
    /// \throw InvalidInput if the hierarchy is empty or the new level would need more than
    ///        2³² − 1 vertices or faces
    SplitResult split();

    /// \brief Positions of the vertices added by the finest level, writable (relative to
    /// origin()); coarser vertices cannot be moved. Empty if the hierarchy has only its base.
    [[nodiscard]] std::span<Vec3d> finest_new_positions();

    /// \brief Every position (relative to origin()), writable, for Level 3 editing: moving
    /// vertices keeps the hierarchy nested (nesting is in the connectivity, which cannot change).
    /// The caller keeps them finite (validate() checks).
    [[nodiscard]] std::span<Vec3d> mutable_positions() { return parts_.positions; }

    /// \brief Drops every level above `level` (keeping levels 0 … level).
    /// \throw InvalidInput if the level does not exist
    void truncate(std::size_t level);

private:
    MultiresParts parts_;
};

} // namespace pointform
