// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/spatial/spatial_sort.h"

#include "pointform/core/error.h"
#include "pointform/core/parallel.h"
#include "pointform/geometry/aabb.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

namespace pointform {
namespace {

/// Spreads the low 21 bits of x so that there are two zero bits between each.
std::uint64_t spread_bits(std::uint64_t x)
{
    x &= 0x1FFFFFU;
    x = (x | x << 32U) & 0x1F00000000FFFFULL;
    x = (x | x << 16U) & 0x1F0000FF0000FFULL;
    x = (x | x << 8U) & 0x100F00F00F00F00FULL;
    x = (x | x << 4U) & 0x10C30C30C30C30C3ULL;
    x = (x | x << 2U) & 0x1249249249249249ULL;
    return x;
}

/// bounding_box(positions), its minima and maxima taken by blocks at once (the same, as min and
/// max do not depend on the order); serially when a coordinate is not finite, where they might.
Aabb parallel_bounding_box(std::span<const Vec3f> positions)
{
    constexpr std::size_t block = 1U << 16U;
    const std::size_t blocks = (positions.size() + block - 1) / block;
    if (blocks <= 1)
        return bounding_box(positions);
    std::vector<std::pair<Eigen::Vector3f, Eigen::Vector3f>> ranges(blocks);
    std::vector<std::uint8_t> finite(blocks, 1);
    parallel_blocks(positions.size(), block, [&](std::size_t begin, std::size_t end) {
        Eigen::Vector3f lo = positions[begin];
        Eigen::Vector3f hi = positions[begin];
        bool all_finite = true;
        for (std::size_t i = begin; i < end; ++i)
        {
            lo = lo.cwiseMin(positions[i]);
            hi = hi.cwiseMax(positions[i]);
            all_finite = all_finite && positions[i].allFinite();
        }
        ranges[begin / block] = {lo, hi};
        finite[begin / block] = all_finite ? 1 : 0;
    });
    if (std::find(finite.begin(), finite.end(), 0) != finite.end())
        return bounding_box(positions);
    Eigen::Vector3f lo = ranges[0].first;
    Eigen::Vector3f hi = ranges[0].second;
    for (const auto& [block_lo, block_hi] : ranges)
    {
        lo = lo.cwiseMin(block_lo);
        hi = hi.cwiseMax(block_hi);
    }
    Aabb box;
    box.min = Vec3d::Zero() + lo.cast<double>();
    box.max = Vec3d::Zero() + hi.cast<double>();
    return box;
}

/// A Morton key and the index it was made for. No default member initialisers: arrays of them are
/// filled by the passes that follow, not zeroed first by one thread.
struct Keyed
{
    std::uint64_t key;
    std::uint32_t index;

    friend bool operator<(const Keyed& a, const Keyed& b)
    {
        return a.key != b.key ? a.key < b.key : a.index < b.index;
    }
};

/// Bits of the key that each counting pass of bucket_sort() takes.
constexpr unsigned radix_bits = 12;
constexpr std::size_t radix = std::size_t{1} << radix_bits;
/// Runs shorter than this are sorted by comparison rather than counted.
constexpr std::size_t min_counted = 256;

/// A thread's buffers for sort_run(), reused from run to run.
struct RunScratch
{
    std::vector<Keyed> keys;
    std::vector<std::uint32_t> start; ///< each part's first place, then its end
    std::vector<std::uint32_t> next;  ///< each part's next free place
};

/// Sorts run by key, then index, as std::sort would: by the radix_bits of the key below
/// `shift` + radix_bits (those above are the same throughout the run) into scratch, then each
/// part sorted by comparison and moved back. On a surface a part holds a few dozen keys, and
/// the run is in cache: two passes over it and short sorts instead of log n passes.
void sort_run(std::span<Keyed> run, unsigned shift, RunScratch& scratch)
{
    if (run.size() < min_counted)
    {
        std::sort(run.begin(), run.end());
        return;
    }
    std::vector<std::uint32_t>& counts = scratch.start;
    counts.assign(radix + 1, 0);
    for (const Keyed& k : run)
        ++counts[((k.key >> shift) & (radix - 1)) + 1];
    for (std::size_t b = 0; b < radix; ++b)
        counts[b + 1] += counts[b];
    scratch.keys.resize(run.size());
    scratch.next.assign(counts.begin(), counts.end() - 1);
    for (const Keyed& k : run)
        scratch.keys[scratch.next[(k.key >> shift) & (radix - 1)]++] = k;
    for (std::size_t b = 0; b < radix; ++b)
        if (counts[b + 1] - counts[b] > 1)
            std::sort(scratch.keys.begin() + counts[b], scratch.keys.begin() + counts[b + 1]);
    std::copy(scratch.keys.begin(), scratch.keys.begin() + static_cast<std::ptrdiff_t>(run.size()),
              run.begin());
}

/// Sorts keys below 2^63 as std::sort would: a stable scatter by the top radix_bits bits of the
/// key, block by block (each block's counts, then every bucket's place for every block), then
/// each bucket by its next radix_bits bits (sort_run()), all in parallel. The buckets of a
/// surface's Morton keys hold a few thousand to some tens of thousands of samples each, so
/// their sorts run in cache; a sort by comparison of the whole array would pass over it log n
/// times.
std::unique_ptr<Keyed[]> bucket_sort(std::unique_ptr<Keyed[]> keyed, std::size_t n)
{
    constexpr unsigned shift = 63 - radix_bits;
    constexpr std::size_t block = std::size_t{1} << 18;
    const std::size_t blocks = (n + block - 1) / block;
    if (blocks <= 1)
    {
        std::sort(keyed.get(), keyed.get() + n);
        return keyed;
    }
    std::vector<std::size_t> place(blocks * radix, 0); // block-major counts, then offsets
    parallel_blocks(n, block, [&](std::size_t begin, std::size_t end) {
        std::size_t* counts = place.data() + (begin / block) * radix;
        for (std::size_t i = begin; i < end; ++i)
            ++counts[keyed[i].key >> shift];
    });
    std::vector<std::size_t> bucket_start(radix + 1, 0);
    for (std::size_t b = 0, total = 0; b < radix; ++b)
    {
        bucket_start[b] = total;
        for (std::size_t k = 0; k < blocks; ++k)
        {
            const std::size_t count = place[k * radix + b];
            place[k * radix + b] = total;
            total += count;
        }
        bucket_start[b + 1] = total;
    }
    // NOLINTNEXTLINE(cppcoreguidelines-owning-memory): not initialised, every entry is written
    std::unique_ptr<Keyed[]> scattered(new Keyed[n]);
    parallel_blocks(n, block, [&](std::size_t begin, std::size_t end) {
        std::size_t* next = place.data() + (begin / block) * radix;
        for (std::size_t i = begin; i < end; ++i)
            scattered[next[keyed[i].key >> shift]++] = keyed[i];
    });
    keyed.reset();
    // Sixteen buckets a block, sharing one set of buffers.
    parallel_blocks(radix, 16, [&](std::size_t first, std::size_t last) {
        RunScratch scratch;
        for (std::size_t b = first; b < last; ++b)
            sort_run({scattered.get() + bucket_start[b], bucket_start[b + 1] - bucket_start[b]},
                     shift - radix_bits, scratch);
    });
    return scattered;
}

/// The Morton key of each point, on a grid of 2^21 cells an axis over
/// the points' bounding box, passed to `use(i, key)` in parallel.
template <typename Use>
void for_each_key(std::span<const Vec3f> positions, const Use& use)
{
    const Aabb box = parallel_bounding_box(positions);
    const double scale = morton_scale(box.size());
    parallel_blocks(positions.size(), 16384, [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i)
            use(i, morton_key(positions[i], box.min, scale));
    });
}

/// Runs of more equal keys than this whose points do not all lie at one place are ordered again
/// by keys over their own box (refine_run()).
constexpr std::size_t refine_above = 16;

/// Calls `use(begin, end)` for every run of more than `above` equal keys of `sorted` that
/// starts in [from, to) (it may end past `to`).
template <typename Use>
void for_each_run(std::span<const Keyed> sorted, std::size_t from, std::size_t to,
                  std::size_t above, const Use& use)
{
    std::size_t begin = from;
    while (begin < to && begin > 0 && sorted[begin].key == sorted[begin - 1].key)
        ++begin;
    while (begin < to)
    {
        std::size_t end = begin + 1;
        while (end < sorted.size() && sorted[end].key == sorted[begin].key)
            ++end;
        if (end - begin > above)
            use(begin, end);
        begin = end;
    }
}

/// Orders a run of points that share a key (a grid cell) by their keys over their own bounding
/// box (order_in_own_box()), and so on inside those keys' own runs: where a far outlier made the
/// grid's cells large, points close in space are close in the order again. Each round shrinks the
/// box by at least 2^21, so float's range allows about a dozen.
void refine_run(std::span<const Vec3f> positions, std::span<Keyed> run)
{
    std::vector<std::uint32_t> indices(run.size());
    std::vector<std::uint64_t> keys(run.size());
    for (std::size_t j = 0; j < run.size(); ++j)
        indices[j] = run[j].index;
    if (!order_in_own_box(positions, indices, keys))
        return;
    for (std::size_t j = 0; j < run.size(); ++j)
        run[j] = {keys[j], indices[j]};
    for_each_run(run, 0, run.size(), refine_above, [&](std::size_t begin, std::size_t end) {
        refine_run(positions, run.subspan(begin, end - begin));
    });
}

/// refine_run() on every run of `runs` (ranges of equal keys of `sorted`) of more than
/// refine_above, in parallel. The keys of those runs are overwritten (only the order is kept).
void refine_cells(std::span<const Vec3f> positions, std::span<Keyed> sorted,
                  std::span<const std::pair<std::size_t, std::size_t>> runs)
{
    parallel_blocks(runs.size(), 1, [&](std::size_t first, std::size_t last) {
        for (std::size_t r = first; r < last; ++r)
            if (runs[r].second - runs[r].first > refine_above)
                refine_run(positions,
                           sorted.subspan(runs[r].first, runs[r].second - runs[r].first));
    });
}

} // namespace

double morton_scale(const Vec3d& extent)
{
    const double largest = std::max({extent.x(), extent.y(), extent.z()});
    return largest > 0.0 ? static_cast<double>((1U << 21U) - 1U) / largest : 0.0;
}

std::uint64_t morton_key(const Vec3f& point, const Vec3d& low, double scale)
{
    const Vec3d q = (point.cast<double>() - low) * scale;
    // Non-finite coordinates (rejected elsewhere) must not poison the casts.
    const auto cell = [](double v) {
        return std::isfinite(v)
                   ? static_cast<std::uint64_t>(std::clamp(v, 0.0, static_cast<double>(0x1FFFFF)))
                   : std::uint64_t{0};
    };
    return spread_bits(cell(q.x())) | spread_bits(cell(q.y())) << 1U |
           spread_bits(cell(q.z())) << 2U;
}

bool order_in_own_box(std::span<const Vec3f> positions, std::span<std::uint32_t> indices,
                      std::span<std::uint64_t> keys)
{
    if (indices.empty())
        return false;
    Vec3f low = positions[indices[0]];
    Vec3f high = low;
    for (const std::uint32_t i : indices)
    {
        low = low.cwiseMin(positions[i]);
        high = high.cwiseMax(positions[i]);
    }
    if (!(low != high) || !low.allFinite() || !high.allFinite())
        return false;
    const Vec3d corner = low.cast<double>();
    const double scale = morton_scale(high.cast<double>() - corner);
    std::vector<std::pair<std::uint64_t, std::uint32_t>> keyed(indices.size());
    for (std::size_t j = 0; j < indices.size(); ++j)
        keyed[j] = {morton_key(positions[indices[j]], corner, scale), indices[j]};
    std::sort(keyed.begin(), keyed.end());
    for (std::size_t j = 0; j < indices.size(); ++j)
        std::tie(keys[j], indices[j]) = keyed[j];
    return true;
}

void morton_keys(std::span<const Vec3f> positions, std::span<std::uint64_t> keys)
{
    if (keys.size() != positions.size())
        throw InvalidInput("morton_keys: " + std::to_string(positions.size()) + " points but " +
                           std::to_string(keys.size()) + " keys");
    for_each_key(positions, [&](std::size_t i, std::uint64_t key) { keys[i] = key; });
}

namespace {

/// The runs of two or more equal keys of `sorted`, as [begin, end) ranges, in order.
std::vector<std::pair<std::size_t, std::size_t>> shared_key_runs(std::span<const Keyed> sorted)
{
    return parallel_collect<std::pair<std::size_t, std::size_t>>(
        sorted.size(), std::size_t{1} << 18U,
        [&](std::size_t first, std::size_t last,
            std::vector<std::pair<std::size_t, std::size_t>>& out) {
            for_each_run(sorted, first, last, 1,
                         [&](std::size_t begin, std::size_t end) { out.emplace_back(begin, end); });
        });
}

/// The copies among the points of the runs (each a range of `sorted`, whatever order the
/// refinement left inside it): the points of a run ordered by their coordinates, ties by index.
std::vector<CoincidentCopy> copies_in_runs(
    std::span<const Vec3f> positions, std::span<const Keyed> sorted,
    std::span<const std::pair<std::size_t, std::size_t>> runs)
{
    std::vector<CoincidentCopy> copies = parallel_collect<CoincidentCopy>(
        runs.size(), 64,
        [&](std::size_t first, std::size_t last, std::vector<CoincidentCopy>& out) {
            std::vector<std::uint32_t> members;
            for (std::size_t r = first; r < last; ++r)
            {
                members.clear();
                for (std::size_t j = runs[r].first; j < runs[r].second; ++j)
                    members.push_back(sorted[j].index);
                std::sort(members.begin(), members.end(), [&](std::uint32_t a, std::uint32_t b) {
                    const Vec3f& p = positions[a];
                    const Vec3f& q = positions[b];
                    return std::tie(p.x(), p.y(), p.z(), a) < std::tie(q.x(), q.y(), q.z(), b);
                });
                std::size_t group = 0;
                for (std::size_t m = 1; m < members.size(); ++m)
                {
                    if (positions[members[m]] != positions[members[group]])
                        group = m;
                    else
                        out.push_back({.copy = members[m], .original = members[group]});
                }
            }
        });
    std::sort(copies.begin(), copies.end(),
              [](const CoincidentCopy& a, const CoincidentCopy& b) { return a.copy < b.copy; });
    return copies;
}

std::vector<std::uint32_t> order_points(std::span<const Vec3f> positions,
                                        std::vector<CoincidentCopy>* copies)
{
    // (Morton key, index) pairs: sorting them orders by key, ties by original index.
    const std::size_t n = positions.size();
    std::vector<std::uint32_t> order(n);
    if (copies != nullptr)
        copies->clear();
    if (n == 0)
        return order;
    // NOLINTNEXTLINE(cppcoreguidelines-owning-memory): not initialised, every entry is written
    std::unique_ptr<Keyed[]> keyed(new Keyed[n]);
    for_each_key(positions, [&](std::size_t i, std::uint64_t key) {
        keyed[i] = {key, static_cast<std::uint32_t>(i)};
    });
    keyed = bucket_sort(std::move(keyed), n); // keys paired with their index: a strict order
    // The runs of equal keys: the crowded ones are ordered again (refine_cells(), only inside
    // each run), and points at one place share a key, so only runs can hold copies.
    const std::vector<std::pair<std::size_t, std::size_t>> runs = shared_key_runs({keyed.get(), n});
    refine_cells(positions, {keyed.get(), n}, runs);
    if (copies != nullptr && !runs.empty())
        *copies = copies_in_runs(positions, {keyed.get(), n}, runs);
    parallel_blocks(n, 1U << 16U, [&](std::size_t begin, std::size_t end) {
        for (std::size_t j = begin; j < end; ++j)
            order[j] = keyed[j].index;
    });
    return order;
}

} // namespace

std::vector<std::uint32_t> spatial_order(std::span<const Vec3f> positions)
{
    return order_points(positions, nullptr);
}

std::vector<std::uint32_t> spatial_order(std::span<const Vec3f> positions,
                                         std::vector<CoincidentCopy>& copies)
{
    return order_points(positions, &copies);
}

} // namespace pointform
