// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include "pointform/core/types.h"
#include "pointform/spatial/kd_tree.h"

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace pointform {

/// \brief The neighbourhood of the scattered-sample test: the sample and its 16 nearest.
inline constexpr std::size_t scatter_neighbourhood = 17;

/// \brief A sample is scattered when its reach (the distance to its 16th nearest other sample)
/// is more than this many times the cloud's median reach ...
inline constexpr double scattered_reach = 4.0;
/// ... and its neighbourhood (it and its 16 nearest) fills a volume rather than lying along a
/// sheet: its covariance's least eigenvalue more than this share of the largest (16 points
/// spread evenly through a ball score about 0.35, and 95% of such neighbourhoods above 0.17; a
/// sheet near 0, a sphere sampled by 100 points under 0.1). A spray of stray returns through
/// the space around a scan is scattered; a noisy surface sampled as densely as the rest is not,
/// nor is a sparse one whose samples lie on a sheet.
inline constexpr double scattered_volume = 0.15;

/// \brief ScatterTest::stray(): a sample farther than this many times its reach from the plane
/// of its 16 nearest is off their surface (a sample on a surface sampled as sparsely as its reach
/// is off it by about reach / (4 R), R the surface's radius of curvature).
inline constexpr double stray_offset = 0.5;
/// \brief ScatterTest::stray(): a sample whose reach is more than this many times the median
/// reach of its 16 nearest is isolated from them.
inline constexpr double stray_isolation = 4.0;

/// \brief The test of scattered samples over one cloud (scatter_test()).
struct ScatterTest
{
    /// The squared reach above which a sample may be scattered: scattered_reach times the
    /// median reach, squared (infinite for a cloud of fewer than 17 samples, or one whose median
    /// reach is 0: most samples copies of 16 others).
    float limit2 = 0.0F;

    /// \brief Whether sample `i` of `positions` (over which `tree` is built) is scattered:
    /// reach² above limit2 (from a search of `tree`) and a neighbourhood that fills a volume.
    [[nodiscard]] bool scattered(const KdTree& tree, std::span<const Vec3f> positions,
                                 std::size_t i) const;

    /// \brief Whether sample `i` is a stray: reach² above limit2, and a neighbourhood that
    /// fills a volume (scattered()), or a sample that stands off the surface of its 16 nearest
    /// (farther than stray_offset times its reach from their plane), or one isolated from them
    /// (a reach over stray_isolation times the median of theirs): a stray return near a surface,
    /// whose nearest samples are that surface's. A surface sampled sparsely but evenly is none
    /// of these.
    [[nodiscard]] bool stray(const KdTree& tree, std::span<const Vec3f> positions,
                             std::size_t i) const;
};

/// \brief The scattered-sample test of `positions` (over which `tree` is built): the median
/// reach is taken over every stride-th sample, at most 4,096 of them. Deterministic.
[[nodiscard]] ScatterTest scatter_test(const KdTree& tree, std::span<const Vec3f> positions);

/// \brief What find_strays() found (indices into the cloud, ascending).
struct Strays
{
    /// The strays: those ScatterTest::stray() finds, and every member of a spray.
    std::vector<std::uint32_t> samples;
    /// The members of sprays: groups (samples past the reach limit, joined to those of their 16
    /// nearest that are past it too) most of whose members are strays. A stray alone is a group
    /// of one; a stray among many samples past the limit that are not (a part sampled sparsely
    /// but evenly, where a few samples stand off its plane) is in none.
    std::vector<std::uint32_t> sprayed;
};

/// \brief The strays among `candidates` (ascending indices into `positions`, over which `tree`
/// is built; every sample whose reach may be over test.limit2). A surface sampled sparsely but
/// evenly, away from strays, has none. Deterministic whatever the thread count.
[[nodiscard]] Strays find_strays(const KdTree& tree, std::span<const Vec3f> positions,
                                 const ScatterTest& test,
                                 std::span<const std::uint32_t> candidates);

} // namespace pointform
