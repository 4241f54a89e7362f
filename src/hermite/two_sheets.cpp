// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "two_sheets.h"

#include "pointform/core/disjoint_sets.h"
#include "pointform/core/parallel.h"

#include "orientation_detail.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace pointform::detail {
namespace {

/// Samples (consecutive in index order) whose offsets are pooled: at least this many lie behind
/// each sample's kurtosis (its own block's and its neighbours' blocks').
constexpr std::size_t pooled_block = 512;
/// The kurtosis of the pooled offsets up to which a sample lies in two bands for certain.
/// Measured (`pointform sample`, 100k samples, noise 0.2% of the diagonal, 8 holes; pooled over
/// blocks of 512): 2.66-3.2 at the 0.1st percentile on noisy spheres, cones, CAD-like parts and
/// plates 0.04 and 0.05 thick, 2.8-3.0 on simulated scans of CAD parts, 2.84 on the shipped
/// LiDAR tile and 2.44 on the PCL stereo scene of a mug (its depths come in layers); 1.77-2.33
/// (0.1st to 99.9th) on a plate 0.02 thick (faces 3.5 deviations apart), median 2.06 at 0.03
/// (5 deviations). A normal distribution scores 3, two bands d deviations apart
/// (3 + 3 d²/2 + d⁴/16) / (1 + d²/4)²: 1.87 at d = 3.5.
constexpr float certain_kurtosis = 2.2F;
/// Samples connected through the neighbour table to such samples lie in the same two bands up
/// to this kurtosis (where the bands part, at a thin plate's rims and holes, the test is weaker):
/// the plate 0.03 thick, Chamfer 0.274% of the diagonal (only the certain ones) -> 0.16.
constexpr float likely_kurtosis = 2.5F;
/// A region is oriented by its bands when this many of its samples are certain.
constexpr std::size_t min_certain = 64;
/// A region is undecided when its normals facing away from its mid-surface outnumber those facing
/// towards it, or the other way round, by less than this share of its samples: where
/// orientation gave both faces of a thin part one sign, the two counts are the faces' (0.000 to
/// 0.002 of the samples apart on the plates 0.02 and 0.03 thick); thin parts that orientation
/// got right (a teapot's lid, a cow's ears in simulated scans) score 0.72 to 0.86.
constexpr double undecided = 0.2;
/// An undecided region faces inwards (a slot) when its normals facing towards its mid-surface
/// outnumber those facing away by at least this share, and away (a thin solid) otherwise.
constexpr double leaning_in = 0.1;

/// A block of samples more than this share of which have a coordinate equal to a neighbour's
/// is quantized (a grid of depths or of stored integers), and its offsets come in layers that
/// are no faces: a sphere whose coordinates were rounded to 0.03 (about 1.5 sampling steps)
/// scored 2.07-2.69, and its normals turned.
constexpr double max_tied_share = 0.25;

/// Whether sample i has a coordinate exactly equal to one of its neighbours' (other than its own
/// place).
bool tied_coordinate(std::span<const Vec3f> positions, const KnnTable& neighbors, std::size_t i)
{
    const Vec3f& p = positions[i];
    for (const std::uint32_t j : neighbors.neighbors(i))
    {
        const Vec3f& q = positions[j];
        if (j != i && q != p && (q.x() == p.x() || q.y() == p.y() || q.z() == p.z()))
            return true;
    }
    return false;
}

/// Sums of the powers 1 to 4 of offsets, and their count.
struct Powers
{
    std::array<double, 4> sum{};
    double count = 0.0;

    void add(double r)
    {
        const double r2 = r * r;
        sum[0] += r;
        sum[1] += r2;
        sum[2] += r2 * r;
        sum[3] += r2 * r2;
        count += 1.0;
    }
    void add(const Powers& p)
    {
        for (std::size_t k = 0; k < 4; ++k)
            sum[k] += p.sum[k];
        count += p.count;
    }
    /// The kurtosis of the offsets about their mean (3 for a normal distribution, 1 for two
    /// equal spikes); infinite without a spread.
    [[nodiscard]] double kurtosis() const
    {
        if (count == 0.0)
            return std::numeric_limits<double>::infinity();
        const double m1 = sum[0] / count;
        const double s2 = sum[1] / count;
        const double s3 = sum[2] / count;
        const double s4 = sum[3] / count;
        const double m2 = s2 - m1 * m1;
        const double m4 = s4 - 4.0 * m1 * s3 + 6.0 * m1 * m1 * s2 - 3.0 * m1 * m1 * m1 * m1;
        return m2 > 0.0 ? m4 / (m2 * m2) : std::numeric_limits<double>::infinity();
    }
};

} // namespace

std::vector<std::int8_t> two_sheet_sides(std::span<const Vec3f> positions,
                                         const KnnTable& neighbors,
                                         std::span<const Vec3f> guide_normals,
                                         std::span<const float> offsets)
{
    const std::size_t n = guide_normals.size();
    std::vector<std::int8_t> sides(n, 0);
    if (n == 0 || offsets.size() != n || positions.size() != n || neighbors.k == 0 ||
        neighbors.rows() != n)
        return sides;
    const auto counts = [&](std::size_t i) {
        return usable(guide_normals[i]) && std::isfinite(offsets[i]);
    };
    const std::size_t blocks = (n + pooled_block - 1) / pooled_block;
    std::vector<Powers> block_sums(blocks);

    parallel_blocks(blocks, 16, [&](std::size_t begin, std::size_t end) {
        for (std::size_t b = begin; b < end; ++b)
        {
            Powers sum;
            std::size_t samples = 0;
            std::size_t tied = 0;
            for (std::size_t i = b * pooled_block; i < std::min(n, (b + 1) * pooled_block); ++i)
            {
                ++samples;
                tied += tied_coordinate(positions, neighbors, i) ? 1U : 0U;
                if (counts(i))
                    sum.add(static_cast<double>(offsets[i]));
            }
            // Quantized coordinates make layers that are no faces: the block says nothing.
            if (static_cast<double>(tied) <= max_tied_share * static_cast<double>(samples))
                block_sums[b] = sum;
        }
    });
    parallel_blocks(n, 4096, [&](std::size_t begin, std::size_t end) {
        std::vector<std::size_t> pooled;
        for (std::size_t i = begin; i < end; ++i)
        {
            if (!counts(i) || offsets[i] == 0.0F || block_sums[i / pooled_block].count == 0.0)
                continue;
            pooled.assign(1, i / pooled_block);
            for (const std::uint32_t j : neighbors.neighbors(i))
                if (std::find(pooled.begin(), pooled.end(), j / pooled_block) == pooled.end())
                    pooled.push_back(j / pooled_block);
            Powers sum;
            for (const std::size_t b : pooled)
                sum.add(block_sums[b]);
            const double kurtosis = sum.kurtosis();

            const std::int8_t strength = kurtosis <= static_cast<double>(certain_kurtosis)  ? 2
                                         : kurtosis <= static_cast<double>(likely_kurtosis) ? 1
                                                                                            : 0;
            sides[i] = static_cast<std::int8_t>(offsets[i] > 0.0F ? strength : -strength);
        }
    });
    return sides;
}

TwoSheetFacing face_two_sheet_regions(const KnnTable& neighbors,
                                      std::span<const Vec3f> guide_normals,
                                      std::span<const std::int8_t> sides, std::span<Vec3f> normals)
{
    TwoSheetFacing facing;
    const std::size_t n = sides.size();
    if (std::none_of(sides.begin(), sides.end(), [](std::int8_t s) { return std::abs(s) == 2; }))
        return facing;
    // Regions: the samples with a side, joined through the table. Per region (by its root):
    // samples, certain samples, and how many of their normals face away from the mid-surface
    // less how many face towards it.
    DisjointSets regions(n);
    for (std::size_t i = 0; i < n; ++i)
        if (sides[i] != 0)
            for (const std::uint32_t j : neighbors.neighbors(i))
                if (j != i && sides[j] != 0)
                    regions.unite(i, j);
    struct Tally
    {
        std::uint32_t samples = 0;
        std::uint32_t certain = 0;
        std::int32_t away = 0;
        std::int8_t turn = 0;
    };
    std::vector<Tally> tally(n);
    for (std::size_t i = 0; i < n; ++i)
    {
        if (sides[i] == 0)
            continue;
        Tally& t = tally[regions.find(i)];
        ++t.samples;
        t.certain += std::abs(sides[i]) == 2 ? 1U : 0U;
        const float along = normals[i].dot(guide_normals[i]) * static_cast<float>(sides[i]);
        t.away += along > 0.0F ? 1 : along < 0.0F ? -1 : 0;
    }
    for (Tally& t : tally)
    {
        const auto samples = static_cast<double>(t.samples);
        if (t.certain < min_certain || std::abs(static_cast<double>(t.away)) >= undecided * samples)
            continue;
        t.turn = static_cast<double>(t.away) < -leaning_in * samples ? -1 : 1;
        ++facing.faced;
    }
    for (std::size_t i = 0; i < n; ++i)
    {
        if (sides[i] == 0)
            continue;
        const std::int8_t turn = tally[regions.find(i)].turn;
        if (turn == 0)
            continue;
        const Vec3f wanted = guide_normals[i] * static_cast<float>(sides[i] > 0 ? turn : -turn);
        if (!(wanted.dot(normals[i]) > 0.0F))
        {
            normals[i] = wanted;
            ++facing.turned;
        }
    }
    return facing;
}

} // namespace pointform::detail
