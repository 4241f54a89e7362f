// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/spatial/point_grid.h"

#include "pointform/core/error.h"
#include "pointform/core/parallel.h"
#include "pointform/spatial/kd_tree.h"

#include "unfused.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cmath>
#include <limits>
#include <memory>
#include <numeric>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#define PF_GRID_AVX2 1
#else
#define PF_GRID_AVX2 0
#endif

namespace pointform {

namespace {

constexpr int coord_bits = 20;
constexpr std::int64_t max_cells = std::int64_t{1} << coord_bits;
constexpr std::size_t max_k = 64;
constexpr std::uint32_t group = 4; ///< slots per vector
/// Points per block of the grid's parallel construction.
constexpr std::size_t build_block = 65536;

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

/// std::floor for finite floats, without a library call: below 2^23 in magnitude through the
/// integers, above it every float is an integer.
float floor_of(float x)
{
    constexpr float exact = 8388608.0F; // 2^23
    if (!(std::abs(x) < exact))
    {
        return x;
    }
    const auto truncated = static_cast<float>(static_cast<std::int32_t>(x));
    return truncated > x ? truncated - 1.0F : truncated;
}

/// How much wider than the last query's spread the first limit of a selection is (Selection):
/// wide enough that a second look is rare, narrow enough that few points are sorted.
constexpr float spread_margin = 1.25F;

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
            __m128 xx = _mm_mul_ps(dx, dx);
            __m128 yy = _mm_mul_ps(dy, dy);
            __m128 zz = _mm_mul_ps(dz, dz);
            PF_UNFUSED(xx);
            PF_UNFUSED(yy);
            PF_UNFUSED(zz);
            const __m128 d2 = _mm_add_ps(_mm_add_ps(xx, yy), zz);
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
            const float d2 =
                detail::unfused_squared_distance(xs[s], ys[s], zs[s], q.x(), q.y(), q.z());
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

#if PF_GRID_AVX2

namespace {

/// The k smallest of keys[0, count) (k <= count), smallest first, as slots and squared distances.
void take_smallest(std::uint64_t* keys, std::size_t count, std::size_t k, std::uint32_t* slots,
                   float* d2)
{
    // Insertion into the sorted first k; later candidates mostly fail the first comparison.
    for (std::size_t i = 1; i < count; ++i)
    {
        const std::uint64_t key = keys[i];
        if (i >= k && key >= keys[k - 1])
        {
            continue;
        }
        std::size_t j = std::min(i, k - 1);
        for (; j > 0 && key < keys[j - 1]; --j)
        {
            keys[j] = keys[j - 1];
        }
        keys[j] = key;
    }
    for (std::size_t j = 0; j < k; ++j)
    {
        slots[j] = static_cast<std::uint32_t>(keys[j]);
        d2[j] = std::bit_cast<float>(static_cast<std::uint32_t>(keys[j] >> 32U));
    }
}

/// For each 8-bit mask, the lanes set, in order, as 4-bit fields (a permutation that packs them
/// to the front).
constexpr std::array<std::uint32_t, 256> packing = [] {
    std::array<std::uint32_t, 256> table{};
    for (std::uint32_t mask = 0; mask < 256; ++mask)
    {
        std::uint32_t fields = 0;
        std::uint32_t at = 0;
        for (std::uint32_t lane = 0; lane < 8; ++lane)
        {
            if (((mask >> lane) & 1U) != 0)
            {
                fields |= lane << (4U * at++);
            }
        }
        table[mask] = fields;
    }
    return table;
}();

bool has_avx2()
{
    static const bool supported = [] {
        __builtin_cpu_init();
        return __builtin_cpu_supports("avx2") != 0;
    }();
    return supported;
}

/// (x − q)² + (y − q)² + (z − q)² of eight points, rounded as Within's four.
__attribute__((target("avx2"))) __m256 squared_distances_avx2(const float* xs, const float* ys,
                                                              const float* zs, __m256 qx, __m256 qy,
                                                              __m256 qz)
{
    const __m256 dx = _mm256_sub_ps(_mm256_loadu_ps(xs), qx);
    const __m256 dy = _mm256_sub_ps(_mm256_loadu_ps(ys), qy);
    const __m256 dz = _mm256_sub_ps(_mm256_loadu_ps(zs), qz);
    __m256 xx = _mm256_mul_ps(dx, dx);
    __m256 yy = _mm256_mul_ps(dy, dy);
    __m256 zz = _mm256_mul_ps(dz, dz);
    PF_UNFUSED(xx);
    PF_UNFUSED(yy);
    PF_UNFUSED(zz);
    return _mm256_add_ps(_mm256_add_ps(xx, yy), zz);
}

__attribute__((target("avx2"))) float smallest_lane(__m256 v)
{
    __m128 low = _mm_min_ps(_mm256_castps256_ps128(v), _mm256_extractf128_ps(v, 1));
    low = _mm_min_ps(low, _mm_movehl_ps(low, low));
    low = _mm_min_ss(low, _mm_shuffle_ps(low, low, 1));
    return _mm_cvtss_f32(low);
}

} // namespace

/// One pass of knn_nearby() (the k nearest of the points of some cells within a reach) with
/// AVX2, with the answer of Within (the k smallest keys of the points within the reach, or
/// none if fewer than k are there or too many crowd in): every squared distance is computed
/// once, with the nearest; then only the points within a limit are sorted, the nearest's
/// distance plus about the last query's spread from its nearest to its k-th (widened while
/// fewer than k are within it).
class PointGrid::Selection
{
public:
    enum class Outcome
    {
        found,
        fewer,     ///< fewer than k within the reach
        crowded,   ///< Within would overflow
        too_large, ///< more points than the buffer holds: the caller asks Within
    };

    /// The points of an octant block (its eight cells' slots one after the other), gathered
    /// into one run padded to whole vectors of eight with points at infinity.
    struct Block
    {
        static constexpr std::size_t capacity = 256; ///< below Within's: never crowded
        std::array<std::int64_t, 3> low{};
        bool valid = false;
        std::size_t count = 0;
        alignas(32) std::array<float, capacity> xs;
        alignas(32) std::array<float, capacity> ys;
        alignas(32) std::array<float, capacity> zs;
        alignas(32) std::array<std::uint32_t, capacity> slots;

        /// \return false (and invalid) if the cells hold too many points
        bool fill(const std::array<std::int64_t, 3>& block_low, std::span<const Range> ranges,
                  const float* grid_xs, const float* grid_ys, const float* grid_zs)
        {
            low = block_low;
            valid = false;
            std::size_t total = 0;
            for (const Range& range : ranges)
            {
                total += range.end - range.begin;
            }
            if (total > capacity)
            {
                return false;
            }
            count = 0;
            for (const Range& range : ranges)
            {
                std::copy(grid_xs + range.begin, grid_xs + range.end, xs.data() + count);
                std::copy(grid_ys + range.begin, grid_ys + range.end, ys.data() + count);
                std::copy(grid_zs + range.begin, grid_zs + range.end, zs.data() + count);
                std::iota(slots.data() + count, slots.data() + count + (range.end - range.begin),
                          range.begin);
                count += range.end - range.begin;
            }
            for (; count % 8 != 0; ++count)
            {
                xs[count] = ys[count] = zs[count] = std::numeric_limits<float>::infinity();
                slots[count] = 0;
            }
            valid = true;
            return true;
        }
    };

    /// The pass over the points of `ranges`, in order.
    /// \param spread2  the last query's k-th squared distance minus its nearest's (a guess that
    ///                 only sets how many points are sorted; NaN or <= 0: unknown)
    __attribute__((target("avx2,popcnt"))) Outcome run(std::span<const Range> ranges,
                                                       const Vec3f& q, std::size_t k, float reach2,
                                                       float spread2, const float* xs,
                                                       const float* ys, const float* zs,
                                                       std::uint32_t* slots, float* d2)
    {
        const __m256 qx = _mm256_set1_ps(q.x());
        const __m256 qy = _mm256_set1_ps(q.y());
        const __m256 qz = _mm256_set1_ps(q.z());
        const __m256 reach = _mm256_set1_ps(reach2);
        const __m256i lanes = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
        __m256 nearest = _mm256_set1_ps(std::numeric_limits<float>::infinity());
        std::size_t used = 0;
        std::size_t within = 0;
        for (const Range& range : ranges)
        {
            const std::uint32_t length = range.end - range.begin;
            if (within + length > capacity)
            {
                return Outcome::crowded;
            }
            if (used + length > buffered)
            {
                return Outcome::too_large;
            }
            // Eight at a time; a last group of four reads four more (the arrays are padded),
            // taken as infinitely far and then overwritten.
            for (std::uint32_t s = range.begin; s < range.end; s += 8)
            {
                __m256 dist2 = squared_distances_avx2(xs + s, ys + s, zs + s, qx, qy, qz);
                const bool four = range.end - s < 8;
                if (four)
                {
                    dist2 = _mm256_blend_ps(
                        dist2, _mm256_set1_ps(std::numeric_limits<float>::infinity()), 0xF0);
                }
                _mm256_storeu_ps(d2_.data() + used, dist2);
                _mm256_storeu_si256(
                    reinterpret_cast<__m256i*>(slot_.data() + used),
                    _mm256_add_epi32(_mm256_set1_epi32(static_cast<int>(s)), lanes));
                nearest = _mm256_min_ps(nearest, dist2);
                within += static_cast<std::size_t>(std::popcount(static_cast<unsigned>(
                    _mm256_movemask_ps(_mm256_cmp_ps(dist2, reach, _CMP_LE_OQ)))));
                used += four ? 4U : 8U;
            }
        }
        if (within < k)
        {
            return Outcome::fewer;
        }
        return pick(used, slot_.data(), smallest_lane(nearest), k, reach2, spread2, slots, d2);
    }

    /// run() over an octant block's cells gathered in `block`.
    __attribute__((target("avx2,popcnt"))) Outcome run(const Block& block, const Vec3f& q,
                                                       std::size_t k, float reach2, float spread2,
                                                       std::uint32_t* slots, float* d2)
    {
        const __m256 qx = _mm256_set1_ps(q.x());
        const __m256 qy = _mm256_set1_ps(q.y());
        const __m256 qz = _mm256_set1_ps(q.z());
        const __m256 reach = _mm256_set1_ps(reach2);
        __m256 nearest = _mm256_set1_ps(std::numeric_limits<float>::infinity());
        std::size_t within = 0;
        for (std::size_t i = 0; i < block.count; i += 8)
        {
            const __m256 dist2 = squared_distances_avx2(block.xs.data() + i, block.ys.data() + i,
                                                        block.zs.data() + i, qx, qy, qz);
            _mm256_storeu_ps(d2_.data() + i, dist2);
            nearest = _mm256_min_ps(nearest, dist2);
            within += static_cast<std::size_t>(std::popcount(static_cast<unsigned>(
                _mm256_movemask_ps(_mm256_cmp_ps(dist2, reach, _CMP_LE_OQ)))));
        }
        if (within < k)
        {
            return Outcome::fewer;
        }
        return pick(block.count, block.slots.data(), smallest_lane(nearest), k, reach2, spread2,
                    slots, d2);
    }

private:
    /// The k smallest keys of the `used` buffered points within the reach (k of them at least),
    /// whose slots are `slot_of`, given the smallest squared distance.
    __attribute__((target("avx2,popcnt"))) Outcome pick(std::size_t used,
                                                        const std::uint32_t* slot_of, float nearest,
                                                        std::size_t k, float reach2, float spread2,
                                                        std::uint32_t* slots, float* d2)
    {
        if (k == 1)
        {
            slots[0] = first_at(used, slot_of, nearest);
            d2[0] = nearest;
            return Outcome::found;
        }
        const float guess = nearest + spread2 * spread_margin;
        float limit2 = guess > nearest && guess < reach2 ? guess : reach2;
        // A limit that keeps more than max_ranked (and k) is halved towards the last one that
        // kept fewer than k (below) a few times, so that the short ranking serves most queries
        // whose guess was poor (the first of a run, or one far from the samples, where the
        // guess passes the reach). Any limit that keeps k gives the same k smallest keys.
        float below = nearest;
        float above = 0.0F; // the last limit that kept too many, if narrowed
        int narrowed = 0;
        while (true)
        {
            const std::size_t kept = gather(used, slot_of, limit2);
            if (kept >= k && kept <= max_ranked)
            {
                rank_smallest(kept, k, slots, d2);
                return Outcome::found;
            }
            if (kept >= k)
            {
                const float half = below + 0.5F * (limit2 - below);
                if (k <= max_ranked && narrowed < max_narrowed && half > below && half < limit2)
                {
                    above = limit2;
                    limit2 = half;
                    ++narrowed;
                    continue;
                }
                for (std::size_t j = 0; j < kept; ++j)
                {
                    keys_[j] = key_of(packed_d2_[j], packed_slot_[j]);
                }
                // take_smallest() is baseline code: leave the upper halves of the vector
                // registers clean for it (GCC 12 does not here), or on some CPUs every SSE
                // instruction after this pass runs several times slower.
                _mm256_zeroupper();
                take_smallest(keys_.data(), kept, k, slots, d2);
                return Outcome::found;
            }
            // Fewer than k within the limit (so it is below the reach): halfway to the limit
            // that kept too many, or, none known, twice as wide (at most the reach, within
            // which k are).
            below = limit2;
            if (narrowed > 0)
            {
                const float half = below + 0.5F * (above - below);
                limit2 = narrowed < max_narrowed && half > below && half < above ? half : above;
                ++narrowed;
                continue;
            }
            const float wider = nearest + 2.0F * (limit2 - nearest);
            limit2 = wider > limit2 && wider < reach2 ? wider : reach2;
        }
    }

    /// The first slot of the buffered points at `distance2`.
    __attribute__((target("avx2"))) std::uint32_t first_at(std::size_t used,
                                                           const std::uint32_t* slot_of,
                                                           float distance2) const
    {
        const __m256 at = _mm256_set1_ps(distance2);
        std::uint32_t first = std::numeric_limits<std::uint32_t>::max();
        for (std::size_t i = 0; i < used; i += 8)
        {
            auto equal = static_cast<unsigned>(
                _mm256_movemask_ps(_mm256_cmp_ps(_mm256_loadu_ps(d2_.data() + i), at, _CMP_EQ_OQ)));
            if (used - i < 8)
            {
                equal &= 0x0FU;
            }
            for (; equal != 0; equal &= equal - 1)
            {
                first =
                    std::min(first, slot_of[i + static_cast<std::size_t>(std::countr_zero(equal))]);
            }
        }
        return first;
    }

    /// The keys of the buffered points within the limit, in keys_; how many.
    __attribute__((target("avx2,popcnt"))) std::size_t gather(std::size_t used,
                                                              const std::uint32_t* slot_of,
                                                              float limit2)
    {
        const __m256 limit = _mm256_set1_ps(limit2);
        const __m256i shifts = _mm256_setr_epi32(0, 4, 8, 12, 16, 20, 24, 28);
        const __m256i seven = _mm256_set1_epi32(7);
        std::size_t count = 0;
        for (std::size_t i = 0; i < used; i += 8)
        {
            const __m256 dist2 = _mm256_loadu_ps(d2_.data() + i);
            auto mask =
                static_cast<unsigned>(_mm256_movemask_ps(_mm256_cmp_ps(dist2, limit, _CMP_LE_OQ)));
            if (used - i < 8)
            {
                mask &= 0x0FU;
            }
            const __m256i order = _mm256_and_si256(
                _mm256_srlv_epi32(_mm256_set1_epi32(static_cast<int>(packing[mask])), shifts),
                seven);
            _mm256_storeu_si256(reinterpret_cast<__m256i*>(packed_d2_.data() + count),
                                _mm256_permutevar8x32_epi32(_mm256_castps_si256(dist2), order));
            _mm256_storeu_si256(
                reinterpret_cast<__m256i*>(packed_slot_.data() + count),
                _mm256_permutevar8x32_epi32(
                    _mm256_loadu_si256(reinterpret_cast<const __m256i*>(slot_of + i)), order));
            count += static_cast<std::size_t>(std::popcount(mask));
        }
        return count;
    }

    /// take_smallest() of the first `count` gathered points (at most max_ranked), by counting
    /// for each how many come before it: nearer, or as near with a smaller slot (the keys'
    /// order; the keys differ, their slots do).
    __attribute__((target("avx2,popcnt"))) void rank_smallest(std::size_t count, std::size_t k,
                                                              std::uint32_t* slots, float* d2)
    {
        // Squared distances are not negative and slots are below 2^31, so signed 32-bit
        // comparisons order both; the padding is farther than all.
        const std::size_t vectors = (count + 7) / 8;
        for (std::size_t i = count; i < 8 * vectors; ++i)
        {
            packed_d2_[i] = static_cast<std::uint32_t>(std::numeric_limits<std::int32_t>::max());
            packed_slot_[i] = 0;
        }
        __m256i dist[max_ranked / 8]; // NOLINT(*-avoid-c-arrays): std::array drops the
                                      // vector type's attributes
        __m256i slot[max_ranked / 8]; // NOLINT(*-avoid-c-arrays)
        for (std::size_t v = 0; v < vectors; ++v)
        {
            dist[v] =
                _mm256_loadu_si256(reinterpret_cast<const __m256i*>(packed_d2_.data() + 8 * v));
            slot[v] =
                _mm256_loadu_si256(reinterpret_cast<const __m256i*>(packed_slot_.data() + 8 * v));
        }
        for (std::size_t i = 0; i < count; ++i)
        {
            const __m256i probe_dist = _mm256_set1_epi32(static_cast<int>(packed_d2_[i]));
            const __m256i probe_slot = _mm256_set1_epi32(static_cast<int>(packed_slot_[i]));
            std::size_t rank = 0;
            for (std::size_t v = 0; v < vectors; ++v)
            {
                const __m256i nearer = _mm256_cmpgt_epi32(probe_dist, dist[v]);
                const __m256i tied = _mm256_and_si256(_mm256_cmpeq_epi32(probe_dist, dist[v]),
                                                      _mm256_cmpgt_epi32(probe_slot, slot[v]));
                rank += static_cast<std::size_t>(std::popcount(static_cast<unsigned>(
                    _mm256_movemask_ps(_mm256_castsi256_ps(_mm256_or_si256(nearer, tied))))));
            }
            if (rank < k)
            {
                slots[rank] = packed_slot_[i];
                d2[rank] = std::bit_cast<float>(packed_d2_[i]);
            }
        }
    }

    /// As Within's keys.
    static std::uint64_t key_of(std::uint32_t d2_bits, std::uint32_t slot)
    {
        return (std::uint64_t{d2_bits} << 32U) | slot;
    }

    static constexpr std::size_t capacity = 1024; ///< Within's
    static constexpr std::size_t buffered = 2048;
    static constexpr std::size_t max_ranked = 24;
    /// How many times pick() may halve a limit that keeps more than max_ranked.
    static constexpr int max_narrowed = 4;
    /// Every point's squared distance and slot (+ 8: the loops write whole vectors).
    std::array<float, buffered + 8> d2_;
    std::array<std::uint32_t, buffered + 8> slot_;
    std::array<std::uint32_t, capacity + 8> packed_d2_;
    std::array<std::uint32_t, capacity + 8> packed_slot_;
    std::array<std::uint64_t, capacity + 8> keys_;
};

/// What the wide knn_nearby() keeps from query to query: the cells and octant blocks looked up
/// last (direct-mapped by their coordinates: coherent queries come back to them), the
/// selection's buffers, and the last query's spread from its nearest to its k-th (a guess for
/// the next, which sets only how many points are sorted).
struct PointGrid::Lookup
{
    struct CachedCell
    {
        std::uint64_t key = ~std::uint64_t{0}; ///< never a cell's
        Range range;
    };

    /// Forgets everything looked up (in another grid, or in none yet).
    void reset(std::uint64_t grid_id)
    {
        grid = grid_id;
        for (CachedCell& cell : cells)
        {
            cell.key = ~std::uint64_t{0};
        }
        for (Selection::Block& block : blocks)
        {
            block.valid = false;
        }
        spread2 = std::numeric_limits<float>::quiet_NaN();
    }

    std::uint64_t grid = 0;
    std::array<CachedCell, 512> cells;
    std::array<Selection::Block, 8> blocks;
    std::array<Range, 27> ranges;
    Selection selection;
    float spread2 = std::numeric_limits<float>::quiet_NaN();
};

std::size_t PointGrid::wide_nearby(const Vec3f& query, const Placement& place, std::size_t k,
                                   Lookup& lookup, std::uint32_t* slot, float* d2) const
{
    const std::size_t want = std::min(k, count_);
    const auto range_at = [&](std::int64_t x, std::int64_t y, std::int64_t z) {
        if (x < 0 || y < 0 || z < 0 || x >= dims_ || y >= dims_ || z >= dims_)
        {
            return Range{};
        }
        const std::uint64_t key = packed(x, y, z);
        Lookup::CachedCell& cached =
            lookup.cells[static_cast<std::size_t>((x & 7) | ((y & 7) << 3) | ((z & 7) << 6))];
        if (cached.key != key)
        {
            cached.key = key;
            cached.range = cell_range(x, y, z);
        }
        return cached.range;
    };
    std::array<Range, 27>& ranges = lookup.ranges;
    const auto octant_cells = [&] {
        for (std::size_t j = 0; j < 8; ++j)
        {
            ranges[j] = range_at(place.low[0] + static_cast<std::int64_t>(j & 1U),
                                 place.low[1] + static_cast<std::int64_t>((j >> 1U) & 1U),
                                 place.low[2] + static_cast<std::int64_t>((j >> 2U) & 1U));
        }
        return std::span<const Range>(ranges.data(), 8);
    };
    const float octant = place.octant_reach * cell_;
    Selection::Block* block = &lookup.blocks[static_cast<std::size_t>(
        (place.low[0] + 3 * place.low[1] + 5 * place.low[2]) & 7)];
    if ((!block->valid || block->low != place.low) &&
        !block->fill(place.low, octant_cells(), xs_.data(), ys_.data(), zs_.data()))
    {
        block = nullptr;
    }
    Selection& selection = lookup.selection;
    auto outcome =
        block != nullptr
            ? selection.run(*block, query, want, octant * octant, lookup.spread2, slot, d2)
            : selection.run(octant_cells(), query, want, octant * octant, lookup.spread2,
                            xs_.data(), ys_.data(), zs_.data(), slot, d2);
    if (outcome == Selection::Outcome::fewer)
    {
        std::size_t j = 0;
        for (std::int64_t z = place.cell[2] - 1; z <= place.cell[2] + 1; ++z)
        {
            for (std::int64_t y = place.cell[1] - 1; y <= place.cell[1] + 1; ++y)
            {
                for (std::int64_t x = place.cell[0] - 1; x <= place.cell[0] + 1; ++x)
                {
                    ranges[j++] = range_at(x, y, z);
                }
            }
        }
        const float ring = (1.0F + place.ring_reach) * cell_;
        outcome = selection.run(ranges, query, want, ring * ring, lookup.spread2, xs_.data(),
                                ys_.data(), zs_.data(), slot, d2);
    }
    std::size_t found = 0;
    if (outcome == Selection::Outcome::too_large)
    {
        found = knn_within(query, want, std::span(slot, want), std::span(d2, want));
    }
    else if (outcome == Selection::Outcome::found)
    {
        found = want;
    }
    if (found != 0)
    {
        lookup.spread2 = d2[want - 1] - d2[0];
    }
    return found;
}

#endif // PF_GRID_AVX2

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

    // Each point's cell: its Morton code (the order of cells in memory) and packed coordinates
    // (the hash key), sorted by code and then index (a strict order: the same for any thread
    // count), all in parallel.
    struct Keyed
    {
        std::uint64_t morton;
        std::uint64_t cell;
        std::uint32_t index;
    };
    std::vector<Keyed> sorted(n);
    parallel_blocks(n, build_block, [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i)
        {
            const Vec3f c = ((points[i] - min_) * inv_cell_).array().floor().matrix();
            const auto x = std::clamp<std::int64_t>(static_cast<std::int64_t>(c.x()), 0, dims_ - 1);
            const auto y = std::clamp<std::int64_t>(static_cast<std::int64_t>(c.y()), 0, dims_ - 1);
            const auto z = std::clamp<std::int64_t>(static_cast<std::int64_t>(c.z()), 0, dims_ - 1);
            sorted[i] = Keyed{morton(x, y, z), packed(x, y, z), static_cast<std::uint32_t>(i)};
        }
    });
    parallel_sort(sorted, [](const Keyed& a, const Keyed& b) {
        return a.morton < b.morton || (a.morton == b.morton && a.index < b.index);
    });

    // Each cell's points take a whole number of groups of four slots, the rest padded with
    // points at infinity, so that a scan runs whole vectors.
    struct Cell
    {
        std::uint64_t key;
        Range range;
        std::uint32_t first; ///< its first point in `sorted`
    };
    std::vector<Cell> cells;
    std::uint32_t slots = 0;
    for (std::size_t s = 0; s < n;)
    {
        std::size_t e = s + 1;
        while (e < n && sorted[e].morton == sorted[s].morton)
        {
            ++e;
        }
        const auto length = static_cast<std::uint32_t>(e - s);
        const std::uint32_t padded = (length + group - 1) / group * group;
        cells.push_back(
            Cell{sorted[s].cell, Range{slots, slots + padded}, static_cast<std::uint32_t>(s)});
        slots += padded;
        s = e;
    }
    constexpr float far = std::numeric_limits<float>::infinity();
    order_.assign(slots, padding_slot);
    slot_of_.resize(n);
    // Four more at the end: Selection reads whole vectors of eight.
    xs_.assign(slots + group, far);
    ys_.assign(slots + group, far);
    zs_.assign(slots + group, far);
    parallel_blocks(cells.size(), build_block / 8, [&](std::size_t begin, std::size_t end) {
        for (std::size_t c = begin; c < end; ++c)
        {
            const Cell& run = cells[c];
            std::uint32_t next = run.first;
            for (std::uint32_t slot = run.range.begin;
                 next < n && sorted[next].cell == run.key && slot < run.range.end; ++slot, ++next)
            {
                const std::uint32_t i = sorted[next].index;
                order_[slot] = i;
                slot_of_[i] = slot;
                xs_[slot] = points[i].x();
                ys_[slot] = points[i].y();
                zs_[slot] = points[i].z();
            }
        }
    });

    const std::size_t capacity = std::bit_ceil(std::max<std::size_t>(2 * cells.size(), 16));
    table_.assign(capacity, Entry{});
    table_mask_ = capacity - 1;
    table_shift_ = 64 - std::countr_zero(capacity);
    for (const Cell& run : cells)
    {
        std::uint64_t h = hash_of(run.key, table_shift_);
        while (table_[h].key != ~std::uint64_t{0})
        {
            h = (h + 1) & table_mask_;
        }
        table_[h] = Entry{run.key, run.range};
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

bool PointGrid::placed(const Vec3f& query, Placement& place) const
{
    place.octant_reach = std::numeric_limits<float>::max();
    place.ring_reach = std::numeric_limits<float>::max();
    for (Eigen::Index axis = 0; axis < 3; ++axis)
    {
        const float scaled = (query[axis] - min_[axis]) * inv_cell_;
        const float floor = floor_of(scaled);
        // Cells far outside the grid cannot be addressed (nor non-finite queries): those
        // queries go to the kd-tree.
        if (!std::isfinite(query[axis]) || !(std::abs(floor) < static_cast<float>(max_cells)))
        {
            return false;
        }
        const float frac = scaled - floor;
        const auto a = static_cast<std::size_t>(axis);
        place.cell[a] = static_cast<std::int64_t>(floor);
        const bool lower = frac < 0.5F;
        place.low[a] = lower ? place.cell[a] - 1 : place.cell[a];
        place.octant_reach = std::min(place.octant_reach, lower ? 1.0F - frac : frac);
        place.ring_reach = std::min(place.ring_reach, std::min(frac, 1.0F - frac));
    }
    return true;
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
    check_buffer_size("PointGrid::knn", "slots", slots.size(), k);
    check_buffer_size("PointGrid::knn", "squared_distances", squared_distances.size(), k);
    if (k == 0)
    {
        return 0;
    }
#if PF_GRID_AVX2
    if (k <= max_k && has_avx2())
    {
        // Each thread keeps its lookups from query to query (coherent queries, such as the
        // steps of a projection along a line, come back to the same cells).
        thread_local std::unique_ptr<Lookup> lookup;
        if (!lookup)
        {
            lookup = std::make_unique_for_overwrite<Lookup>(); // grid 0: no grid's, reset below
        }
        if (lookup->grid != id_)
        {
            lookup->reset(id_);
        }
        Placement place;
        return placed(query, place)
                   ? wide_nearby(query, place, k, *lookup, slots.data(), squared_distances.data())
                   : 0;
    }
#endif
    return knn_within(query, k, slots, squared_distances);
}

std::size_t PointGrid::knn_within(const Vec3f& query, std::size_t k, std::span<std::uint32_t> slots,
                                  std::span<float> squared_distances) const
{
    Placement place;
    if (k <= max_k && placed(query, place))
    {
        {
            const std::array<std::int64_t, 3>& c = place.cell;
            const std::array<std::int64_t, 3>& low = place.low;
            const float octant_reach = place.octant_reach;
            const float ring_reach = place.ring_reach;
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

void PointGrid::knn_nearby(std::span<const Vec3f> queries, std::size_t k,
                           std::span<std::uint32_t> slots, std::span<float> squared_distances,
                           std::span<std::uint32_t> found) const
{
    const std::size_t n = queries.size();
    check_buffer_size("PointGrid::knn_nearby", "found", found.size(), n);
    if (n > 0 && k > std::numeric_limits<std::size_t>::max() / n)
        throw InvalidInput("PointGrid::knn_nearby: k · queries overflows");
    check_buffer_size("PointGrid::knn_nearby", "slots", slots.size(), k * n);
    check_buffer_size("PointGrid::knn_nearby", "squared_distances", squared_distances.size(),
                      k * n);
    const std::size_t want = std::min(k, count_);
#if PF_GRID_AVX2
    const bool wide = has_avx2();
#else
    const bool wide = false;
#endif
    if (n == 0)
    {
        return;
    }
    if (want == 0 || want > max_k || !wide)
    {
        for (std::size_t i = 0; i < n; ++i)
        {
            found[i] = static_cast<std::uint32_t>(knn_nearby(queries[i], k, slots.subspan(i * k, k),
                                                             squared_distances.subspan(i * k, k)));
        }
        return;
    }
#if PF_GRID_AVX2
    // Each query gets Within's answer for the same passes as knn_nearby() (the octant block
    // with its reach, then the 3 × 3 × 3 block with its), only found faster (Selection), so the
    // answers are the same whatever the order of the queries and the guesses.
    // The lookups are kept from query to query: coherent queries come back to the same cells.
    constexpr std::size_t run = 32;
    std::array<Placement, run> places;
    std::array<bool, run> placed_ok{};
    const auto lookup = std::make_unique_for_overwrite<Lookup>(); // reset() sets what is read
    lookup->reset(id_);
    for (std::size_t start = 0; start < n;)
    {
        const std::size_t end = std::min(n, start + run);
        for (std::size_t i = start; i < end; ++i)
        {
            placed_ok[i - start] = placed(queries[i], places[i - start]);
        }
        for (std::size_t i = start; i < end; ++i)
        {
            found[i] = placed_ok[i - start]
                           ? static_cast<std::uint32_t>(wide_nearby(
                                 queries[i], places[i - start], k, *lookup, slots.data() + i * k,
                                 squared_distances.data() + i * k))
                           : 0;
        }
        start = end;
    }
#endif
}

void PointGrid::squared_distances(const Vec3f& query, std::span<const std::uint32_t> slots,
                                  std::span<float> squared_distances) const
{
    check_buffer_size("PointGrid::squared_distances", "squared_distances", squared_distances.size(),
                      slots.size());
    for (std::size_t i = 0; i < slots.size(); ++i)
    {
        const std::uint32_t s = slots[i];
        squared_distances[i] = detail::unfused_squared_distance(xs_[s], ys_[s], zs_[s], query.x(),
                                                                query.y(), query.z());
    }
}

std::size_t PointGrid::knn_far(const Vec3f& query, std::size_t k, std::span<std::uint32_t> slots,
                               std::span<float> squared_distances, float bound2) const
{
    k = std::min(k, count_);
    check_buffer_size("PointGrid::knn_far", "slots", slots.size(), k);
    check_buffer_size("PointGrid::knn_far", "squared_distances", squared_distances.size(), k);
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
    const std::size_t found = fallback_->knn(query, k, bound2, index, d2);
    for (std::size_t i = 0; i < found; ++i)
    {
        slots[i] = slot_of_[index[i]];
        squared_distances[i] = d2[i];
    }
    return found;
}

} // namespace pointform
