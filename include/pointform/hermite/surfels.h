// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include "pointform/core/progress.h"
#include "pointform/geometry/point_cloud.h"
#include "pointform/geometry/tri_mesh.h"
#include "pointform/hermite/normals.h"
#include "pointform/hermite/orientation.h"
#include "pointform/hermite/radius.h"
#include "pointform/metrics/surface_sampling.h"

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace pointform {

/// \brief How compute_surfels orients normals.
enum class OrientMode
{
    /// Towards the cloud's sensor where it is one view of a sensor (PointCloud::sensor: a depth
    /// image, whose every surface faced the sensor), else Mst (default)
    Auto,
    Mst,     ///< minimum-spanning-tree propagation, every component
    None,    ///< keep PCA's arbitrary signs
    Towards, ///< towards a viewpoint
    Along,   ///< along a direction
    Flip,    ///< MST, then reversed (inward normals)
};

/// \brief An orientation mode with its target (SurfelOptions::orient and orient_target).
struct OrientChoice
{
    OrientMode mode = OrientMode::Auto;
    /// Towards: the viewpoint; Along: the direction (not zero). World coordinates.
    Vec3d target = Vec3d::UnitZ();
};

/// \brief An orientation as the command line and the Python module spell it: "auto", "mst",
/// "none", "flip", "towards:X,Y,Z" (a viewpoint) or "along:X,Y,Z" (a direction).
/// \throw InvalidInput for another word, a missing, extra or non-finite number, or a zero
/// direction, saying what was expected
[[nodiscard]] OrientChoice parse_orient(std::string_view text);

/// \brief Options for compute_surfels: Level 1 → Level 2 (§4).
struct SurfelOptions
{
    /// Neighbours of each point, besides itself, for PCA and the automatic radius (as CGAL counts
    /// them; Open3D's KNN(k) counts the point itself).
    std::size_t k = default_neighbors;
    /// Neighbours a point in the orientation graph; 0 = min(k, 10).
    std::size_t graph_k = 0;
    /// Orientation mode and its parameters.
    OrientMode orient = OrientMode::Auto;
    /// Towards: the viewpoint; Along: the direction. World coordinates.
    Vec3d orient_target = Vec3d::UnitZ();
    /// Orientation propagation rule (MST modes).
    OrientationRule rule = OrientationRule::Hoppe;
    /// Factor on the automatic influence radius (§4.1), > 0.
    double radius_scale = default_radius_scale;
    /// User regions that set the radius (§4.1, interactive), applied after the automatic one.
    std::vector<RadiusRegion> radius_regions;
    /// In a clean cloud, refit each oriented normal at a crease to the sample's own face
    /// (detail::refit_crease_normals()) instead of keeping the principal component normal, a
    /// blend of the faces' there. Off by default (README, `normals --sharp-creases`).
    bool sharp_creases = false;
    /// Find the samples that stand off the surface of their nearest (off_surface_samples(): a
    /// scanner's stray returns near a surface) and leave them out of every other sample's
    /// neighbourhood, so that they tilt no normal, link no orientation and shorten no radius.
    /// They keep surfels of their own, from their own nearest, and are listed in
    /// SurfelResult::off_surface. Off by default (every sample's normal as its nearest give it);
    /// surfels_from_samples() sets it and leaves them out.
    bool off_surface = false;
    /// Optional progress report.
    ProgressCallback progress;
};

/// \brief The surfels and a report of how they were made.
struct SurfelResult
{
    /// The input points (same order, same origin) with oriented unit normals and radii.
    PointCloud surfels;
    /// Orientation outcome (components, flipped, unoriented samples); its `normals` are left
    /// empty (they are the surfels').
    OrientedNormals orientation;
    /// Normals refitted to their own face at a crease of a clean cloud (SurfelOptions::
    /// sharp_creases).
    std::size_t crease_refits = 0;
    /// The normals were turned to face the cloud's sensor (OrientMode::Auto and
    /// PointCloud::sensor), not oriented by MST.
    bool towards_sensor = false;
    /// Samples whose neighbourhood was coincident or collinear (normal taken from a neighbour).
    std::size_t degenerate = 0;
    /// The smallest, median and largest of the surfels' radii.
    RadiusSummary radius;
    /// The samples that lie alone far from the rest (isolated_samples()), ascending input
    /// indices: their surfels are kept here; surfels_from_samples() leaves them out.
    std::vector<std::uint32_t> isolated;
    /// With SurfelOptions::off_surface, the samples that stand off the surface of their nearest
    /// (off_surface_samples()), ascending input indices; their surfels are kept here, and
    /// surfels_from_samples() leaves them out.
    std::vector<std::uint32_t> off_surface;
    /// The samples at the very place of an earlier one (spatial_order()), ascending input
    /// indices: the surfels are computed once a place, and each copy has its original's normal
    /// and radius; surfels_from_samples() leaves the copies out.
    std::vector<std::uint32_t> copies;
    /// Wall-clock seconds by stage, in order: "check", "spatial sort" (with the copies), "kd-tree",
    /// "knn", "off surface" (with SurfelOptions::off_surface), "normals", "orientation", "creases"
    /// (with SurfelOptions::sharp_creases), "radius", "output order" (back to the input's order).
    std::vector<std::pair<std::string, double>> stage_seconds;
};

/// \brief Checks that points can carry surfels: more than `k` points (k ≥ 3), all finite, not all
/// coincident and not all on one line.
/// \throw InvalidInput saying which condition fails
void check_surfel_input(const PointCloudView& cloud, std::size_t k);

/// \brief Level 1 → 2 (§4): k nearest neighbours, PCA normals, consistent orientation and
/// influence radii, for every sample, in parallel where it pays.
/// \throw InvalidInput as check_surfel_input, or for non-positive radius_scale
[[nodiscard]] SurfelResult compute_surfels(const PointCloudView& cloud,
                                           const SurfelOptions& options = {});

/// \brief compute_surfels() of a cloud the caller no longer needs: its positions and colours
/// move into the result instead of being copied, and `cloud` is left empty. If it throws,
/// `cloud` is unchanged.
[[nodiscard]] SurfelResult compute_surfels(PointCloud&& cloud, const SurfelOptions& options = {});

/// \brief Options of surfels_from_samples(): samples of any kind to the surfels of a field.
struct SurfelsFromSamplesOptions
{
    /// Neighbours of each sample, besides itself, for normals and the automatic radius, ≥ 3.
    std::size_t k = default_neighbors;
    /// Factor on the automatic influence radius (distance to the k-th neighbour), > 0; applies
    /// to the radii computed here, not to radii the samples carry.
    double radius_scale = default_field_radius_scale;
    /// User regions that set the computed radii (§4.1), applied after the automatic one.
    std::vector<RadiusRegion> radius_regions;
    /// Estimate and orient normals even if the samples have them.
    bool reestimate = false;
    /// How estimated normals are oriented, and the viewpoint or direction
    /// (SurfelOptions::orient, orient_target); normals the samples carry keep their signs.
    OrientMode orient = OrientMode::Auto;
    Vec3d orient_target = Vec3d::UnitZ();
    /// Estimated normals at a clean cloud's creases refitted to their own face
    /// (SurfelOptions::sharp_creases).
    bool sharp_creases = false;
    /// Keep the samples that stand off the surface of their nearest (off_surface_samples()),
    /// which are otherwise left out: for a cloud whose faces seen at a grazing angle hold a few
    /// samples each beside a densely sampled face, and no stray returns.
    bool keep_off_surface = false;
    ProgressCallback progress;
};

/// \brief The surfels of surfels_from_samples() and what was done to make them.
struct SurfelsFromSamples
{
    /// Oriented unit normals and radii; the samples without a usable normal left out.
    PointCloud surfels;
    /// Normals were estimated and oriented here (the samples had none, or reestimate).
    bool estimated_normals = false;
    /// Radii were computed here (normals estimated, or the samples had no radius).
    bool estimated_radii = false;
    /// When normals were estimated: the orientation's components and flipped normals
    /// (OrientedNormals), and the samples whose neighbourhood was degenerate.
    std::size_t components = 0;
    std::size_t flipped = 0;
    std::size_t degenerate = 0;
    /// OrientedNormals::thin_parts and thin_part_turned.
    std::size_t thin_parts = 0;
    std::size_t thin_part_turned = 0;
    /// Normals refitted at creases (SurfelsFromSamplesOptions::sharp_creases).
    std::size_t crease_refits = 0;
    /// The estimated normals face the samples' sensor (SurfelResult::towards_sensor).
    bool towards_sensor = false;
    /// Samples left out for want of a usable normal: ones that could not be oriented, or given
    /// normals that are zero or not finite.
    std::size_t unoriented = 0;
    /// Samples left out because they lie alone far from the rest (isolated_samples(); only
    /// where radii were computed here).
    std::size_t isolated = 0;
    /// Samples left out because they stand off the surface of their nearest
    /// (off_surface_samples(); only where radii were computed here), besides the isolated.
    std::size_t off_surface = 0;
    /// Samples left out because an earlier sample lies at the very same place
    /// (spatial_order(); where normals or radii were computed here): a place is one surfel.
    std::size_t copies = 0;
};

/// \brief Samples of any kind to the surfels of a field (Level 1 or 2 → 2): raw points get
/// normals estimated and oriented and radii computed (compute_surfels()); points with normals
/// keep them and get automatic radii if they have none. Samples without a usable normal
/// (zero, non-finite, or unorientable) are dropped and counted, and so are, where the radii are
/// computed here, the samples that lie alone far from the rest (isolated_samples()) and those
/// that stand off the surface of their nearest (off_surface_samples(); where normals are
/// estimated here, the other samples' normals and radii are made without them).
/// \throw InvalidInput as check_surfel_input(), for a radius_scale not positive and finite, or
///        when fewer than k + 1 samples with a usable normal are left
[[nodiscard]] SurfelsFromSamples surfels_from_samples(
    const PointCloudView& samples, const SurfelsFromSamplesOptions& options = {});

/// \brief Options of surfels_from_mesh().
struct SurfelsFromMeshOptions
{
    /// Area-uniform samples besides the vertices; 0 = as many as the mesh has vertices.
    std::size_t samples = 0;
    /// Seed of the area-uniform samples (sample_surface()).
    std::uint64_t seed = SurfaceSamplingOptions{}.seed;
    /// Neighbours of each surfel, besides itself, for its influence radius, ≥ 3.
    std::size_t k = default_neighbors;
    /// Factor on the influence radius (distance to the k-th neighbour), > 0.
    double radius_scale = default_field_radius_scale;
};

/// \brief The surfels of a mesh (remeshing, §6: the mesh as Level 2).
struct SurfelsFromMesh
{
    PointCloud surfels;
    /// Surfels at the mesh's vertices (area-weighted vertex normals), and area-uniform ones
    /// (their triangle's normal), in that order in `surfels`.
    std::size_t vertex_surfels = 0;
    std::size_t area_surfels = 0;
};

/// \brief A triangle mesh to surfels (§6): every vertex a triangle uses with its area-weighted
/// normal (left out where that normal vanishes), then `samples` area-uniform samples
/// (sample_surface()) with their triangle's normal; radii from the distance to the k-th
/// neighbour times radius_scale. The result does not depend on the thread count.
/// \throw InvalidInput for a mesh without triangles or area, an index out of range, a
///        radius_scale not positive and finite, or k + 1 or fewer surfels
[[nodiscard]] SurfelsFromMesh surfels_from_mesh(const TriMesh& mesh,
                                                const SurfelsFromMeshOptions& options = {});

} // namespace pointform
