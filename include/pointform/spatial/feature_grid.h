// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include "pointform/core/types.h"
#include "pointform/geometry/aabb.h"

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

namespace pointform {

/// \brief A dense grid of nodes that knows, at every node, a point near the nearest of the
/// points: an exact Euclidean feature transform of the points snapped to the nodes.
///
/// Node (i, j, k) lies at origin() + spacing() · (i, j, k). Each point is snapped to the node
/// nearest to it, its *site*, and each site keeps one *representative*: the point nearest to the
/// node, ties to the smallest index. Every node then stores the representative of its nearest
/// site and the squared distance to that site (exact: the separable lower envelope of parabolas
/// of Felzenszwalb and Huttenlocher, in integer arithmetic; ties between sites equally near are
/// broken in a fixed order).
///
/// Since every point lies within snap_radius() ≤ √3/2 · spacing() of its site, the grid bounds
/// the distance from any point p of the box to the nearest point both ways, from the 8 corners
/// of p's cell alone (see CellQuery). Far from the points, where an exact nearest-point search
/// visits most of them, this answers in constant time.
///
/// Building is parallel over grid rows and gives the same grid whatever the thread count.
/// Queries are const and may run concurrently.
class FeatureGrid
{
public:
    /// \brief What a node stores.
    struct Node
    {
        /// The representative of the node's nearest site (an index into the points).
        std::uint32_t point = 0;
        /// The squared distance from the node to that site, in units of spacing().
        std::uint32_t site_distance2 = 0;
    };

    /// \brief What the corners of a query's cell tell about the points near it.
    struct CellQuery
    {
        /// The representatives of the nearest sites of the cell's 8 corners (they may repeat),
        /// corner (dx, dy, dz) at index dx + 2 dy + 4 dz.
        std::array<std::uint32_t, 8> points{};
        /// A lower bound on the distance from the query to every point:
        /// max over the corners v of (distance from v to its nearest site − snap_radius() −
        /// ‖query − v‖). Then the nearest of `points` is at most
        /// (nearest distance) + 2 (snap_radius() + min over v ‖query − v‖) ≤ nearest + 2√3
        /// spacing() away (each corner's representative is within ‖query − v‖ + the corner's site
        /// distance
        /// + snap_radius(), and that site distance is at most ‖query − v‖ + nearest +
        /// snap_radius()).
        double lower_bound = 0.0;
    };

    /// \param points      the points (not kept), at most 2^32 − 1 of them
    /// \param box         the box that the nodes cover, in the points' units; it must hold every
    ///                    point
    /// \param max_nodes   nodes along the box's longest side, 2 to 1024; the spacing is that side
    ///                    over (max_nodes − 1), and the other sides get as many nodes as they need
    ///                    (at least 2)
    /// \throw InvalidInput if there are no points, a point is not finite or outside the box, the
    ///        box is empty or not finite, or max_nodes is out of range
    FeatureGrid(std::span<const Vec3f> points, const Aabb& box, std::size_t max_nodes);

    /// \brief Representatives of the corners of the cell that holds `p` and a lower bound on the
    /// distance from `p` to every point; nullopt if `p` is outside the grid (or not finite).
    [[nodiscard]] std::optional<CellQuery> query(const Vec3d& p) const;

    /// \brief A quick lower bound on the distance from `p` to every point, from the node nearest
    /// to `p` alone: its distance to its nearest site − snap_radius() − its distance to `p`
    /// (0 outside the grid). Looser than query()'s, which takes the best of 8 corners.
    [[nodiscard]] double lower_bound(const Vec3d& p) const;

    /// \brief The node a point snaps to (its site), as (i, j, k).
    [[nodiscard]] std::array<std::uint32_t, 3> site_of(const Vec3f& point) const;
    [[nodiscard]] const Node& node(std::uint32_t i, std::uint32_t j, std::uint32_t k) const
    {
        return nodes_[(static_cast<std::size_t>(k) * dims_[1] + j) * dims_[0] + i];
    }
    [[nodiscard]] Vec3d node_position(std::uint32_t i, std::uint32_t j, std::uint32_t k) const
    {
        return origin_ + spacing_ * Vec3d(i, j, k);
    }
    /// \brief Nodes along x, y and z.
    [[nodiscard]] const std::array<std::uint32_t, 3>& dims() const { return dims_; }
    [[nodiscard]] const Vec3d& origin() const { return origin_; }
    [[nodiscard]] double spacing() const { return spacing_; }
    /// \brief The largest distance from a point to its site (slightly rounded up), at most
    /// √3/2 · spacing().
    [[nodiscard]] double snap_radius() const { return snap_radius_; }
    /// \brief Memory held, in bytes (8 per node).
    [[nodiscard]] std::size_t memory_bytes() const { return nodes_.size() * sizeof(Node); }

private:
    std::array<std::uint32_t, 3> dims_{};
    Vec3d origin_ = Vec3d::Zero();
    double spacing_ = 0.0;
    double inv_spacing_ = 0.0;
    double snap_radius_ = 0.0;
    std::vector<Node> nodes_; ///< x fastest, then y, then z
};

} // namespace pointform
