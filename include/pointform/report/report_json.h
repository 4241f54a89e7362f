// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// The library's reports as JSON and in words: one presentation of every figure, under one set of
// names, for every front end (the CLI's --json and its text, the Python module's dicts, the
// viewer), so that all of them show the same figures from the same library call.

#pragma once

#include "pointform/hermite/surfels.h"
#include "pointform/metrics/hausdorff.h"
#include "pointform/multires/deformation.h"
#include "pointform/multires/details.h"
#include "pointform/multires/edit_file.h"
#include "pointform/multires/texture.h"
#include "pointform/polygonize/base_mesh.h"
#include "pointform/polygonize/reconstruct.h"
#include "pointform/polygonize/refine.h"

#include <nlohmann/json.hpp>

#include <cstddef>
#include <string>

namespace pointform {

/// What the refinement's figures mean, stated beside them.
inline constexpr const char* sampling_density_definition =
    "median over the samples of the distance to the nearest other sample";
inline constexpr const char* robust_distance_definition =
    "mean of the smallest 95% of the distances from the samples to the mesh";
inline constexpr const char* hausdorff_definition =
    "one-sided Hausdorff distance: the largest distance from a sample to the mesh (exact "
    "closest point on the triangles)";

/// \brief A number in words: six significant digits (printf's %.6g).
[[nodiscard]] std::string format_number(double value);

/// \brief Why the refinement stopped, in words, with the figures that decided it.
[[nodiscard]] std::string stop_reason(const SemiRegularReport& report);

/// \brief surfels_from_samples()'s report: estimated_normals, estimated_radii, components,
/// flipped, crease_refits, thin_parts, thin_part_turned, degenerate, unoriented, isolated,
/// off_surface, copies.
[[nodiscard]] nlohmann::json report_json(const SurfelsFromSamples& surfels);

/// \brief One refined level (RefineLevelStats), its distances also relative to `diagonal`.
[[nodiscard]] nlohmann::json report_json(const RefineLevelStats& level, double diagonal);

/// \brief The automatic base mesh's figures (BaseMeshStats), its "source" "automatic".
[[nodiscard]] nlohmann::json report_json(const BaseMeshStats& stats);

/// \brief The short handles cut (cut_short_handles()): genus before and after, cuts, rounds,
/// the longest loop cut and the bound.
[[nodiscard]] nlohmann::json report_json(const HandleCutReport& handles);

/// \brief A semi-regular mesh's report: the samples, the sampling density and the definitions,
/// the levels from the base (level 0) up, a dropped level, the stop and its reason, the
/// predictor and relaxation of `options`, and the automatic base mesh when there is one.
[[nodiscard]] nlohmann::json report_json(const SemiRegularReport& report,
                                         const SemiRegularOptions& options);

/// \brief reconstruct()'s report: report_json(report.semi_regular, ...) and the field's fit, the
/// intermediate marching-cubes mesh, the debris removed and the base mesh (automatic, or the
/// picked one with its angles and topology).
[[nodiscard]] nlohmann::json report_json(const ReconstructReport& report,
                                         const ReconstructOptions& options);

/// \brief remesh()'s report: report_json(report.semi_regular, ...), the input mesh's counts,
/// the surfels at vertices and area samples, and the fit.
[[nodiscard]] nlohmann::json report_json(const RemeshReport& report, const RemeshOptions& options);

/// \brief Distance statistics: count, min, max, mean, rms, p50, p90, p99.
[[nodiscard]] nlohmann::json report_json(const DistanceStats& stats);

/// \brief compare()'s result: diagonal, absolute and relative_to_diagonal (a_to_b, b_to_a,
/// symmetric, hausdorff, chamfer) and fscore (threshold, absolute_threshold, precision,
/// recall, f).
[[nodiscard]] nlohmann::json report_json(const DistanceComparison& comparison);

/// \brief A shape compare() measured: its kind ("mesh" or "points"), points, faces, and how
/// many samples measure it with `samples` area samples a mesh (its used vertices added).
[[nodiscard]] nlohmann::json report_json(const ShapeRef& shape, std::size_t samples);

/// \brief A deformation's report: level, region_vertices, handle_vertices, free_vertices,
/// unconstrained_vertices, largest_displacement (also relative to `diagonal`) and per level
/// (vertices, moved, largest).
[[nodiscard]] nlohmann::json report_json(const DeformReport& report, double diagonal);

/// \brief The details' statistics per level (details, mean_length, max_length, mean_normal,
/// mean_tangent, normal_share) and the tolerance that defines an almost pure normal detail.
[[nodiscard]] nlohmann::json report_json(const std::vector<DetailLevelStats>& levels,
                                         double normal_tolerance);

/// \brief deform_hierarchy()'s outcome: mode, predictor, diagonal, deformation (as above) and
/// details (the input's, as above).
[[nodiscard]] nlohmann::json report_json(const DeformOutcome& outcome);

/// \brief texture_hierarchy()'s outcome: level, the atlas (size, gutter, charts, texel_usage,
/// texels_per_unit), per exported level its faces, vertices and distortion (l2_stretch,
/// linf_stretch, angle_distortion, area_distortion, flipped), the exported vertex count (seams
/// included), and the bake's figures when colours were baked.
[[nodiscard]] nlohmann::json report_json(const TextureOutcome& outcome);

} // namespace pointform
