// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include "pointform/hermite/orientation.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace pointform::detail {

/// Lowers `slot` to `value` where that is less, atomically: of the values that threads offer one
/// slot, the least stays, whichever thread offers it when (a result the same at any thread count).
template <class T>
void lower_atomically(T& slot, T value)
{
    std::atomic_ref<T> shared(slot);
    T seen = shared.load(std::memory_order_relaxed);
    while (value < seen && !shared.compare_exchange_weak(seen, value, std::memory_order_relaxed))
    {}
}

/// Whether a normal (unit, or zero where there is none) can be used.
[[nodiscard]] inline bool usable(const Vec3f& n)
{
    return n.squaredNorm() > 0.5F;
}

/// Guide normals (grow_guide()) and, for each sample, the band of heights along its guide that
/// its own sheet fills (set by orient_with_guide()). Moves, never copies: `normals` views either
/// `storage` or an array a caller lent to grow_guide().
struct Guide
{
    Guide() = default;
    Guide(Guide&&) noexcept = default;
    Guide& operator=(Guide&&) noexcept = default;
    Guide(const Guide&) = delete;
    Guide& operator=(const Guide&) = delete;
    ~Guide() = default;

    /// One a sample; empty for a clean cloud.
    std::span<Vec3f> normals;
    /// The normals' array, unless a caller lent one.
    std::vector<Vec3f> storage;
    /// The median height of each sample's neighbours along its guide, relative to the sample.
    std::vector<float> centre;
    /// How far from `centre` a point may lie and still be on the sample's sheet.
    std::vector<float> reach;
    /// The flatness (flatness() in orientation.cpp) of the neighbourhood the guide was taken from:
    /// 0 on a plane.
    std::vector<float> flatness;
    /// Where a sample's wider neighbourhood is two bands of heights along its guide (the faces of
    /// a thin part that noise joins), the band it lies in: +1 along its guide, -1 against it;
    /// else 0 (two_sheet_sides()).
    std::vector<std::int8_t> side;
    /// Each sample's height along its guide over the centroid of its widest neighbourhood (the
    /// guide's last ring), in units of that neighbourhood's spread (√ of its covariance's trace);
    /// freed once the sides are found.
    std::vector<float> offset;

    /// How well a plane fits sample i's neighbourhood: (1 - flatness)², 0 for an isotropic blob.
    [[nodiscard]] float confidence(std::size_t i) const
    {
        const float fit = std::max(0.0F, 1.0F - flatness[i]);
        return fit * fit;
    }

    /// Whether `to` lies off the band of `from`'s sheet (false without guides).
    [[nodiscard]] bool off_sheet(std::span<const Vec3f> positions, std::uint32_t from,
                                 std::uint32_t to) const
    {
        if (reach.empty())
            return false;
        const float height = (positions[to] - positions[from]).dot(normals[from]);
        return std::abs(height - centre[from]) > reach[from];
    }
    /// Whether sample i lies on its own sheet: within own_sheet_share of its band from the median
    /// height of its neighbours (true without a bound on the band).
    [[nodiscard]] bool on_own_sheet(std::uint32_t i) const
    {
        return std::abs(centre[i]) <= own_sheet_share * reach[i];
    }
    /// Whether the edge a–b of the neighbour table jumps between sheets: b lies off a's sheet and
    /// is one of a's neighbours or lies on its own sheet (on_own_sheet()), or the other way round.
    /// Such edges would pass the orientation of one face of a thin plate to the opposite face
    /// unchanged, since their guides are parallel. A sample pushed into the gap of a thin plate
    /// by noise lies on a sheet of its own neighbours, and is judged by the band of a sample
    /// across the gap even where it is not in that sample's row (its own row, which holds the
    /// sample across, may be widened by the far face); a noise outlier of one sheet, whose
    /// neighbours' median height lies far from it, is judged only where it is in the row.
    [[nodiscard]] bool jumps(std::span<const Vec3f> positions, const KnnTable& table,
                             std::uint32_t a, std::uint32_t b) const
    {
        return judged_jump(positions, table, a, b, true);
    }
    /// jumps() judged by the rows alone: b is one of a's neighbours and lies off a's sheet, or
    /// the other way round. What the vote of the neighbours (vote_normals()) leaves out: judged
    /// from both ends it left a noise-thick slab (faces 3.3 deviations apart, one sheet of
    /// samples) with more samples outvoted by too few neighbours, and the field through them
    /// with a handle that no cut found.
    [[nodiscard]] bool jumps_in_rows(std::span<const Vec3f> positions, const KnnTable& table,
                                     std::uint32_t a, std::uint32_t b) const
    {
        return judged_jump(positions, table, a, b, false);
    }

private:
    /// on_own_sheet()'s share of the band. Measured (`pointform reconstruct`, Chamfer in % of the
    /// diagonal): a plate 0.04 thick (100k samples, noise 0.2% of the diagonal: faces 7
    /// deviations apart; seed 5) 0.0671 at half the band and at the whole band (1.2065 judged
    /// by the rows alone); on the simulated scans of bench/peers, bracket scan 2 0.358 at half
    /// the band (as by the rows alone) and 0.430 at the whole band (3.1% and 4.2% of its area
    /// facing away), fin block scan 1 0.254 and 0.231 (0.334 by the rows alone).
    static constexpr float own_sheet_share = 0.5F;
    static constexpr std::size_t no_entry = ~std::size_t{0};
    /// jumps() (`own_sheets`) or jumps_in_rows().
    [[nodiscard]] bool judged_jump(std::span<const Vec3f> positions, const KnnTable& table,
                                   std::uint32_t a, std::uint32_t b, bool own_sheets) const
    {
        // The row is searched only where off the band, which is rare.
        const auto off = [&](std::uint32_t from, std::uint32_t to) {
            return off_sheet(positions, from, to) &&
                   ((own_sheets && on_own_sheet(to)) || entry(table, from, to) != no_entry);
        };
        return off(a, b) || off(b, a);
    }
    /// The table entry (row-major) of `to` in `from`'s row, or no_entry.
    [[nodiscard]] static std::size_t entry(const KnnTable& table, std::uint32_t from,
                                           std::uint32_t to)
    {
        const auto row = table.neighbors(from);
        for (std::size_t c = 0; c < row.size(); ++c)
            if (row[c] == to)
                return from * table.k + c;
        return no_entry;
    }
};

/// The guide's normals of a noisy cloud (the first step of orient_normals_mst() under the Hoppe
/// rule), from the positions and the neighbour table alone: so a caller can grow them before it
/// has the fine normals, and the two never take memory at once. Empty for a clean cloud, or when
/// `options` asks for no guide. The normals are written into `scratch` when it has a slot for
/// every sample (its contents are overwritten and it must outlive the guide), else into the
/// guide's own storage.
[[nodiscard]] Guide grow_guide(std::span<const Vec3f> positions, const KnnTable& neighbors,
                               const OrientationOptions& options, std::span<Vec3f> scratch = {});

/// orient_normals_mst() of a neighbour table already checked against the positions (every row
/// whole, every index below their count), as compute_surfels() has it: knn_batch() made it and
/// estimate_normals() checked each row it read. Skips the pass over the whole table that the
/// public function makes first (0.1 s at 10M samples).
[[nodiscard]] OrientedNormals orient_checked_table(std::span<const Vec3f> positions,
                                                   std::span<const Vec3f> fine_normals,
                                                   const KnnTable& neighbors,
                                                   const OrientationOptions& options);

/// orient_checked_table() along a guide that grow_guide() made from the same positions, table
/// and options (the same result).
[[nodiscard]] OrientedNormals orient_with_guide(std::span<const Vec3f> positions,
                                                std::span<const Vec3f> fine_normals,
                                                const KnnTable& neighbors,
                                                const OrientationOptions& options, Guide guide);

} // namespace pointform::detail
