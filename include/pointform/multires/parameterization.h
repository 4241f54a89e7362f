// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include "pointform/core/types.h"
#include "pointform/geometry/multires_mesh.h"

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace pointform {

/// \file
/// \brief The parameterization of every level over the base mesh (§5.3) that the 1-to-4 splits
/// give for free: each vertex lies in a base face at exact dyadic barycentric coordinates (a
/// vertex added at level i has coordinates k / 2^i), and each face of level i is the image of a
/// dyadic sub-triangle of its base face f / 4^i.

/// \brief Where a vertex lies over the base mesh: base face and barycentric coordinates with
/// respect to that face's corners (in the face's corner order), summing to 1.
struct BaseCoordinates
{
    std::uint32_t face = 0;
    Vec3d barycentric = Vec3d(1.0, 0.0, 0.0);
};

/// \brief The parameterization of a hierarchy: for every vertex of every level its canonical
/// base coordinates, and the means to express a vertex in any base face whose closure holds it.
///
/// The canonical face of a vertex is the lowest-index base face whose closure holds it: a vertex
/// inside a base face has that face; one on a base edge or at a base vertex has the lowest of
/// the faces around it, and a zero coordinate (or two).
class Parameterization
{
public:
    /// \brief The parameterization of `mesh`'s connectivity (positions are not read).
    /// \throw InvalidInput if the hierarchy is empty
    explicit Parameterization(const MultiresMesh& mesh);

    /// \brief Canonical coordinates of every vertex (of the finest level; coarser levels' are a
    /// prefix).
    [[nodiscard]] std::span<const BaseCoordinates> coordinates() const { return coordinates_; }

    /// \brief Vertex v's barycentric coordinates in base face `face`, whose closure must hold v
    /// (exact: on a shared base edge or vertex, the coordinates of the shared corners carry
    /// over). \throw InvalidInput if the face's closure does not hold v
    [[nodiscard]] Vec3d coordinates_in(std::uint32_t face, std::uint32_t v) const;

    /// \brief The face of level `level` that holds the point with barycentric coordinates
    /// `barycentric` in base face `face` (on a shared edge of children, the lower-index child),
    /// and the point's barycentric coordinates in that face's corners. \pre barycentric ≥ 0,
    /// summing to 1 (to within rounding); level < level count
    struct Location
    {
        std::uint32_t face = 0; ///< index among faces(level)
        Vec3d barycentric = Vec3d(1.0, 0.0, 0.0);
    };
    [[nodiscard]] static Location locate(std::uint32_t face, const Vec3d& barycentric,
                                         std::size_t level);

    [[nodiscard]] std::span<const Triangle> base_faces() const { return base_faces_; }

private:
    std::vector<Triangle> base_faces_;
    std::vector<BaseCoordinates> coordinates_;
};

} // namespace pointform
