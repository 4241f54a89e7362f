// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include "pointform/core/types.h"

#include <array>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

namespace pointform {

class KdTree;

/// \brief A sparse uniform grid over float points for exact k-nearest queries near the points.
///
/// The points are stored cell by cell (cells in Morton order) and the occupied cells are found
/// through a hash table, so a query reads a few short runs of contiguous memory instead of
/// walking a tree. A query first scans the 2 × 2 × 2 cells around it, then 3 × 3 × 3, then
/// 5 × 5 × 5, and stops as soon as the k-th nearest point found is closer than every point it
/// has not scanned; a query farther from the points than that goes to the kd-tree. With a cell
/// about twice the k-th neighbour distance of the points, queries near the surface they sample
/// (as fields and polygonization ask) stop after the first 8 cells.
///
/// The results are exact and ties are broken in a fixed order (by grid slot), so they do not
/// depend on the order of queries or on threads.
class PointGrid
{
public:
    /// \param points  the points (kept by copy, in grid order)
    /// \param cell    the cell size, > 0 (grown if the points span more than 2^20 cells)
    /// \param fallback a kd-tree over the same points, for queries far from them; must outlive
    ///                 the grid
    PointGrid(std::span<const Vec3f> points, float cell, const KdTree& fallback);

    /// \brief The k nearest points to `query`, nearest first, as slots (positions in grid
    /// order; original_index() maps them back).
    /// \param slots, squared_distances  caller buffers of size >= min(k, point count)
    /// \return how many were found: min(k, point count)
    /// \throw InvalidInput if a buffer is shorter
    std::size_t knn(const Vec3f& query, std::size_t k, std::span<std::uint32_t> slots,
                    std::span<float> squared_distances) const;

    /// \brief knn() where the grid alone answers it: returns 0 (and fills nothing) when the
    /// query is too far from the points for the cells around it, so that a caller who needs
    /// less there (say, the nearest point only) can ask the kd-tree for just that.
    std::size_t knn_nearby(const Vec3f& query, std::size_t k, std::span<std::uint32_t> slots,
                           std::span<float> squared_distances) const;

    /// \brief knn() of a query that knn_nearby() has already turned down (returned 0 for at
    /// least k): the kd-tree's answer, without scanning the grid's cells again.
    /// \param bound2  a squared distance that at least min(k, point count) points lie strictly
    ///        within, or infinity: it only speeds the search (KdTree::knn())
    /// \param slots, squared_distances  caller buffers of size >= min(k, point count)
    std::size_t knn_far(const Vec3f& query, std::size_t k, std::span<std::uint32_t> slots,
                        std::span<float> squared_distances,
                        float bound2 = std::numeric_limits<float>::infinity()) const;

    /// \brief knn_nearby() for many queries at once: query i's answer (the same neighbours, in
    /// the same order, with the same distances, bit for bit) goes to found[i] (the count, or 0)
    /// and to slots and squared_distances from i · k on.
    ///
    /// Faster where consecutive queries are close to each other (as in Morton order): the cells
    /// around a run of them are looked up once, an octant block's points are gathered once for
    /// the queries that share it, and each query sorts only the points within its nearest's
    /// distance plus about the previous query's spread to its k-th (widened while fewer than k
    /// are there) instead of all those within the reach. Uses AVX2 where the CPU has it.
    /// \param slots, squared_distances  caller buffers of size >= k · queries.size()
    /// \param found  a caller buffer of size >= queries.size()
    /// \throw InvalidInput if a buffer is shorter
    void knn_nearby(std::span<const Vec3f> queries, std::size_t k, std::span<std::uint32_t> slots,
                    std::span<float> squared_distances, std::span<std::uint32_t> found) const;

    /// \brief The squared distances from `query` to the points at `slots`, rounded as the grid's
    /// queries round them: bit for bit what knn() reports for those points, so that a caller
    /// that ranks candidates it already holds gets the same order and values as a query.
    /// \param squared_distances  a caller buffer of size >= slots.size()
    /// \throw InvalidInput if the buffer is shorter
    void squared_distances(const Vec3f& query, std::span<const std::uint32_t> slots,
                           std::span<float> squared_distances) const;

    /// \brief The slot of an original point index.
    [[nodiscard]] std::uint32_t slot_of(std::uint32_t index) const { return slot_of_[index]; }
    [[nodiscard]] std::uint32_t original_index(std::uint32_t slot) const { return order_[slot]; }
    /// \brief Slots in all, padding included: callers that keep attributes in grid order size
    /// them by this and fill the slots whose original_index() is not padding_slot.
    [[nodiscard]] std::size_t slot_count() const { return order_.size(); }
    /// \brief original_index() of a padding slot (cells are padded to whole vectors).
    static constexpr std::uint32_t padding_slot = ~std::uint32_t{0};
    [[nodiscard]] float cell_size() const { return cell_; }
    [[nodiscard]] std::size_t size() const { return count_; }

private:
    struct Range
    {
        std::uint32_t begin = 0;
        std::uint32_t end = 0;
    };
    struct Entry
    {
        std::uint64_t key = ~std::uint64_t{0};
        Range range;
    };
    class Within;
    class Selection;
    struct OctantCache;
    struct Lookup;
    /// Where a query falls: its cell, its octant block (the 2 × 2 × 2 cells from low to low + 1
    /// on each axis) and, in cells, the distance within which every point is in the octant
    /// block (octant_reach), and in the 3 × 3 × 3 block around the cell, minus 1 (ring_reach).
    struct Placement
    {
        std::array<std::int64_t, 3> cell{};
        std::array<std::int64_t, 3> low{};
        float octant_reach = 0.0F;
        float ring_reach = 0.0F;
    };

    /// \return false for queries that no cell can answer (non-finite, or too far out)
    [[nodiscard]] bool placed(const Vec3f& query, Placement& place) const;

    /// knn_nearby() by Within alone (k at most the point count).
    std::size_t knn_within(const Vec3f& query, std::size_t k, std::span<std::uint32_t> slots,
                           std::span<float> squared_distances) const;
    /// knn_nearby() of one placed query with AVX2 (Selection), `lookup` kept from the last
    /// query of this grid; `slot` and `d2` hold k entries.
    std::size_t wide_nearby(const Vec3f& query, const Placement& place, std::size_t k,
                            Lookup& lookup, std::uint32_t* slot, float* d2) const;
    [[nodiscard]] Range cell_range(std::int64_t x, std::int64_t y, std::int64_t z) const;

    const KdTree* fallback_;
    std::uint64_t id_; ///< unique per grid ever built, so thread caches never mix grids
    float cell_ = 0.0F;
    float inv_cell_ = 0.0F;
    Vec3f min_ = Vec3f::Zero();
    std::size_t count_ = 0;
    std::int64_t dims_ = 0; ///< cells per axis are < dims_ (a power-of-two bound for the keys)
    std::vector<float> xs_, ys_, zs_;
    std::vector<std::uint32_t> order_;
    std::vector<std::uint32_t> slot_of_;
    std::vector<Entry> table_;
    std::uint64_t table_mask_ = 0;
    int table_shift_ = 0;
};

} // namespace pointform
