// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/spatial/point_grid.h"

#include "pointform/core/error.h"
#include "pointform/spatial/kd_tree.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cmath>
#include <limits>
#include <numeric>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace pointform {

namespace {

constexpr int coord_bits = 20;
constexpr std::int64_t max_cells = std::int64_t{1} << coord_bits;
constexpr std::size_t max_k = 64;
constexpr std::uint32_t group = 4; ///< slots per vector

/// Spreads the low 21 bits of v so that two zero bits follow each.
std::uint64_t spread(std::uint64_t v)
{
    v &= 0x1FFFFFU;
    v = (v | (v << 32U)) & 0x1F00000000FFFFULL;
    v = (v | (v << 16U)) & 0x1F0000FF0000FFULL;
    v = (v | (v << 8U)) & 0x100F00F00F00F00FULL;
    v = (v | (v << 4U)) & 0x10C30C30C30C30C3ULL;
    v = (v | (v << 2U)) & 0x1249249249249249ULL;
    return v;
}

std::uint64_t morton(std::int64_t x, std::int64_t y, std::int64_t z)
{
    return spread(static_cast<std::uint64_t>(x)) | (spread(static_cast<std::uint64_t>(y)) << 1U) |
           (spread(static_cast<std::uint64_t>(z)) << 2U);
}

/// The hash table's key of a cell: its coordinates side by side (cheaper than the Morton code
/// that orders the cells in memory).
std::uint64_t packed(std::int64_t x, std::int64_t y, std::int64_t z)
{
    return static_cast<std::uint64_t>(x) | (static_cast<std::uint64_t>(y) << 21U) |
           (static_cast<std::uint64_t>(z) << 42U);
}

std::uint64_t hash_of(std::uint64_t key, int shift)
{
    return (key * 0x9E3779B97F4A7C15ULL) >> static_cast<unsigned>(shift);
}

} // namespace

/// The points of some cells within a distance of the query, then the k nearest of them.
class PointGrid::Within
{
public:
    explicit Within(float reach2) : reach2_(reach2) {}

    /// Adds the points of `range` (a whole number of groups of four) within the reach.
    void scan(Range range, const Vec3f& q, const float* xs, const float* ys, const float* zs)
    {
        const std::uint32_t length = range.end - range.begin;
        if (count_ + length > capacity)
        {
            overflow_ = overflow_ || length > 0;
            return;
        }
#if defined(__SSE2__)
        const __m128 qx = _mm_set1_ps(q.x());
        const __m128 qy = _mm_set1_ps(q.y());
        const __m128 qz = _mm_set1_ps(q.z());
        const __m128 reach2 = _mm_set1_ps(reach2_);
        for (std::uint32_t s = range.begin; s < range.end; s += group)
        {
            const __m128 dx = _mm_sub_ps(_mm_load_ps(xs + s), qx);
            const __m128 dy = _mm_sub_ps(_mm_load_ps(ys + s), qy);
            const __m128 dz = _mm_sub_ps(_mm_load_ps(zs + s), qz);
            const __m128 d2 =
                _mm_add_ps(_mm_add_ps(_mm_mul_ps(dx, dx), _mm_mul_ps(dy, dy)), _mm_mul_ps(dz, dz));
            auto inside = static_cast<unsigned>(_mm_movemask_ps(_mm_cmple_ps(d2, reach2)));
            if (inside == 0)
            {
                continue;
            }
            alignas(16) std::array<std::uint32_t, group> bits;
            _mm_store_ps(reinterpret_cast<float*>(bits.data()), d2);
            for (; inside != 0; inside &= inside - 1)
            {
                const auto lane = static_cast<std::uint32_t>(std::countr_zero(inside));
                key_[count_++] = key_of(bits[lane], s + lane);
            }
        }
#else
        for (std::uint32_t s = range.begin; s < range.end; ++s)
        {
            const float dx = xs[s] - q.x();
            const float dy = ys[s] - q.y();
            const float dz = zs[s] - q.z();
            const float d2 = dx * dx + dy * dy + dz * dz;
            key_[count_] = key_of(std::bit_cast<std::uint32_t>(d2), s);
            count_ += d2 <= reach2_ ? 1U : 0U;
        }
#endif
    }

    [[nodiscard]] std::size_t count() const
    {
        return count_;
    }
    [[nodiscard]] bool overflow() const
    {
        return overflow_;
    }

    /// The k nearest, nearest first (k <= count()).
    void take_nearest(std::size_t k, std::span<std::uint32_t> slots, std::span<float> d2)
    {
        // Insertion into the sorted first k; later candidates mostly fail the first comparison.
        for (std::size_t i = 1; i < count_; ++i)
        {
            const std::uint64_t key = key_[i];
            if (i >= k && key >= key_[k - 1])
            {
                continue;
            }
            std::size_t j = std::min(i, k - 1);
            for (; j > 0 && key < key_[j - 1]; --j)
            {
                key_[j] = key_[j - 1];
            }
            key_[j] = key;
        }
        for (std::size_t j = 0; j < k; ++j)
        {
            slots[j] = static_cast<std::uint32_t>(key_[j]);
            d2[j] = std::bit_cast<float>(static_cast<std::uint32_t>(key_[j] >> 32U));
        }
    }

private:
    /// A candidate as one integer: the squared distance's bits (which order like the
    /// non-negative floats they are) over the slot, so that one comparison sorts by distance
    /// with ties to the earlier slot.
    static std::uint64_t key_of(std::uint32_t d2_bits, std::uint32_t slot)
    {
        return (std::uint64_t{d2_bits} << 32U) | slot;
    }

    static constexpr std::size_t capacity = 1024;
    float reach2_;
    std::size_t count_ = 0;
    bool overflow_ = false;
    std::array<std::uint64_t, capacity> key_;
};

/// The cells of the octant block that a thread searched last, and in which grid.
struct PointGrid::OctantCache
{
    std::uint64_t grid = 0;
    std::array<std::int64_t, 3> low{};
    std::array<Range, 8> ranges{};
};

namespace {
std::atomic<std::uint64_t> next_grid_id{1};
} // namespace

PointGrid::PointGrid(std::span<const Vec3f> points, float cell, const KdTree& fallback)
    : fallback_(&fallback), id_(next_grid_id.fetch_add(1))
{
    if (!(cell > 0.0F) || !std::isfinite(cell))
    {
        throw InvalidInput("point grid: the cell size must be positive");
    }
    const std::size_t n = points.size();
    if (n >= std::numeric_limits<std::uint32_t>::max() / 2)
    {
        throw InvalidInput("point grid: too many points");
    }
    Vec3f lo = Vec3f::Constant(std::numeric_limits<float>::max());
    Vec3f hi = Vec3f::Constant(std::numeric_limits<float>::lowest());
    for (const Vec3f& p : points)
    {
        lo = lo.cwiseMin(p);
        hi = hi.cwiseMax(p);
    }
    if (n == 0)
    {
        lo = hi = Vec3f::Zero();
    }
    // Keep every coordinate below 2^20 cells (a far outlier makes the cells larger, never the
    // keys ambiguous).
    const float extent = (hi - lo).maxCoeff();
    cell = std::max(cell, extent / static_cast<float>(max_cells - 2));
    cell_ = cell;
    inv_cell_ = 1.0F / cell;
    min_ = lo;
    dims_ = max_cells;
    count_ = n;

    std::vector<std::uint64_t> keys(n);    // Morton codes: the order of cells in memory
    std::vector<std::uint64_t> cell_of(n); // packed coordinates: the hash key
    for (std::size_t i = 0; i < n; ++i)
    {
        const Vec3f c = ((points[i] - min_) * inv_cell_).array().floor().matrix();
        const auto x = std::clamp<std::int64_t>(static_cast<std::int64_t>(c.x()), 0, dims_ - 1);
        const auto y = std::clamp<std::int64_t>(static_cast<std::int64_t>(c.y()), 0, dims_ - 1);
        const auto z = std::clamp<std::int64_t>(static_cast<std::int64_t>(c.z()), 0, dims_ - 1);
        keys[i] = morton(x, y, z);
        cell_of[i] = packed(x, y, z);
    }
    std::vector<std::uint32_t> sorted(n);
    std::iota(sorted.begin(), sorted.end(), 0U);
    std::sort(sorted.begin(), sorted.end(), [&](std::uint32_t a, std::uint32_t b) {
        return keys[a] < keys[b] || (keys[a] == keys[b] && a < b);
    });

    // Each cell's points take a whole number of groups of four slots, the rest padded with
    // points at infinity, so that a scan runs whole vectors.
    std::vector<std::pair<std::uint64_t, Range>> cells;
    std::uint32_t slots = 0;
    for (std::size_t s = 0; s < n;)
    {
        std::size_t e = s + 1;
        while (e < n && keys[sorted[e]] == keys[sorted[s]])
        {
            ++e;
        }
        const auto length = static_cast<std::uint32_t>(e - s);
        const std::uint32_t padded = (length + group - 1) / group * group;
        cells.emplace_back(cell_of[sorted[s]], Range{slots, slots + padded});
        slots += padded;
        s = e;
    }
    constexpr float far = std::numeric_limits<float>::infinity();
    order_.assign(slots, padding_slot);
    slot_of_.resize(n);
    xs_.assign(slots, far);
    ys_.assign(slots, far);
    zs_.assign(slots, far);
    std::size_t next = 0;
    for (const auto& [key, range] : cells)
    {
        for (std::uint32_t slot = range.begin;
             next < n && cell_of[sorted[next]] == key && slot < range.end; ++slot, ++next)
        {
            const std::uint32_t i = sorted[next];
            order_[slot] = i;
            slot_of_[i] = slot;
            xs_[slot] = points[i].x();
            ys_[slot] = points[i].y();
            zs_[slot] = points[i].z();
        }
    }

    const std::size_t capacity = std::bit_ceil(std::max<std::size_t>(2 * cells.size(), 16));
    table_.assign(capacity, Entry{});
    table_mask_ = capacity - 1;
    table_shift_ = 64 - std::countr_zero(capacity);
    for (const auto& [key, range] : cells)
    {
        std::uint64_t h = hash_of(key, table_shift_);
        while (table_[h].key != ~std::uint64_t{0})
        {
            h = (h + 1) & table_mask_;
        }
        table_[h] = Entry{key, range};
    }
}

PointGrid::Range PointGrid::cell_range(std::int64_t x, std::int64_t y, std::int64_t z) const
{
    if (x < 0 || y < 0 || z < 0 || x >= dims_ || y >= dims_ || z >= dims_)
    {
        return {};
    }
    const std::uint64_t key = packed(x, y, z);
    std::uint64_t h = hash_of(key, table_shift_);
    while (true)
    {
        const Entry& entry = table_[h];
        if (entry.key == key)
        {
            return entry.range;
        }
        if (entry.key == ~std::uint64_t{0})
        {
            return {};
        }
        h = (h + 1) & table_mask_;
    }
}

std::size_t PointGrid::knn(const Vec3f& query, std::size_t k, std::span<std::uint32_t> slots,
                           std::span<float> squared_distances) const
{
    const std::size_t found = knn_nearby(query, k, slots, squared_distances);
    return found > 0 || k == 0 || count_ == 0 ? found : knn_far(query, k, slots, squared_distances);
}

std::size_t PointGrid::knn_nearby(const Vec3f& query, std::size_t k, std::span<std::uint32_t> slots,
                                  std::span<float> squared_distances) const
{
    k = std::min(k, count_);
    PF_ASSERT(slots.size() >= k && squared_distances.size() >= k);
    if (k == 0)
    {
        return 0;
    }
    if (k <= max_k && query.allFinite())
    {
        const Vec3f scaled = (query - min_) * inv_cell_;
        const Vec3f floor = scaled.array().floor().matrix();
        const Vec3f frac = scaled - floor;
        // Cells far outside the grid cannot be addressed; those queries go to the kd-tree.
        if ((floor.array().abs() < static_cast<float>(max_cells)).all())
        {
            std::array<std::int64_t, 3> c{};
            std::array<std::int64_t, 3> low{}; // the octant block is low..low+1 on each axis
            float octant_reach = std::numeric_limits<float>::max();
            float ring_reach = std::numeric_limits<float>::max();
            for (std::size_t a = 0; a < 3; ++a)
            {
                const auto axis = static_cast<Eigen::Index>(a);
                c[a] = static_cast<std::int64_t>(floor[axis]);
                const bool lower = frac[axis] < 0.5F;
                low[a] = lower ? c[a] - 1 : c[a];
                octant_reach = std::min(octant_reach, lower ? 1.0F - frac[axis] : frac[axis]);
                ring_reach = std::min(ring_reach, std::min(frac[axis], 1.0F - frac[axis]));
            }
            // First the octant block, then the 3 × 3 × 3 block around the query's cell: each
            // keeps the points within the distance its cells guarantee, and succeeds when k
            // are there (every point outside is farther).
            for (int pass = 0; pass < 2; ++pass)
            {
                const float reach = (pass == 0 ? octant_reach : 1.0F + ring_reach) * cell_;
                Within within(reach * reach);
                if (pass == 0)
                {
                    // Coherent queries mostly share their octant block with the one before:
                    // each thread remembers the last block's cells.
                    thread_local OctantCache cache;
                    if (cache.grid != id_ || cache.low != low)
                    {
                        cache.grid = id_;
                        cache.low = low;
                        for (std::size_t i = 0; i < 8; ++i)
                        {
                            cache.ranges[i] =
                                cell_range(low[0] + static_cast<std::int64_t>(i & 1U),
                                           low[1] + static_cast<std::int64_t>((i >> 1U) & 1U),
                                           low[2] + static_cast<std::int64_t>((i >> 2U) & 1U));
                        }
                    }
                    for (const Range& range : cache.ranges)
                    {
                        within.scan(range, query, xs_.data(), ys_.data(), zs_.data());
                    }
                }
                else
                {
                    for (std::int64_t z = c[2] - 1; z <= c[2] + 1; ++z)
                    {
                        for (std::int64_t y = c[1] - 1; y <= c[1] + 1; ++y)
                        {
                            for (std::int64_t x = c[0] - 1; x <= c[0] + 1; ++x)
                            {
                                within.scan(cell_range(x, y, z), query, xs_.data(), ys_.data(),
                                            zs_.data());
                            }
                        }
                    }
                }
                if (within.overflow())
                {
                    break; // crowded (duplicates): the kd-tree
                }
                if (within.count() >= k)
                {
                    within.take_nearest(k, slots, squared_distances);
                    return k;
                }
            }
        }
    }

    return 0;
}

std::size_t PointGrid::knn_far(const Vec3f& query, std::size_t k, std::span<std::uint32_t> slots,
                               std::span<float> squared_distances) const
{
    k = std::min(k, count_);
    // Far from the points: the kd-tree, its indices mapped to slots.
    std::array<std::uint32_t, max_k> index_buffer{};
    std::array<float, max_k> d2_buffer{};
    std::vector<std::uint32_t> index_heap;
    std::vector<float> d2_heap;
    std::span<std::uint32_t> index(index_buffer.data(), std::min(k, max_k));
    std::span<float> d2(d2_buffer.data(), std::min(k, max_k));
    if (k > max_k)
    {
        index_heap.resize(k);
        d2_heap.resize(k);
        index = index_heap;
        d2 = d2_heap;
    }
    const std::size_t found = fallback_->knn(query, k, index, d2);
    for (std::size_t i = 0; i < found; ++i)
    {
        slots[i] = slot_of_[index[i]];
        squared_distances[i] = d2[i];
    }
    return found;
}

} // namespace pointform
