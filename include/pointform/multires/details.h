// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include "pointform/core/types.h"
#include "pointform/geometry/multires_mesh.h"

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace pointform {

/// \file
/// \brief Level 3 (§5.3): a hierarchy as base mesh plus details. The detail of a vertex added at
/// level i + 1 is its offset from the prediction made from level i, expressed in a local
/// orthonormal frame of level i at the prediction; synthesis rebuilds the finer levels from a
/// coarser one and the details. Because predictions are affine combinations and frames turn
/// with the mesh, a rigid motion of level i moves every finer level by the same motion, and a
/// smooth deformation of level i bends the fine relief instead of shearing it.

/// \brief The local frame of a new vertex: t along its parent edge (a → b), n the area-weighted
/// normal of the edge's one or two faces of level i made perpendicular to t, b = n × t.
struct LocalFrame
{
    Vec3d t = Vec3d::UnitX();
    Vec3d n = Vec3d::UnitZ();
    Vec3d b = -Vec3d::UnitY();
};

/// \brief The frame of the edge (a, b) whose faces are (a, b, c) and, unless `d` is null, (b, a,
/// d), all counter-clockwise seen from outside. Degenerate input gets a frame all the same (an
/// edge of length 0: t = x; faces of area 0: n perpendicular to t, chosen from the axes), so
/// analysis and synthesis stay exact inverses; only such frames do not turn with the mesh.
[[nodiscard]] LocalFrame local_frame(const Vec3d& a, const Vec3d& b, const Vec3d& c,
                                     const Vec3d* d);

/// \brief The details of a hierarchy: for vertex v ≥ vertex_count(0), entry v − vertex_count(0)
/// holds its offset from its prediction as (t, n, b) components in its LocalFrame.
struct MultiresDetails
{
    Predictor predictor = Predictor::Midpoint;
    std::vector<std::size_t> level_offsets; ///< as MultiresMesh::level_offsets()
    std::vector<Vec3d> coefficients;
};

/// \brief Per level i ≥ 1, what its details are like.
struct DetailLevelStats
{
    std::size_t level = 0;
    std::size_t details = 0;   ///< vertices added by the level
    double mean_length = 0.0;  ///< mean |detail|, world units
    double max_length = 0.0;   ///< largest |detail|
    double mean_normal = 0.0;  ///< mean |normal component|
    double mean_tangent = 0.0; ///< mean length of the tangential part (t, b)
    /// Share of the details that are almost pure normal offsets (the normal-mesh property of
    /// Guskov et al. 2000): the tangential part at most `normal_tolerance` × |detail| (zero
    /// details count as normal).
    double normal_share = 0.0;
};

/// \brief The prediction stencils and frame vertices of every level of one hierarchy's
/// connectivity, made once so that analysis and synthesis are plain loops (the reusable object
/// behind analyze_details() and synthesize_details(); a deformation keeps one to re-synthesize
/// per edit). Works for any hierarchy with the same connectivity (same base faces and parent
/// edges) as the one it was made from.
class DetailSynthesizer
{
public:
    /// \brief Stencils of `mesh`'s connectivity for `mesh.predictor()`.
    explicit DetailSynthesizer(const MultiresMesh& mesh);

    [[nodiscard]] Predictor predictor() const { return predictor_; }

    /// \brief The details of `mesh`'s positions.
    /// \throw InvalidInput if `mesh` has another vertex count per level
    [[nodiscard]] MultiresDetails analyze(const MultiresMesh& mesh) const;

    /// \brief Rebuilds levels from_level + 1 … J of `mesh` from its level `from_level` and the
    /// details. With `moved` (one flag per vertex of the finest level, set for the vertices of
    /// levels ≤ from_level that changed since the details were taken), only the vertices whose
    /// stencil or frame reads a moved vertex are recomputed, the others keep their positions bit
    /// for bit, and `moved` gains the recomputed vertices whose position changed. Parallel per
    /// level; the result does not depend on the thread count.
    /// \throw InvalidInput if the shapes do not match or from_level does not exist
    void synthesize(MultiresMesh& mesh, const MultiresDetails& details, std::size_t from_level,
                    std::vector<std::uint8_t>* moved = nullptr) const;

private:
    Predictor predictor_ = Predictor::Midpoint;
    std::vector<std::size_t> level_offsets_;
    /// Per new vertex (entry v − V0): parent edge ends a, b, the opposite corners c, d (d =
    /// none on the boundary) of the edge's faces.
    std::vector<std::array<std::uint32_t, 4>> frame_vertices_;
    /// Butterfly only: the stencils, CSR (stencil_offsets_ has one entry per new vertex + 1).
    std::vector<std::uint32_t> stencil_offsets_;
    std::vector<std::uint32_t> stencil_vertices_;
    std::vector<double> stencil_weights_;

    [[nodiscard]] Vec3d predict(std::size_t k, std::span<const Vec3d> x) const;
    [[nodiscard]] LocalFrame frame(std::size_t k, std::span<const Vec3d> x) const;
    void check_shape(const MultiresMesh& mesh, const char* what) const;
};

/// \brief The details of every vertex above the base, for the hierarchy's own predictor.
[[nodiscard]] MultiresDetails analyze_details(const MultiresMesh& mesh);

/// \brief Rebuilds levels from_level + 1 … J from level `from_level` and `details` (which must
/// come from a hierarchy with the same connectivity). synthesize_details(H, analyze_details(H),
/// 0) gives H back to within rounding.
/// \throw InvalidInput if the shapes do not match or from_level does not exist
void synthesize_details(MultiresMesh& mesh, const MultiresDetails& details,
                        std::size_t from_level = 0);

/// \brief Per level 1 … J, the statistics of its details; `normal_tolerance` in [0, 1] is the
/// largest tangential part, relative to the detail's length, of an "almost pure normal" detail.
/// \throw InvalidInput if normal_tolerance is outside [0, 1]
[[nodiscard]] std::vector<DetailLevelStats> detail_statistics(const MultiresDetails& details,
                                                              double normal_tolerance = 0.1);

} // namespace pointform
