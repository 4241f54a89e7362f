// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/report/report_json.h"

#include <cstdio>
#include <vector>

namespace pointform {

std::string format_number(double value)
{
    char buffer[64];
    std::snprintf(buffer, sizeof buffer, "%.6g", value);
    return buffer;
}

std::string stop_reason(const SemiRegularReport& r)
{
    if (r.exact_levels)
        return "--levels " + std::to_string(r.level_cap) + ": refined exactly to level " +
               std::to_string(r.level_cap);
    const std::size_t finest = r.hierarchy.finest_level();
    const double last = r.refinement.levels.empty() ? r.refinement.initial_hausdorff
                                                    : *r.refinement.levels.back().hausdorff;
    const double robust = r.refinement.levels.empty() ? r.refinement.initial_robust_distance
                                                      : *r.refinement.levels.back().robust_distance;
    if (r.refinement.stop_rule == StopRule::Automatic)
    {
        const double detail = r.refinement.levels.empty()
                                  ? r.refinement.initial_next_detail
                                  : r.refinement.levels.back().next_detail.value_or(0.0);
        switch (r.refinement.stop)
        {
            case RefineStop::SmallDetails:
                return "level " + std::to_string(finest + 1) + " would move its new vertices by " +
                       format_number(detail) + " on average, not more than the threshold " +
                       format_number(r.refinement.detail_threshold) +
                       " (a tenth of the field's residual at the samples, " +
                       format_number(r.refinement.field_residual) +
                       ", or a thousandth of the sampling density): level " +
                       std::to_string(finest) +
                       " is as close as the field allows (robust distance " +
                       format_number(robust) + ")";
            case RefineStop::NoisyDetails:
                return "level " + std::to_string(finest + 1) + " would move its new vertices by " +
                       format_number(detail) +
                       " on average, less than the field's residual at the samples (" +
                       format_number(r.refinement.field_residual) +
                       "), and more than 0.35 times the level before (a smooth surface's shrink to "
                       "a "
                       "quarter): these details follow the noise, so level " +
                       std::to_string(finest) + " is the output (robust distance " +
                       format_number(robust) + ")";
            case RefineStop::VertexBudget:
                return "level " + std::to_string(finest + 1) +
                       " would have more vertices than the budget of " +
                       std::to_string(r.refinement.vertex_budget) +
                       " (the number of samples), so level " + std::to_string(finest) +
                       " is the output (robust distance " + format_number(robust) + ")";
            default:
                break;
        }
    }
    const std::string distances = "Hausdorff " + format_number(last) + ", sampling density " +
                                  format_number(r.refinement.sampling_density);
    switch (r.refinement.stop)
    {
        case RefineStop::BelowSamplingDensity:
            return finest == 0
                       ? "the base mesh is already within the sampling density (" + distances + ")"
                       : "the Hausdorff distance from the samples fell below the sampling "
                         "density at level " +
                             std::to_string(finest) + " (" + distances + ")";
        case RefineStop::Stalled:
            return "level " + std::to_string(finest + 1) +
                   " lowered the Hausdorff distance by less than 5%, so it is not kept and level " +
                   std::to_string(finest) + " is the output (" + distances +
                   "): the samples still farther than the density lie where refinement cannot "
                   "reach (outliers, noise, beyond a hole's rim)";
        case RefineStop::LevelCap:
        case RefineStop::VertexBudget:
        case RefineStop::SmallDetails:
        case RefineStop::NoisyDetails:
            break;
    }
    return "reached the level cap " + std::to_string(r.level_cap) +
           (r.cap_from_memory ? " (the deepest level that fits in memory)"
                              : " (the default; --levels J refines further)") +
           " with the distance still above the sampling density (" + distances + ")";
}

nlohmann::json report_json(const SurfelsFromSamples& surfels)
{
    return {{"estimated_normals", surfels.estimated_normals},
            {"estimated_radii", surfels.estimated_radii},
            {"components", surfels.components},
            {"flipped", surfels.flipped},
            {"crease_refits", surfels.crease_refits},
            {"towards_sensor", surfels.towards_sensor},
            {"thin_parts", surfels.thin_parts},
            {"thin_part_turned", surfels.thin_part_turned},
            {"degenerate", surfels.degenerate},
            {"unoriented", surfels.unoriented},
            {"isolated", surfels.isolated},
            {"off_surface", surfels.off_surface},
            {"copies", surfels.copies}};
}

nlohmann::json report_json(const RefineLevelStats& s, double diagonal)
{
    nlohmann::json out;
    out["level"] = s.level;
    out["faces"] = s.faces;
    out["vertices"] = s.vertices;
    out["new_vertices"] = s.new_vertices;
    out["hausdorff"] = s.hausdorff.value_or(0.0);
    out["hausdorff_relative"] = diagonal > 0.0 ? s.hausdorff.value_or(0.0) / diagonal : 0.0;
    out["mean_distance"] = s.mean_distance.value_or(0.0);
    out["robust_distance"] = s.robust_distance.value_or(0.0);
    out["p90_distance"] = s.p90_distance.value_or(0.0);
    if (s.next_detail)
    {
        out["next_detail"] = *s.next_detail;
    }
    out["fold_vertices"] = s.fold_vertices;
    out["folds_fixed_by_ven"] = s.folds_fixed_by_ven;
    out["folds_unresolved"] = s.folds_unresolved;
    out["unprojected"] = s.unprojected;
    out["relaxed"] = s.relaxed;
    out["relax_undone"] = s.relax_undone;
    out["folded_faces"] = s.folded_faces;
    out["seconds"] = s.seconds;
    return out;
}

nlohmann::json report_json(const HandleCutReport& handles)
{
    return {{"genus_before", handles.genus_before},
            {"genus_after", handles.genus_after},
            {"cuts", handles.cuts},
            {"rounds", handles.rounds},
            {"longest_cut", handles.longest_cut},
            {"max_length", handles.max_length},
            {"skipped_not_manifold", handles.skipped_not_manifold}};
}

nlohmann::json report_json(const BaseMeshStats& stats)
{
    nlohmann::json out;
    out["source"] = "automatic";
    out["input_faces"] = stats.input_faces;
    out["target_faces"] = stats.target_faces;
    out["decimated_in_blocks"] = stats.decimated_in_blocks;
    out["faces"] = stats.faces;
    out["vertices"] = stats.vertices;
    out["min_angle_degrees"] = stats.min_angle_degrees;
    out["mean_min_angle_degrees"] = stats.mean_min_angle_degrees;
    out["share_below_20_degrees"] = stats.share_below_20_degrees;
    out["share_below_20_degrees_off_boundary"] = stats.share_below_20_degrees_off_boundary;
    out["smoothing_rounds"] = stats.smoothing_rounds;
    out["flips"] = stats.flips;
    out["chord_splits"] = stats.chord_splits;
    out["boundary_tolerance"] = stats.boundary_tolerance;
    out["unprojected"] = stats.unprojected;
    out["max_vertex_move"] = stats.max_vertex_move;
    out["topology_kept"] = stats.topology_kept;
    out["topology_change"] = stats.topology_change;
    out["holes_filled"] = stats.holes_filled;
    out["hole_vertices"] = stats.hole_vertices;
    out["hole_area_share"] = stats.hole_area_share;
    out["euler_characteristic"] = stats.topology_after.euler_characteristic;
    out["boundary_loops"] = stats.topology_after.boundary_loops;
    out["components"] = stats.topology_after.components;
    out["seconds"] = stats.seconds;
    return out;
}

nlohmann::json report_json(const SemiRegularReport& r, const SemiRegularOptions& options)
{
    nlohmann::json out;
    out["samples"] = r.sample_count;
    out["sampling_density"] = r.refinement.sampling_density;
    out["sampling_density_definition"] = sampling_density_definition;
    out["hausdorff_definition"] = hausdorff_definition;
    out["diagonal"] = r.diagonal;
    nlohmann::json levels = nlohmann::json::array();
    nlohmann::json base;
    base["level"] = 0;
    base["faces"] = r.hierarchy.face_count(0);
    base["vertices"] = r.hierarchy.vertex_count(0);
    base["hausdorff"] = r.refinement.initial_hausdorff;
    base["hausdorff_relative"] =
        r.diagonal > 0.0 ? r.refinement.initial_hausdorff / r.diagonal : 0.0;
    base["mean_distance"] = r.refinement.initial_mean_distance;
    base["robust_distance"] = r.refinement.initial_robust_distance;
    base["p90_distance"] = r.refinement.initial_p90_distance;
    if (r.refinement.stop_rule == StopRule::Automatic)
    {
        base["next_detail"] = r.refinement.initial_next_detail;
    }
    base["folds_fixed_by_ven"] = 0;
    base["unprojected"] = r.base_unprojected;
    base["seconds"] = r.base_seconds;
    levels.push_back(base);
    for (const RefineLevelStats& s : r.refinement.levels)
    {
        levels.push_back(report_json(s, r.diagonal));
    }
    out["levels"] = levels;
    if (r.refinement.dropped)
    {
        out["dropped_level"] = report_json(*r.refinement.dropped, r.diagonal);
    }
    out["finest_level"] = r.hierarchy.finest_level();
    out["faces"] = r.hierarchy.face_count(r.hierarchy.finest_level());
    out["vertices"] = r.hierarchy.vertex_count();
    out["predictor"] = std::string(to_string(options.predictor));
    out["relaxation"] = {{"move", std::string(to_string(options.relaxation))},
                         {"rounds", options.relax_iterations}};
    out["exact_levels"] = r.exact_levels;
    out["level_cap"] = r.level_cap;
    out["level_cap_from_memory"] = r.cap_from_memory;
    out["stop"] =
        r.exact_levels ? std::string("levels") : std::string(to_string(r.refinement.stop));
    out["stop_reason"] = stop_reason(r);
    out["stop_rule"] =
        r.exact_levels ? std::string("levels") : std::string(to_string(r.refinement.stop_rule));
    out["robust_distance_definition"] = robust_distance_definition;
    if (!r.exact_levels && r.refinement.stop_rule == StopRule::Automatic)
    {
        out["vertex_budget"] = r.refinement.vertex_budget;
        out["field_residual"] = r.refinement.field_residual;
        out["detail_threshold"] = r.refinement.detail_threshold;
        out["denoise_rounds"] = r.refinement.denoise_rounds;
        out["denoise_max_move"] = r.refinement.denoise_max_move;
        out["face_fit_vertices"] = r.refinement.face_fit_vertices;
        out["face_fit_max_move"] = r.refinement.face_fit_max_move;
        out["face_fit_median_move"] = r.refinement.face_fit_median_move;
        out["face_fit_probes"] = r.refinement.face_fit_probes;
        out["spikes"] = r.refinement.spikes;
        out["unsupported_regions"] = r.refinement.unsupported.regions;
        out["unsupported_membranes"] = r.refinement.unsupported.membranes;
        out["unsupported_creases"] = r.refinement.unsupported.creases;
        out["unsupported_vertices"] = r.refinement.unsupported.vertices;
        out["unsupported_max_move"] = r.refinement.unsupported.max_move;
    }
    // The level the paper's rule (§5.2.4: Hausdorff below the sampling density) picks, counted
    // from the base, or null when no level made reaches it.
    out["paper_rule_level"] = r.refinement.paper_level ? nlohmann::json(*r.refinement.paper_level)
                                                       : nlohmann::json(nullptr);
    if (r.base)
        out["base_mesh"] = report_json(*r.base);
    return out;
}

nlohmann::json report_json(const ReconstructReport& report, const ReconstructOptions& options)
{
    nlohmann::json out = report_json(report.semi_regular, options.semi_regular);
    out["fit"] = std::string(to_string(options.fit));
    out["rim_reach"] = options.rim_reach;
    if (report.semi_regular.base)
    {
        out["cell"] = report.cell;
        out["intermediate_coarsening"] = report.coarsening;
        out["intermediate_undefined_triangles"] = report.undefined_triangles;
        out["intermediate_cell_vertices"] = report.cell_vertices;
        out["intermediate_faces"] = report.intermediate_faces;
        out["intermediate_vertices"] = report.intermediate_vertices;
        out["degenerate_triangles"] = report.degenerate_triangles;
        out["degenerate_kept"] = report.degenerate_kept;
        out["debris"] = {{"components", report.debris.components},
                         {"removed_components", report.debris.removed_components},
                         {"removed_faces", report.debris.removed_faces},
                         {"min_samples", report.debris.min_samples},
                         {"scattered_components", report.debris.scattered_components},
                         {"stray_samples", report.stray_samples}};
        out["handles"] = report_json(report.handles);
        out["field_noise_scale"] = {{"refitted", report.sponge_genus > 0},
                                    {"sponge_genus", report.sponge_genus},
                                    {"cells", report.sponge_cells}};
    }
    else if (report.picked)
    {
        const PickedBaseMesh& picked = *report.picked;
        nlohmann::json b;
        b["source"] =
            options.base_mesh.empty() ? options.picked_vertices.source : options.base_mesh.string();
        b["faces"] = picked.mesh.face_count();
        b["vertices"] = picked.mesh.vertex_count();
        b["reoriented_faces"] = picked.reoriented_faces;
        b["max_snap_distance"] = picked.max_snap_distance;
        b["min_angle_degrees"] = report.picked_angles.min_degrees;
        b["share_below_20_degrees"] = report.picked_angles.sliver_share;
        b["euler_characteristic"] = picked.topology.euler_characteristic;
        b["boundary_loops"] = picked.topology.boundary_loops;
        b["components"] = picked.topology.components;
        out["base_mesh"] = b;
    }
    return out;
}

nlohmann::json report_json(const RemeshReport& report, const RemeshOptions& options)
{
    nlohmann::json out = report_json(report.semi_regular, options.semi_regular);
    out["input_faces"] = report.input_faces;
    out["input_vertices"] = report.input_vertices;
    out["vertex_surfels"] = report.vertex_surfels;
    out["area_samples"] = report.area_surfels;
    out["fit"] = std::string(to_string(options.fit));
    return out;
}

nlohmann::json report_json(const DistanceStats& s)
{
    return {{"count", s.count}, {"min", s.min}, {"max", s.max}, {"mean", s.mean},
            {"rms", s.rms},     {"p50", s.p50}, {"p90", s.p90}, {"p99", s.p99}};
}

namespace {

nlohmann::json summary_json(const DistanceSummary& s)
{
    return {{"a_to_b", report_json(s.a_to_b)},
            {"b_to_a", report_json(s.b_to_a)},
            {"symmetric", report_json(s.symmetric)},
            {"hausdorff", s.hausdorff},
            {"chamfer", s.chamfer}};
}

} // namespace

nlohmann::json report_json(const DistanceComparison& comparison)
{
    nlohmann::json out;
    out["diagonal"] = comparison.diagonal;
    out["absolute"] = summary_json(comparison.absolute);
    out["relative_to_diagonal"] = summary_json(comparison.relative);
    nlohmann::json scores = nlohmann::json::array();
    for (const FScore& f : comparison.fscores)
        scores.push_back({{"threshold", f.threshold},
                          {"absolute_threshold", f.absolute_threshold},
                          {"precision", f.precision},
                          {"recall", f.recall},
                          {"f", f.f}});
    out["fscore"] = scores;
    return out;
}

nlohmann::json report_json(const ShapeRef& shape, std::size_t samples)
{
    return {{"kind", shape.mesh != nullptr ? "mesh" : "points"},
            {"points", shape.points.size()},
            {"faces", shape.mesh != nullptr ? shape.mesh->face_count() : 0},
            {"samples", compare_sample_count(shape, samples)}};
}

nlohmann::json report_json(const DeformReport& report, double diagonal)
{
    nlohmann::json out;
    out["level"] = report.level;
    out["region_vertices"] = report.region_vertices;
    out["handle_vertices"] = report.handle_vertices;
    out["free_vertices"] = report.free_vertices;
    out["unconstrained_vertices"] = report.unconstrained_vertices;
    out["largest_displacement"] = report.largest_displacement;
    out["largest_displacement_relative"] =
        diagonal > 0.0 ? report.largest_displacement / diagonal : 0.0;
    nlohmann::json levels = nlohmann::json::array();
    for (const LevelMotion& motion : report.levels)
        levels.push_back({{"level", motion.level},
                          {"vertices", motion.vertices},
                          {"moved", motion.moved},
                          {"largest", motion.largest}});
    out["levels"] = levels;
    return out;
}

nlohmann::json report_json(const std::vector<DetailLevelStats>& levels, double normal_tolerance)
{
    nlohmann::json out;
    out["normal_tolerance"] = normal_tolerance;
    out["definition"] =
        "a detail is almost a pure normal offset when its tangential part is at "
        "most normal_tolerance times its length";
    nlohmann::json rows = nlohmann::json::array();
    for (const DetailLevelStats& s : levels)
        rows.push_back({{"level", s.level},
                        {"details", s.details},
                        {"mean_length", s.mean_length},
                        {"max_length", s.max_length},
                        {"mean_normal", s.mean_normal},
                        {"mean_tangent", s.mean_tangent},
                        {"normal_share", s.normal_share}});
    out["levels"] = rows;
    return out;
}

nlohmann::json report_json(const DeformOutcome& outcome)
{
    nlohmann::json out;
    out["mode"] = outcome.mode;
    out["predictor"] = std::string(to_string(outcome.predictor));
    out["diagonal"] = outcome.diagonal;
    out["deformation"] = report_json(outcome.deformation, outcome.diagonal);
    out["details"] = report_json(outcome.details, outcome.normal_tolerance);
    return out;
}

nlohmann::json report_json(const TextureOutcome& outcome)
{
    nlohmann::json out;
    out["level"] = outcome.level;
    out["atlas"] = {{"size", outcome.atlas.size},
                    {"gutter", outcome.atlas.gutter},
                    {"charts", outcome.atlas.corners.size()},
                    {"texel_usage", outcome.atlas.texel_usage},
                    {"texels_per_unit", outcome.atlas.texels_per_unit}};
    nlohmann::json levels = nlohmann::json::array();
    for (std::size_t i = 0; i < outcome.distortion.size(); ++i)
    {
        const AtlasDistortion& d = outcome.distortion[i];
        levels.push_back({{"level", d.level},
                          {"faces", d.faces},
                          {"vertices", outcome.mesh.lod_vertex_counts[i]},
                          {"l2_stretch", d.l2_stretch},
                          {"linf_stretch", d.linf_stretch},
                          {"angle_distortion", d.angle_distortion},
                          {"area_distortion", d.area_distortion},
                          {"flipped", d.flipped}});
    }
    out["levels"] = levels;
    out["vertices"] = outcome.mesh.positions.size();
    out["normal_map"] = !outcome.mesh.normal_map.empty();
    if (outcome.bake)
        out["bake"] = {{"texels", outcome.bake->texels},
                       {"dilated", outcome.bake->dilated},
                       {"mean_distance", outcome.bake->mean_distance},
                       {"rms_color_error", outcome.bake->rms_color_error}};
    return out;
}

} // namespace pointform
