// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include "pointform/core/progress.h"
#include "pointform/core/types.h"
#include "pointform/spatial/neighborhoods.h"

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>

namespace pointform {

/// \brief Options for building a KdTree.
struct KdTreeOptions
{
    /// Maximum number of points in a leaf. 10 to 32 is a good range for 3-D queries (16: fastest
    /// measured for k = 16 on 1M samples); 0 = 16.
    std::size_t leaf_size = 16;
};

/// \brief Options for batch queries.
struct KnnOptions
{
    /// knn_batch(): keep only each row's farthest squared distance (KnnTable).
    bool farthest_distance_only = false;
    /// Optional progress report, called from one thread.
    ProgressCallback progress;
};

/// \brief A kd-tree over float positions for exact k-nearest and radius queries.
///
/// The tree refers to the caller's positions, which must outlive it and stay unchanged; when
/// they are not in Morton order (spatial_order()), it keeps a copy in that order (16 bytes a
/// point, with their indices) to search, as points scattered in memory slow every query. Queries
/// are const and may run concurrently. Results are exact (Euclidean, in the positions' units) and
/// deterministic: knn() returns the k smallest (squared distance, index) pairs, so points tied at
/// the k-th distance (coincident points) are taken lowest index first, whatever the tree's layout
/// (leaf size) or the thread count.
class KdTree
{
public:
    /// \param positions  N points; N may be 0 (then every query returns nothing)
    /// \throw InvalidInput if N exceeds 2^32 - 1
    explicit KdTree(std::span<const Vec3f> positions, const KdTreeOptions& options = {});
    ~KdTree();
    KdTree(KdTree&&) noexcept;
    KdTree& operator=(KdTree&&) noexcept;
    KdTree(const KdTree&) = delete;
    KdTree& operator=(const KdTree&) = delete;

    [[nodiscard]] std::size_t size() const;
    [[nodiscard]] std::span<const Vec3f> positions() const;
    /// \brief The points' indices in Morton order (spatial_order()), when the tree had to sort
    /// a copy of them (they were not in that order); empty otherwise. Queries taken in this
    /// order run faster, each near the one before.
    [[nodiscard]] std::span<const std::uint32_t> spatial_order() const;

    /// \brief The k nearest points to `query` (a point of the tree is its own nearest).
    /// \param indices, squared_distances  caller buffers of size >= min(k, size()), filled
    ///        nearest first
    /// \return the number found, min(k, size())
    /// \throw InvalidInput if a buffer is shorter
    std::size_t knn(const Vec3f& query, std::size_t k, std::span<std::uint32_t> indices,
                    std::span<float> squared_distances) const;

    /// \brief knn() given a squared distance `bound2` that at least min(k, size()) points lie
    /// strictly within (say, the farthest of k points found for a nearby query, measured from
    /// this one): the search skips every subtree beyond it from the start, which far from the
    /// points (over a hole, say) saves most of the tree. The same answer as knn(), bit for bit,
    /// when the bound holds; fewer points (those within it) when it does not.
    std::size_t knn(const Vec3f& query, std::size_t k, float bound2,
                    std::span<std::uint32_t> indices, std::span<float> squared_distances) const;

    /// \brief The single nearest point; returns its index, or invalid if the tree is empty.
    [[nodiscard]] PointId nearest(const Vec3f& query, float* squared_distance = nullptr) const;

    /// \brief A point at most `factor` (≥ 1) times as far as the nearest: far from a surface
    /// every point is nearly as far as the nearest, and an exact search visits most of them.
    [[nodiscard]] PointId nearest_within_factor(const Vec3f& query, float factor,
                                                float* squared_distance = nullptr) const;

    /// \brief nearest_within_factor() given a point `start` of the tree known to be near the
    /// query (say, from a coarser structure): the search starts with its distance as the bound,
    /// so it skips every subtree farther than that from the start, and returns `start` itself
    /// when no point is nearer than its distance over `factor`. Same guarantee: the point
    /// returned is at most `factor` times as far as the nearest.
    /// \throw InvalidInput if `start` is not a point of the tree
    [[nodiscard]] PointId nearest_within_factor(const Vec3f& query, float factor, PointId start,
                                                float* squared_distance = nullptr) const;

    /// \brief Appends to the buffers every point within `radius` of `query`, nearest first.
    /// \return the number appended
    std::size_t radius_search(const Vec3f& query, float radius, std::vector<std::uint32_t>& indices,
                              std::vector<float>& squared_distances) const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

/// \brief k nearest neighbours of every query, in parallel.
/// \param queries  M query points (may be the tree's own positions)
/// \param k        neighbours a query, 1 <= k <= tree.size()
/// \return an M by k table
/// \throw InvalidInput if k is 0 or larger than the tree
[[nodiscard]] KnnTable knn_batch(const KdTree& tree, std::span<const Vec3f> queries, std::size_t k,
                                 const KnnOptions& options = {});

/// \brief All points within `radius` of every query, in parallel, as CSR.
/// \throw InvalidInput if radius is negative or not finite
[[nodiscard]] RadiusTable radius_batch(const KdTree& tree, std::span<const Vec3f> queries,
                                       float radius, const KnnOptions& options = {});

} // namespace pointform
