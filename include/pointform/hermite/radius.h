// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include "pointform/core/types.h"
#include "pointform/geometry/aabb.h"
#include "pointform/spatial/neighborhoods.h"

#include <filesystem>
#include <span>
#include <string>
#include <vector>

namespace pointform {

/// \brief The factor on the automatic influence radius (§4.1) of surfels made for their own sake
/// (compute_surfels(), `pointform normals`): the k-th neighbour's distance as it is.
inline constexpr double default_radius_scale = 1.0;

/// \brief The factor on the automatic influence radius (§4.1) of surfels that a field is built
/// from (surfels_from_samples(), surfels_from_mesh(); `mc`, `model`, `reconstruct`, `remesh`):
/// at 1 irregularly sampled scans keep pinholes between clusters; 1.5 closes those and leaves
/// real holes open.
inline constexpr double default_field_radius_scale = 1.5;

/// \brief Automatic influence radius (§4.1): for every point, the radius of the smallest ball
/// centred at it that holds its k nearest neighbours (the distance to the k-th), times `scale`.
/// \param neighbors  an N by k table with squared distances
/// \param scale      user factor, > 0; 1 closes gaps up to about one sampling step, larger values
///                   close larger holes in the field
/// \throw InvalidInput if scale is not positive and finite
[[nodiscard]] std::vector<float> influence_radii(const KnnTable& neighbors,
                                                 double scale = default_radius_scale);

/// \brief The smallest, the median and the largest of a set of radii.
struct RadiusSummary
{
    float min = 0.0F;
    /// The value at position N / 2 in ascending order (as std::nth_element leaves it).
    float median = 0.0F;
    float max = 0.0F;
};

/// \brief The smallest, median and largest of `radii`, in parallel passes over them (a radix
/// select: the values' counts by their leading bits, then the one bucket that holds the median),
/// the same whatever the thread count. Values are ordered as numbers, with -0 below +0.
/// \throw InvalidInput if radii is empty or holds a NaN
[[nodiscard]] RadiusSummary summarize_radii(std::span<const float> radii);

/// \brief Two samples hold together (isolated_samples()) when their gap is at most this many
/// times the shorter of their two reaches (a sample's reach: its distance to its own k-th
/// neighbour, the farthest of its row). Along a sampled surface the gap to a row's farthest
/// entry is one reach, and neighbouring reaches differ little: on the scans and shapes of
/// bench/peers and the shipped data (the bunny's range scans, alone and merged, the kitten, a
/// LiDAR crop, a stereo table scene, noisy CAD parts, a sphere with one half sampled 100 times
/// more sparsely than the other) no sample is isolated at this factor.
inline constexpr float isolation_factor = 2.0F;

/// \brief The samples that lie apart from the rest, alone or in a small group (a scanner's
/// stray returns): the groups of at most k samples (too few to hold a neighbourhood of their
/// own) that hold together (see isolation_factor) and hold to no other sample. The row of such
/// a sample reaches past its group, to the surface: its radius would be as large as the gap,
/// and its plane, fitted to a few samples, a surface that spans that gap. Every sample of such
/// a group has a reach longer than isolation_factor times the shortest reach in its row (its
/// link to a row entry past the group is broken although that gap is within its own reach), and
/// only rows of samples whose reach exceeds that factor times the least reach of all are read
/// (on a cloud sampled at random, most: at 10M samples the pass takes about a fiftieth of the
/// kNN queries' time). A group closer to the surface than that factor times its reaches is left
/// to the field's fits, as noise. Unless such groups are part of a sheet: the far face of a thin
/// part scanned from one side, sampled 100 times more sparsely than the near face 0.1 away, has
/// rows full of the near face's samples, which its samples' links cannot reach. The samples of
/// all such groups hold together when their gap is at most isolation_factor times the shorter
/// of their spacings among themselves (the distance to the seventh nearest of them), and those
/// in a whole of more than 128 are a sheet, not strays (stray groups apart from each other make
/// wholes of a few groups at most). In parallel; ascending; the same whatever the thread count.
/// \param positions  N points
/// \param neighbors  their N by k + 1 table (with each point's own index, as knn_batch() of the
///                   points themselves gives it) and its farthest squared distances
/// \throw InvalidInput if the table does not fit the points
[[nodiscard]] std::vector<std::uint32_t> isolated_samples(std::span<const Vec3f> positions,
                                                          const KnnTable& neighbors);

/// \brief A user region that sets the influence radius of the samples inside it (§4.1,
/// interactive). Coordinates are world coordinates in the input's units.
struct RadiusRegion
{
    enum class Kind
    {
        Ball,
        Box,
    };
    Kind kind = Kind::Ball;
    Vec3d center = Vec3d::Zero(); ///< Ball
    double ball_radius = 0.0;     ///< Ball
    Aabb box;                     ///< Box
    /// The radius to set, in world units; used when `scale` is 0.
    double radius = 0.0;
    /// If > 0, multiplies the automatic radius instead of setting an absolute one.
    double scale = 0.0;

    [[nodiscard]] bool contains(const Vec3d& p) const;
};

/// \brief Reads regions from JSON:
/// `{"regions": [{"ball": {"center": [x,y,z], "radius": R}, "set": r},
///               {"box": {"min": [x,y,z], "max": [x,y,z]}, "scale": s}]}`.
/// Each region has "set" (absolute radius) or "scale" (factor on the automatic radius).
/// Later regions override earlier ones where they overlap.
/// \throw IoError naming the file and what is wrong (syntax with line and column, a missing
///        key, a negative or non-finite value)
[[nodiscard]] std::vector<RadiusRegion> read_radius_regions(const std::filesystem::path& path);

/// \brief Parses the same JSON from a string; `source` names it in error messages.
[[nodiscard]] std::vector<RadiusRegion> parse_radius_regions(const std::string& json,
                                                             const std::filesystem::path& source);

/// \brief Applies regions to radii: every sample inside a region gets the region's radius.
/// \param positions  N points, relative to `origin`
/// \param radii      N automatic radii
/// \return the new radii
[[nodiscard]] std::vector<float> apply_radius_regions(std::span<const Vec3f> positions,
                                                      const Vec3d& origin, std::vector<float> radii,
                                                      std::span<const RadiusRegion> regions);

} // namespace pointform
