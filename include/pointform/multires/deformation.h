// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include "pointform/core/types.h"
#include "pointform/geometry/multires_mesh.h"
#include "pointform/multires/details.h"

#include <Eigen/Core>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

namespace pointform {

/// \file
/// \brief Multiresolution deformation (§5.3, Fig. 11): an edit of level j deforms level j
/// smoothly (a bi-Laplacian solve) and levels j + 1 … J follow by synthesis of their details, so
/// the fine relief rides along undistorted. Coarser levels keep their vertices' new positions
/// (they are vertices of level j too), so the hierarchy stays nested.

/// \brief Where a deformation may move level j's vertices.
struct RegionOfInterest
{
    enum class Kind
    {
        Whole,    ///< every vertex of the level
        Vertices, ///< the listed vertices
        Ball,     ///< the vertices within `radius` of `center` (world coordinates)
        Box,      ///< the vertices in the box [min, max] (world coordinates)
    };
    Kind kind = Kind::Whole;
    std::vector<std::uint32_t> vertices;
    Vec3d center = Vec3d::Zero();
    double radius = 0.0;
    Vec3d min = Vec3d::Zero();
    Vec3d max = Vec3d::Zero();

    [[nodiscard]] static RegionOfInterest whole() { return {}; }
    [[nodiscard]] static RegionOfInterest of_vertices(std::vector<std::uint32_t> vertices);
    [[nodiscard]] static RegionOfInterest ball(const Vec3d& center, double radius);
    [[nodiscard]] static RegionOfInterest box(const Vec3d& min, const Vec3d& max);
};

/// \brief Handle vertices of level j and where they go: the affine map `transform` (a 4 × 4
/// matrix on world coordinates, last row 0 0 0 1) of their positions before the edit. The
/// vertices are listed by id, or chosen by place: with `vertices` empty, level j's vertices in
/// `selection` (a ball or a box), so that an edit written for one reconstruction still holds
/// when the ids change.
struct DeformHandle
{
    std::vector<std::uint32_t> vertices;
    Eigen::Matrix4d transform = Eigen::Matrix4d::Identity();
    RegionOfInterest selection = RegionOfInterest::of_vertices({});

    [[nodiscard]] static DeformHandle translate(std::vector<std::uint32_t> vertices,
                                                const Vec3d& by);
    [[nodiscard]] static DeformHandle affine(std::vector<std::uint32_t> vertices,
                                             const Eigen::Matrix4d& transform);
    /// The vertices in a ball or box (RegionOfInterest::ball(), box()), moved by `transform`.
    [[nodiscard]] static DeformHandle within(const RegionOfInterest& selection,
                                             const Eigen::Matrix4d& transform);
};

/// \brief An edit at level j: handles with their targets inside a region of interest.
struct MultiresEdit
{
    std::size_t level = 0;
    std::vector<DeformHandle> handles;
    RegionOfInterest region;
};

/// \brief What moved, per level i (its own vertices, those it added).
struct LevelMotion
{
    std::size_t level = 0;
    std::size_t vertices = 0; ///< vertices the level added (level 0: the base vertices)
    std::size_t moved = 0;    ///< of which moved
    double largest = 0.0;     ///< their largest displacement, world units
};

/// \brief The outcome of a deformation.
struct DeformReport
{
    std::size_t level = 0;           ///< the level edited
    std::size_t region_vertices = 0; ///< level j's vertices in the region
    std::size_t handle_vertices = 0; ///< handle vertices
    std::size_t free_vertices = 0;   ///< vertices the solve placed (region minus handles)
    /// Free vertices in parts of the region that touch neither a handle nor the region's rim:
    /// nothing constrains them, so they stay where they are.
    std::size_t unconstrained_vertices = 0;
    std::vector<LevelMotion> levels;   ///< every level, coarse to fine
    double largest_displacement = 0.0; ///< over every vertex
};

/// \brief The reusable solver of a multiresolution deformation: level j's bi-Laplacian system
/// (cotangent Laplacian L, lumped mass M, energy ‖M^(-1/2) L d‖² over the displacement d),
/// restricted to the free vertices (in the region, not handles) with the handles and every
/// vertex outside the region (the rim included) as constraints, is factored once (Eigen's
/// SimplicialLDLT, a sparse Cholesky); each apply() then solves for new handle targets, writes
/// level j's new positions and re-synthesizes the finer levels from the details taken at
/// construction. Outside the region nothing moves at any level, bit for bit (only vertices that
/// read a moved vertex are recomputed).
class MultiresDeformer
{
public:
    /// \brief Analyses `rest` (its details, the region, the handles' vertex sets) and factors the
    /// system. The handles' transforms are not used here; apply() takes the targets.
    /// \throw InvalidInput for a level that does not exist, an unknown vertex id, a vertex in two
    ///        handles or twice in one, a handle vertex outside the region, a non-finite or
    ///        non-affine transform, a ball of radius ≤ 0, an empty or inverted box, or a system
    ///        the factorization cannot solve
    MultiresDeformer(const MultiresMesh& rest, const MultiresEdit& edit);
    ~MultiresDeformer();
    MultiresDeformer(MultiresDeformer&&) noexcept;
    MultiresDeformer& operator=(MultiresDeformer&&) noexcept;

    /// \brief Handle vertices, handle by handle, in the order the edit listed them.
    [[nodiscard]] std::span<const std::uint32_t> handle_vertices() const;
    [[nodiscard]] std::size_t level() const;

    /// \brief Sets `mesh` (a hierarchy with the rest's connectivity) to the rest hierarchy
    /// deformed so that the handle vertices reach `targets` (world positions, one per
    /// handle_vertices() entry).
    /// \throw InvalidInput if the counts or shapes do not match or a target is not finite
    DeformReport apply(MultiresMesh& mesh, std::span<const Vec3d> targets) const;

    /// \brief As above, the targets the handles' transforms give their rest positions; the
    /// handles must name the same vertices as at construction.
    DeformReport apply(MultiresMesh& mesh, std::span<const DeformHandle> handles) const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

/// \brief One edit, made once: MultiresDeformer(mesh, edit).apply(mesh, edit.handles).
/// \throw InvalidInput as MultiresDeformer
DeformReport deform(MultiresMesh& mesh, const MultiresEdit& edit);

/// \brief What moved between two hierarchies of the same connectivity, per level.
[[nodiscard]] std::vector<LevelMotion> level_motion(const MultiresMesh& before,
                                                    const MultiresMesh& after);

} // namespace pointform
