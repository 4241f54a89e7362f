// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/spatial/kd_tree.h"

#include "pointform/core/error.h"
#include "pointform/core/memory.h"
#include "pointform/core/parallel.h"
#include "pointform/spatial/spatial_sort.h"

#include "unfused.h"

#include <nanoflann.hpp>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace pointform {
namespace {

/// nanoflann's dataset adaptor over the caller's positions: no copy.
struct PositionSpan
{
    std::span<const Vec3f> points;

    [[nodiscard]] std::size_t kdtree_get_point_count() const { return points.size(); }
    [[nodiscard]] float kdtree_get_pt(std::size_t i, std::size_t dim) const
    {
        return points[i][static_cast<Eigen::Index>(dim)];
    }
    template <class Box>
    bool kdtree_get_bbox(Box& /*box*/) const
    {
        return false;
    }
};

/// nanoflann's L2_Simple_Adaptor with the squared distance rounded as the point grid rounds
/// it (detail::unfused_squared_distance()), on any target: the two answer a query with the same
/// bits, so that a caller may take either's neighbours (and their distances) for the other's.
struct UnfusedL2
{
    using ElementType = float;
    using DistanceType = float;

    const PositionSpan& data_source;

    explicit UnfusedL2(const PositionSpan& source) : data_source(source) {}

    [[nodiscard]] float evalMetric(const float* a, std::uint32_t b, std::size_t /*size*/) const
    {
        const Vec3f& p = data_source.points[b];
        return detail::unfused_squared_distance(a[0], a[1], a[2], p.x(), p.y(), p.z());
    }

    template <typename U, typename V>
    [[nodiscard]] float accum_dist(const U a, const V b, std::size_t /*dim*/) const
    {
        return (a - b) * (a - b);
    }
};

using NanoTree = nanoflann::KDTreeSingleIndexAdaptor<UnfusedL2, PositionSpan, 3, std::uint32_t>;

constexpr std::size_t query_block = 2048;

/// The k nearest in the order (squared distance, index), whatever the tree's layout.
/// nanoflann's KNNResultSet (even with NANOFLANN_FIRST_MATCH) keeps whichever of several points
/// tied at the k-th distance the traversal met first: its leaves only offer points strictly
/// nearer than worstDist(), and it prunes a subtree when its distance bound, summed up
/// incrementally in float, exceeds worstDist(), and that bound can round a few ulps above the
/// distance of a point inside. Here, once full, worstDist() is the k-th distance plus a relative
/// slack of 2^-16 (far above the float rounding of the bound, about 2^-18 at depth 32, and
/// never less than one ulp), so every point tied at the k-th distance reaches addPoint(),
/// which keeps the lowest indices.
class OrderedKnnResult
{
public:
    using DistanceType = float;
    using IndexType = std::uint32_t;
    using CountType = std::size_t;

    /// The tree's leaves hold points at one place in ascending index order (build_in_order()),
    /// so a query whose k nearest are all coincident with it stops at the next coincident point
    /// (a higher index, as is every point left in that leaf; every other point is farther),
    /// instead of offering every copy: a cloud with 50,000 copies of one point took 84 s with
    /// nanoflann's tree and 8 s with the Morton tree before this.
    /// `original`: the caller's index of each of the tree's points (null: the same), whose
    /// order those copies keep.
    /// `bound2`: the search's bound until it is full (points at or beyond it are not offered),
    /// with the same slack as the bound it takes then.
    OrderedKnnResult(std::size_t capacity, std::uint32_t* indices, float* distances,
                     const std::uint32_t* original, float bound2 = infinity)
        : capacity_(capacity),
          indices_(indices),
          distances_(distances),
          original_(original),
          bound_(slackened(bound2))
    {}

    [[nodiscard]] std::size_t size() const { return count_; }
    [[nodiscard]] bool full() const { return count_ == capacity_; }

    /// Inserts (dist, index) in order; always lets the search go on.
    bool addPoint(float dist, std::uint32_t index)
    {
        if (original_ != nullptr)
            index = original_[index];
        const auto before = [](float d1, std::uint32_t i1, float d2, std::uint32_t i2) {
            return d1 < d2 || (d1 == d2 && i1 < i2);
        };
        if (full() && !before(dist, index, distances_[capacity_ - 1], indices_[capacity_ - 1]))
            return !(dist == 0.0F && distances_[capacity_ - 1] == 0.0F);
        std::size_t i = full() ? capacity_ - 1 : count_++;
        for (; i > 0 && before(dist, index, distances_[i - 1], indices_[i - 1]); --i)
        {
            distances_[i] = distances_[i - 1];
            indices_[i] = indices_[i - 1];
        }
        distances_[i] = dist;
        indices_[i] = index;
        if (full()) // the bound only changes here: not worked out at every node of the search
            bound_ = std::min(bound_, slackened(distances_[capacity_ - 1]));
        return true;
    }

    [[nodiscard]] float worstDist() const { return bound_; }

private:
    static constexpr float infinity = std::numeric_limits<float>::infinity();

    /// A squared distance `worst` widened by the slack (above the smallest normal float already
    /// more than one ulp).
    static float slackened(float worst)
    {
        constexpr float slack = 1.0F + 0x1p-16F;
        return worst >= std::numeric_limits<float>::min() ? worst * slack
                                                          : std::nextafter(worst, infinity);
    }

    std::size_t capacity_;
    std::uint32_t* indices_;
    float* distances_;
    const std::uint32_t* original_;
    std::size_t count_ = 0;
    float bound_; ///< worstDist(): the given bound until full
};

/// The nearest point found, as nanoflann's KNNResultSet of one keeps it (a point replaces it only
/// when strictly nearer, so of several tied the first met), with the caller's index. The bound
/// may start at a given point's distance.
class NearestResult
{
public:
    using DistanceType = float;
    using IndexType = std::uint32_t;
    using CountType = std::size_t;

    NearestResult(const std::uint32_t* original, std::uint32_t index, float distance)
        : original_(original), index_(index), distance_(distance)
    {}

    [[nodiscard]] std::size_t size() const { return 1; }
    [[nodiscard]] bool full() const { return true; }

    bool addPoint(float dist, std::uint32_t index)
    {
        if (dist < distance_)
        {
            distance_ = dist;
            index_ = original_ != nullptr ? original_[index] : index;
        }
        return true;
    }

    [[nodiscard]] float worstDist() const { return distance_; }
    [[nodiscard]] std::uint32_t index() const { return index_; }

private:
    const std::uint32_t* original_;
    std::uint32_t index_;
    float distance_;
};

using Node = NanoTree::Node;
using Offset = NanoTree::Offset;
using BoundingBox = NanoTree::BoundingBox;

/// The box around two boxes.
BoundingBox united(const BoundingBox& a, const BoundingBox& b)
{
    BoundingBox box;
    for (int d = 0; d < 3; ++d)
    {
        box[d].low = std::min(a[d].low, b[d].low);
        box[d].high = std::max(a[d].high, b[d].high);
    }
    return box;
}

/// Where points [left, right) in Morton order (their `keys` differing: `differ` is the first's
/// key xor the last's) split: at the first key with the highest differing bit set, along that
/// bit's axis.
struct MortonSplit
{
    Offset middle;
    int axis;
};

MortonSplit morton_split(std::span<const std::uint64_t> keys, Offset left, Offset right,
                         std::uint64_t differ)
{
    const int bit = 63 - std::countl_zero(differ);
    const std::uint64_t mask = std::uint64_t{1} << static_cast<unsigned>(bit);
    const auto middle = static_cast<Offset>(
        std::partition_point(keys.begin() + static_cast<std::ptrdiff_t>(left),
                             keys.begin() + static_cast<std::ptrdiff_t>(right),
                             [&](std::uint64_t key) { return (key & mask) == 0; }) -
        keys.begin());
    return {middle, bit % 3};
}

/// Points a subtree at least, below which it is built by one thread (morton_subtree()).
constexpr std::size_t min_subtree = 8192;

/// The subtree of points [left, right) of the tree's order `vacc`, whose Morton `keys` do not
/// decrease, its nodes taken in turn from `next`: each node splits its points where their keys
/// first differ, which is a plane between two halves of a grid cell (so every point of the first
/// child lies below every point of the second along that axis), down to leaves of at most `leaf`
/// points, or of copies of one point, in index order. A cell of more points than a leaf that do
/// not all lie at one place is keyed again over its own box (order_in_own_box()). `bbox` is set
/// to the points' box.
Node* morton_subtree(std::span<const Vec3f> points, std::span<std::uint32_t> vacc,
                     std::span<std::uint64_t> keys, std::size_t leaf, Node*& next, Offset left,
                     Offset right, BoundingBox& bbox)
{
    Node* node = next++;
    std::uint64_t differ = keys[left] ^ keys[right - 1];
    if (differ == 0 && right - left > leaf &&
        order_in_own_box(points, vacc.subspan(left, right - left),
                         keys.subspan(left, right - left)))
        differ = keys[left] ^ keys[right - 1];
    if (right - left <= leaf || differ == 0)
    {
        node->child1 = node->child2 = nullptr;
        node->node_type.lr.left = left;
        node->node_type.lr.right = right;
        for (int d = 0; d < 3; ++d)
            bbox[d].low = bbox[d].high = points[vacc[left]][d];
        for (Offset k = left + 1; k < right; ++k)
            for (int d = 0; d < 3; ++d)
            {
                bbox[d].low = std::min(bbox[d].low, points[vacc[k]][d]);
                bbox[d].high = std::max(bbox[d].high, points[vacc[k]][d]);
            }
        return node;
    }
    const auto [middle, axis] = morton_split(keys, left, right, differ);
    BoundingBox low;
    BoundingBox high;
    node->child1 = morton_subtree(points, vacc, keys, leaf, next, left, middle, low);
    node->child2 = morton_subtree(points, vacc, keys, leaf, next, middle, right, high);
    node->node_type.sub.divfeat = axis;
    node->node_type.sub.divlow = low[axis].high;
    node->node_type.sub.divhigh = high[axis].low;
    bbox = united(low, high);
    return node;
}

/// A node at the top of a tree built in parallel: split one by one, down to subtrees that are
/// then built at once.
struct Top
{
    Offset left;
    Offset right;
    BoundingBox bbox{}; // the points' own box once built
    std::size_t child1 = 0;
    std::size_t child2 = 0;
    NanoTree::Dimension cutfeat = 0;
    bool split = false;
    Node* node = nullptr;
};

/// Builds the `subtrees` (indices into `top`) at once, `build_subtree(t)` setting t's node and
/// box, then the split top nodes bottom up: their split bounds and boxes from their children's
/// boxes. The tree's root is top[0].
template <typename BuildSubtree>
void finish_tree(NanoTree& tree, std::vector<Top>& top, std::span<const std::size_t> subtrees,
                 const BuildSubtree& build_subtree)
{
    parallel_blocks(subtrees.size(), 1, [&](std::size_t begin, std::size_t end) {
        for (std::size_t s = begin; s < end; ++s)
            build_subtree(top[subtrees[s]]);
    });
    for (std::size_t t = top.size(); t-- > 0;)
    {
        Top& node = top[t];
        if (!node.split)
            continue;
        const Top& low = top[node.child1];
        const Top& high = top[node.child2];
        node.node = tree.pool.allocate<Node>();
        node.node->node_type.sub.divfeat = node.cutfeat;
        node.node->child1 = low.node;
        node.node->child2 = high.node;
        node.node->node_type.sub.divlow = low.bbox[node.cutfeat].high;
        node.node->node_type.sub.divhigh = high.bbox[node.cutfeat].low;
        node.bbox = united(low.bbox, high.bbox);
    }
    tree.root_bbox = top[0].bbox;
    tree.root_node = top[0].node;
}

} // namespace

struct KdTree::Impl
{
    /// The caller's points.
    std::span<const Vec3f> original;
    /// The caller's points in Morton order (spatial_order()), when they are not in it already:
    /// a tree over points scattered in memory (a file's order) answers queries several times
    /// slower, each point of a leaf on another cache line. Empty otherwise.
    std::vector<Vec3f> sorted;
    /// The caller's index of each point of `sorted` (spatial_order()); empty when not sorted.
    std::vector<std::uint32_t> original_index;
    PositionSpan data; ///< what the tree indexes: `sorted`, or else `original`
    NanoTree tree;
    /// The subtrees' nodes (the tree's own pool has the top ones): the subtree of points
    /// [left, right) has nodes [2 left, 2 right), more than its at most 2 (right - left) - 1.
    /// Left uninitialised, so only the pages used are ever resident; one block allocated by this
    /// thread, rather than pools by the threads that build the subtrees, which would keep the
    /// freed nodes in their own malloc arenas.
    std::unique_ptr<Node[]> nodes;

    Impl(std::span<const Vec3f> points, std::size_t leaf)
        : original(points),
          data{points},
          tree(3, data,
               nanoflann::KDTreeSingleIndexAdaptorParams(
                   leaf, nanoflann::KDTreeSingleIndexAdaptorFlags::SkipInitialBuildIndex))
    {
        if (!points.empty())
            build();
    }

    /// The caller's index of each tree index, or null when they are the same.
    [[nodiscard]] const std::uint32_t* caller_index() const
    {
        return original_index.empty() ? nullptr : original_index.data();
    }

    /// The tree over the points in Morton order (build_in_order()), the caller's if they are
    /// in it (as compute_surfels() and the field sort them), or else a copy put in it. The
    /// tree's layout does not change the k nearest neighbours (OrderedKnnResult) nor the
    /// caller's indices of any result.
    void build();

    /// The tree of morton_subtree() over points whose Morton `keys` do not decrease: the top
    /// nodes one by one down to subtrees of about n / 64 points (at least min_subtree), which
    /// are built at once; the top nodes' split bounds and boxes last, bottom up. Points at one
    /// place lie in one leaf, in index order.
    void build_in_order(std::span<std::uint64_t> keys);
};

void KdTree::Impl::build()
{
    const std::size_t n = original.size();
    // Filled in parallel (so the pages are touched where they are used), hence not zeroed first.
    const auto storage = std::make_unique_for_overwrite<std::uint64_t[]>(n);
    std::span<std::uint64_t> keys(storage.get(), n);
    morton_keys(original, keys);
    std::atomic<bool> in_order{true};
    parallel_blocks(n - 1, 1U << 16U, [&](std::size_t begin, std::size_t end) {
        bool local = true;
        for (std::size_t i = begin; i < end; ++i)
            local &= keys[i] <= keys[i + 1];
        if (!local)
            in_order.store(false, std::memory_order_relaxed);
    });
    if (in_order.load())
    {
        build_in_order(keys);
        return;
    }
    // The same keys in the new order (the box is the same), which does not decrease them;
    // points at one place keep their order.
    original_index = pointform::spatial_order(original);
    sorted.resize(n);
    const auto sorted_storage = std::make_unique_for_overwrite<std::uint64_t[]>(n);
    const std::span<std::uint64_t> sorted_keys(sorted_storage.get(), n);
    parallel_blocks(n, 1U << 16U, [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i)
        {
            sorted[i] = original[original_index[i]];
            sorted_keys[i] = keys[original_index[i]];
        }
    });
    data.points = sorted;
    build_in_order(sorted_keys);
}

void KdTree::Impl::build_in_order(std::span<std::uint64_t> keys)
{
    const std::span<const Vec3f> points = data.points;
    const std::size_t n = points.size();
    tree.m_size = n;
    tree.m_size_at_index_build = n;
    tree.vAcc.resize(n);
    parallel_blocks(n, 1U << 16U, [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i)
            tree.vAcc[i] = static_cast<std::uint32_t>(i);
    });
    const std::size_t leaf = tree.m_leaf_max_size;
    const std::size_t grain = std::max({min_subtree, n / 64, leaf});
    std::vector<Top> top{{.left = 0, .right = n}};
    std::vector<std::size_t> subtrees;
    for (std::size_t t = 0; t < top.size(); ++t)
    {
        const Offset left = top[t].left;
        const Offset right = top[t].right;
        const std::uint64_t differ = keys[left] ^ keys[right - 1];
        if (right - left <= grain || differ == 0)
        {
            subtrees.push_back(t);
            continue;
        }
        const auto [middle, axis] = morton_split(keys, left, right, differ);
        top[t].split = true;
        top[t].cutfeat = axis;
        top[t].child1 = top.size();
        top[t].child2 = top.size() + 1;
        top.push_back({.left = left, .right = middle});
        top.push_back({.left = middle, .right = right});
    }
    nodes.reset(new Node[2 * n]); // NOLINT(cppcoreguidelines-owning-memory): not initialised
    advise_sparse(nodes.get(), 2 * n * sizeof(Node)); // an eighth of it or so is used
    finish_tree(tree, top, subtrees, [&](Top& node) {
        Node* next = nodes.get() + 2 * node.left;
        node.node =
            morton_subtree(points, tree.vAcc, keys, leaf, next, node.left, node.right, node.bbox);
    });
}

KdTree::KdTree(std::span<const Vec3f> positions, const KdTreeOptions& options)
{
    if (positions.size() >= std::numeric_limits<std::uint32_t>::max())
        throw InvalidInput("kd-tree: " + std::to_string(positions.size()) +
                           " points exceed the 32-bit index range");
    impl_ = std::make_unique<Impl>(positions, options.leaf_size == 0 ? 16 : options.leaf_size);
}

KdTree::~KdTree() = default;
KdTree::KdTree(KdTree&&) noexcept = default;
KdTree& KdTree::operator=(KdTree&&) noexcept = default;

std::size_t KdTree::size() const
{
    return impl_->original.size();
}

void check_knn_table_shape(const KnnTable& table, std::size_t rows, const char* function)
{
    const std::string name(function);
    if (table.k == 0 ? !table.indices.empty() : table.indices.size() % table.k != 0)
        throw InvalidInput(name + ": neighbour table of " + std::to_string(table.indices.size()) +
                           " indices is not whole rows of k = " + std::to_string(table.k));
    if (table.rows() != rows)
        throw InvalidInput(name + ": neighbour table has " + std::to_string(table.rows()) +
                           " rows for " + std::to_string(rows) + " points");
    if (table.squared_distances.size() != table.rows() || table.k == 1)
        check_same_size(function, "the neighbour table's squared_distances",
                        table.squared_distances.size(), table.indices.size());
}

void check_knn_table(const KnnTable& table, std::size_t rows, std::size_t points,
                     const char* function)
{
    check_knn_table_shape(table, rows, function);
    // Whether any is out of range first (loops without branches, in parallel), the offender only
    // then.
    const auto limit = static_cast<std::uint64_t>(points);
    std::atomic<bool> out_of_range{false};
    parallel_blocks(table.indices.size(), std::size_t{1} << 20U,
                    [&](std::size_t begin, std::size_t end) {
                        bool local = false;
                        for (std::size_t i = begin; i < end; ++i)
                            local |= table.indices[i] >= limit;
                        if (local)
                            out_of_range.store(true, std::memory_order_relaxed);
                    });
    if (!out_of_range.load())
        return;
    const auto bad = static_cast<std::size_t>(
        std::find_if(table.indices.begin(), table.indices.end(),
                     [&](std::uint32_t index) { return index >= points; }) -
        table.indices.begin());
    throw_knn_index_out_of_range(table.indices[bad], bad / table.k, points, function);
}

void throw_knn_index_out_of_range(std::uint32_t index, std::size_t row, std::size_t points,
                                  const char* function)
{
    throw InvalidInput(std::string(function) + ": neighbour " + std::to_string(index) + " of row " +
                       std::to_string(row) + " is out of range for " + std::to_string(points) +
                       " points");
}

std::span<const Vec3f> KdTree::positions() const
{
    return impl_->original;
}

std::span<const std::uint32_t> KdTree::spatial_order() const
{
    return impl_->original_index;
}

std::size_t KdTree::knn(const Vec3f& query, std::size_t k, std::span<std::uint32_t> indices,
                        std::span<float> squared_distances) const
{
    return knn(query, k, std::numeric_limits<float>::infinity(), indices, squared_distances);
}

std::size_t KdTree::knn(const Vec3f& query, std::size_t k, float bound2,
                        std::span<std::uint32_t> indices, std::span<float> squared_distances) const
{
    k = std::min(k, size());
    check_buffer_size("KdTree::knn", "indices", indices.size(), k);
    check_buffer_size("KdTree::knn", "squared_distances", squared_distances.size(), k);
    if (k == 0)
        return 0;
    // NaN or negative: no bound.
    OrderedKnnResult result(k, indices.data(), squared_distances.data(), impl_->caller_index(),
                            bound2 >= 0.0F ? bound2 : std::numeric_limits<float>::infinity());
    impl_->tree.findNeighbors(result, query.data(), nanoflann::SearchParams());
    return result.size();
}

PointId KdTree::nearest_within_factor(const Vec3f& query, float factor,
                                      float* squared_distance) const
{
    PF_ASSERT(factor >= 1.0F);
    if (size() == 0)
        return {};
    NearestResult result(impl_->caller_index(), 0, std::numeric_limits<float>::max());
    nanoflann::SearchParams params;
    params.eps = factor - 1.0F;
    impl_->tree.findNeighbors(result, query.data(), params);
    if (squared_distance != nullptr)
        *squared_distance = result.worstDist();
    return PointId{result.index()};
}

PointId KdTree::nearest_within_factor(const Vec3f& query, float factor, PointId start,
                                      float* squared_distance) const
{
    PF_ASSERT(factor >= 1.0F);
    if (!start.is_valid() || start.value >= size()) [[unlikely]]
        throw InvalidInput("KdTree::nearest_within_factor: start " + std::to_string(start.value) +
                           " is not a point of the tree (" + std::to_string(size()) + " points)");
    // The result set's worst distance is the search's bound: preset it to the start's, so
    // that the search only looks for points nearer than that.
    const Vec3f& from = impl_->original[start.value];
    NearestResult result(impl_->caller_index(), start.value,
                         detail::unfused_squared_distance(query.x(), query.y(), query.z(), from.x(),
                                                          from.y(), from.z()));
    nanoflann::SearchParams params;
    params.eps = factor - 1.0F;
    impl_->tree.findNeighbors(result, query.data(), params);
    if (squared_distance != nullptr)
        *squared_distance = result.worstDist();
    return PointId{result.index()};
}

PointId KdTree::nearest(const Vec3f& query, float* squared_distance) const
{
    std::uint32_t index = 0;
    float d2 = 0.0F;
    if (knn(query, 1, {&index, 1}, {&d2, 1}) == 0)
        return {};
    if (squared_distance != nullptr)
        *squared_distance = d2;
    return PointId(index);
}

std::size_t KdTree::radius_search(const Vec3f& query, float radius,
                                  std::vector<std::uint32_t>& indices,
                                  std::vector<float>& squared_distances) const
{
    if (size() == 0)
        return 0;
    std::vector<std::pair<std::uint32_t, float>> found;
    nanoflann::SearchParams params;
    params.sorted = false;
    impl_->tree.radiusSearch(query.data(), radius * radius, found, params);
    if (const std::uint32_t* caller = impl_->caller_index(); caller != nullptr)
        for (auto& hit : found)
            hit.first = caller[hit.first];
    std::sort(found.begin(), found.end(), [](const auto& a, const auto& b) {
        return a.second < b.second || (a.second == b.second && a.first < b.first);
    });
    for (const auto& [index, d2] : found)
    {
        indices.push_back(index);
        squared_distances.push_back(d2);
    }
    return found.size();
}

KnnTable knn_batch(const KdTree& tree, std::span<const Vec3f> queries, std::size_t k,
                   const KnnOptions& options)
{
    if (k == 0 || k > tree.size())
        throw InvalidInput("k-nearest neighbours: k = " + std::to_string(k) +
                           " must be between 1 and the number of points (" +
                           std::to_string(tree.size()) + ")");
    KnnTable table;
    table.k = k;
    table.indices.resize(queries.size() * k);
    const bool all = !options.farthest_distance_only;
    table.squared_distances.resize(all ? queries.size() * k : queries.size());
    // The tree's own points are queried in its order, when it sorted them: each query near
    // the one before.
    const std::span<const std::uint32_t> order =
        queries.data() == tree.positions().data() && queries.size() == tree.size()
            ? tree.spatial_order()
            : std::span<const std::uint32_t>();
    ProgressReporter progress(options.progress, "k-nearest neighbours");
    parallel_blocks(
        queries.size(), query_block,
        [&](std::size_t begin, std::size_t end) {
            std::vector<float> row(all ? 0 : k);
            for (std::size_t j = begin; j < end; ++j)
            {
                const std::size_t i = order.empty() ? j : order[j];
                const std::span<float> distances =
                    all ? std::span<float>(table.squared_distances.data() + i * k, k)
                        : std::span<float>(row);
                tree.knn(queries[i], k, {table.indices.data() + i * k, k}, distances);
                if (!all)
                    table.squared_distances[i] = row[k - 1];
            }
        },
        &progress);
    progress.finish();
    return table;
}

RadiusTable radius_batch(const KdTree& tree, std::span<const Vec3f> queries, float radius,
                         const KnnOptions& options)
{
    if (!(radius >= 0.0F) || !std::isfinite(radius))
        throw InvalidInput("radius search: radius must be finite and non-negative");
    const std::size_t blocks = (queries.size() + query_block - 1) / query_block;
    // Each block gathers its rows locally; blocks are then concatenated in order.
    std::vector<RadiusTable> parts(blocks);
    ProgressReporter progress(options.progress, "radius search");
    parallel_blocks(
        queries.size(), query_block,
        [&](std::size_t begin, std::size_t end) {
            RadiusTable& part = parts[begin / query_block];
            part.offsets.push_back(0);
            for (std::size_t i = begin; i < end; ++i)
            {
                tree.radius_search(queries[i], radius, part.indices, part.squared_distances);
                part.offsets.push_back(part.indices.size());
            }
        },
        &progress);
    progress.finish();

    RadiusTable table;
    table.offsets.reserve(queries.size() + 1);
    table.offsets.push_back(0);
    for (const auto& part : parts)
    {
        const std::size_t base = table.indices.size();
        for (std::size_t r = 1; r < part.offsets.size(); ++r)
            table.offsets.push_back(base + part.offsets[r]);
        table.indices.insert(table.indices.end(), part.indices.begin(), part.indices.end());
        table.squared_distances.insert(table.squared_distances.end(),
                                       part.squared_distances.begin(),
                                       part.squared_distances.end());
    }
    if (queries.empty())
        table.offsets.assign(1, 0);
    return table;
}

} // namespace pointform
