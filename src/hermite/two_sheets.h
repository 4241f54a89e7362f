// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include "pointform/core/types.h"
#include "pointform/spatial/neighborhoods.h"

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace pointform::detail {

/// The two faces of a thin part whose gap noise fills (faces a few noise deviations apart): no
/// test of a sample's position against its neighbours' band tells one face's samples from the
/// other's, and orientation along the guides, which are parallel across the gap, hands both
/// faces one sign: the field through them is one sheet in the middle, half of it facing away
/// from the nearer face. Across a wider neighbourhood the heights of such a part along the guide
/// are two bands, not one: this finds where, and which band each sample lies in.
///
/// `offsets` are the samples' heights along their guides over the centroids of their widest
/// guide neighbourhoods (Guide::offset), which lie between the faces of such a part: two bands
/// of offsets there, one band elsewhere. Their kurtosis (3 for one normal band, under 2 for two
/// bands more than 3 deviations apart) is taken over the offsets of the sample's block of
/// consecutive samples and of its neighbours' blocks (spatially sorted samples, as
/// compute_surfels() has them, make compact blocks; unsorted ones pool the whole cloud, which
/// finds only a cloud that is all thin part). Blocks of quantized coordinates (many samples share
/// a coordinate with a neighbour), whose layers are no faces, are left out. Where it is low, the
/// sample's side is its offset's sign: ±2 (kurtosis low enough to be certain) or ±1 (likely, next
/// to certain ones), + along its guide; elsewhere 0. The guide normals are unoriented lines (zero
/// where unusable).
[[nodiscard]] std::vector<std::int8_t> two_sheet_sides(std::span<const Vec3f> positions,
                                                       const KnnTable& neighbors,
                                                       std::span<const Vec3f> guide_normals,
                                                       std::span<const float> offsets);

/// The side (sign and strength) that ball_sides() gives a sample.
constexpr std::int8_t ball_side = 3;

/// The faces of a thin part a few noise deviations apart, seen from balls: each ball_stride-th
/// sample (in index order) and its ball_samples nearest samples, Euclidean, which reach across the
/// gap where a neighbourhood grown through the table keeps to its centre's face. Where the heights
/// of a ball's samples along its least axis dip (their histogram has a hole in the middle, which
/// one sheet's heights, curved or creased, do not) and most of the balls about it dip too, each
/// sample in it whose guide lies along that axis takes the band it lies in, from the dipping ball
/// whose centre is nearest: ±ball_side, + along its guide. The sides from two_sheet_sides() it
/// overrides. Beside such balls, balls whose heights dip only shallowly but surely (many samples)
/// count too. Where a counted ball's faces are so close that the noise turned the guides of
/// some of its samples across the axis at random (not a rim's), those guides become the axis and
/// the samples take their band too. On a plate 6 deviations thick (100k samples, noise 0.2% of
/// the diagonal, 8 holes), 83% of the balls count; they give 92% of the faces' samples a side,
/// 99.4% of them their own band's. Above ball_cloud samples the balls are found in an even
/// subsample, so that they are as wide at any size, and measured over all the samples in them.
void ball_sides(std::span<const Vec3f> positions, std::span<Vec3f> guide_normals,
                std::span<std::int8_t> sides);

/// TwoSheetFacing::faced_by's values.
constexpr std::uint8_t faced_by_kurtosis = 1;
constexpr std::uint8_t faced_by_ball = 2;

/// What face_two_sheet_regions() did.
struct TwoSheetFacing
{
    /// Regions whose normals were set by their sides.
    std::size_t faced = 0;
    /// Samples whose normal turned.
    std::size_t turned = 0;
    /// One a sample when a region was faced (else empty): where the sample's region was faced,
    /// faced_by_ball if its side came from a ball (ball_sides()), else faced_by_kurtosis; 0
    /// elsewhere.
    std::vector<std::uint8_t> faced_by;
};

/// Orients the two-sheet regions (samples with a side, connected through the neighbour table,
/// with enough certain ones, |side| at least 2) that orientation left undecided: where the
/// oriented normals of a region's samples agree with the direction away from its mid-surface (side
/// times guide) about as often as they disagree, each normal becomes that direction (the two faces
/// of a thin solid face away from each other; a region whose normals lean to facing inwards, a
/// narrow slot, faces inwards). Regions that orientation got right keep their normals, and the
/// sides' errors (samples that noise carried past the mid-surface) with them. `normals` are the
/// oriented guide normals.
TwoSheetFacing face_two_sheet_regions(const KnnTable& neighbors,
                                      std::span<const Vec3f> guide_normals,
                                      std::span<const std::int8_t> sides, std::span<Vec3f> normals);

} // namespace pointform::detail
