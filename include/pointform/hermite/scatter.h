// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include "pointform/core/types.h"
#include "pointform/spatial/kd_tree.h"
#include "pointform/spatial/neighborhoods.h"

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

/// \brief off_surface_samples(): of a sample's nearest, the share taken as the surface's: those
/// nearest the plane of the share nearest their coordinate-wise median (the rest may be other
/// strays, or the far face of a thin part) ...
inline constexpr double off_surface_kept = 0.75;
/// ... a sample stands off that surface when it lies farther from that plane than this many
/// times the noise of the kept neighbours (their RMS distance from it, times 1.65: the RMS of the
/// three quarters of a normal sample nearest its mean is 0.61 of its deviation) ...
inline constexpr double off_surface_noise = 6.0;
/// ... and than this many times their spread along it (their RMS distance from their centroid
/// along one direction of the plane: about a sample spacing) ...
inline constexpr double off_surface_spacing = 2.0;
/// ... unless others of its nearest lie off that plane too (farther from it than
/// off_surface_beside times the noise, and than a quarter of the spread): at least
/// off_surface_face of them, on one plane with the sample (each within that distance of it).
/// A sample of a face at a crease, where its own face's samples are fewer than the other
/// face's (a face seen at a grazing angle), has its own face among its nearest, off the other
/// face's plane and on one with it; a stray among other strays has them off the plane but not
/// on one with it. One or two others off the plane say nothing (three points always lie on a
/// plane): such a sample is taken as off the surface, a stray beside one or two others, or a
/// sample of a face seen so sparsely that its own face's samples are one or two of its nearest
/// (on eleven simulated scans and a cube with strays, with the samples so found removed before
/// `reconstruct`, taking these too, where two others were
/// taken as its own face before, lowered Chamfer on 8: the cube with 5% strays 0.094 -> 0.075% of
/// the diagonal, Hausdorff 4.1 -> 1.3%, its handle gone; fandisk scan 2 0.913 -> 0.853; raised it
/// on 3: fandisk scan 1 0.158 -> 0.168).
inline constexpr std::size_t off_surface_face = 3;
inline constexpr double off_surface_beside = 3.0;
/// \brief Samples that stand off the surface by off_surface_samples()'s test but lie, with this
/// many of the nearest such samples, on one plane (their spread across it at most
/// off_surface_sheet times their least spread along it) are a sheet, not strays: the far face
/// of a thin part scanned from one side, sampled more sparsely than its near face.
inline constexpr std::size_t off_surface_sheet_neighbours = 8;
inline constexpr double off_surface_sheet = 0.1;
/// \brief Rounds of off_surface_samples() after the first: each tests again the samples whose
/// nearest hold samples found so far, with those left out of their nearest (strays among
/// strays, where three or more others in a row stand off the surface beside the sample, on one
/// plane with it, as its own face at a crease would).
inline constexpr std::size_t off_surface_rounds = 3;

/// \brief The samples that stand off the surface of their nearest (see off_surface_kept and what
/// follows it): a scanner's stray returns near a surface, where the reach of their nearest is
/// no longer than a surface sample's (ScatterTest and isolated_samples() find those farther
/// out). Such a sample's fit would raise a tent of the field over the surface. A sample of a
/// noisy surface stands off it by the noise, which the test measures; one on a crease or a
/// corner lies on its faces' planes; one of a thin part's face has its face among its nearest.
/// In parallel; ascending; the same whatever the thread count.
/// \param positions  N points
/// \param neighbors  their N-row table of nearest (the point itself may be among them, and is
///                   skipped), at least 8 others a row
/// \throw InvalidInput if the table does not fit the points
[[nodiscard]] std::vector<std::uint32_t> off_surface_samples(std::span<const Vec3f> positions,
                                                             const KnnTable& neighbors);

} // namespace pointform
