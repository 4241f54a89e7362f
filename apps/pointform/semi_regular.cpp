// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "semi_regular.h"

#include "pointform/core/error.h"
#include "pointform/io/hierarchy.h"
#include "pointform/io/io.h"
#include "pointform/metrics/hausdorff.h"

#include "common.h"
#include "output_transaction.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

namespace pointform::cli {
namespace {

constexpr const char* sampling_density_definition =
    "median over the samples of the distance to the nearest other sample";
constexpr const char* robust_distance_definition =
    "mean of the smallest 95% of the distances from the samples to the mesh";
constexpr const char* hausdorff_definition =
    "one-sided Hausdorff distance: the largest distance from a sample to the mesh (exact "
    "closest point on the triangles)";

std::string percent_of(double value, double diagonal)
{
    return diagonal > 0.0 ? format_number(100.0 * value / diagonal) + "%" : "-";
}

} // namespace

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
                       ") and not half as much as the level before: these details follow the "
                       "noise, so level " +
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

namespace {

nlohmann::json level_json(const RefineLevelStats& s, double diagonal)
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

} // namespace

void write_semi_regular(const std::string& output, const SemiRegularCommandOptions& options,
                        const MultiresMesh& hierarchy)
{
    OutputTransaction transaction;
    transaction.stage(output, [&](const std::filesystem::path& path) {
        write_mesh(path, hierarchy.level_mesh(hierarchy.finest_level()), {.ascii = options.ascii});
    });
    if (!options.save_hierarchy.empty())
    {
        transaction.stage(options.save_hierarchy, [&](const std::filesystem::path& path) {
            write_hierarchy(path, hierarchy);
        });
    }
    transaction.commit(); // the mesh and the hierarchy, or neither
}

nlohmann::json base_mesh_json(const BaseMeshStats& stats)
{
    nlohmann::json out;
    out["input_faces"] = stats.input_faces;
    out["target_faces"] = stats.target_faces;
    out["faces"] = stats.faces;
    out["vertices"] = stats.vertices;
    out["min_angle_degrees"] = stats.min_angle_degrees;
    out["mean_min_angle_degrees"] = stats.mean_min_angle_degrees;
    out["share_below_20_degrees"] = stats.share_below_20_degrees;
    out["share_below_20_degrees_off_boundary"] = stats.share_below_20_degrees_off_boundary;
    out["smoothing_rounds"] = stats.smoothing_rounds;
    out["flips"] = stats.flips;
    out["boundary_tolerance"] = stats.boundary_tolerance;
    out["unprojected"] = stats.unprojected;
    out["max_vertex_move"] = stats.max_vertex_move;
    out["topology_kept"] = stats.topology_kept;
    out["topology_change"] = stats.topology_change;
    out["euler_characteristic"] = stats.topology_after.euler_characteristic;
    out["boundary_loops"] = stats.topology_after.boundary_loops;
    out["components"] = stats.topology_after.components;
    out["seconds"] = stats.seconds;
    return out;
}

void print_base_mesh(const BaseMeshStats& stats)
{
    print_row("base mesh", std::to_string(stats.faces) + " faces, " +
                               std::to_string(stats.vertices) + " vertices (target " +
                               std::to_string(stats.target_faces) + ", from " +
                               std::to_string(stats.input_faces) + " faces)");
    print_row("base min angle",
              format_number(stats.min_angle_degrees) + "° (mean of minima " +
                  format_number(stats.mean_min_angle_degrees) + "°; " +
                  format_number(100.0 * stats.share_below_20_degrees) +
                  "% of the triangles below 20°, " +
                  format_number(100.0 * stats.share_below_20_degrees_off_boundary) +
                  "% away from the boundary)");
    print_row("base topology",
              stats.topology_kept
                  ? "kept (Euler characteristic " +
                        std::to_string(stats.topology_after.euler_characteristic) + ", " +
                        std::to_string(stats.topology_after.boundary_loops) + " boundary loops, " +
                        std::to_string(stats.topology_after.components) + " components)"
                  : "CHANGED: " + stats.topology_change);
    print_row("base unprojected", std::to_string(stats.unprojected) + " vertices off f = 0");
}

nlohmann::json refinement_json(const SemiRegularReport& r, const SemiRegularOptions& options)
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
        levels.push_back(level_json(s, r.diagonal));
    }
    out["levels"] = levels;
    if (r.refinement.dropped)
    {
        out["dropped_level"] = level_json(*r.refinement.dropped, r.diagonal);
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
    }
    // The level the paper's rule (§5.2.4: Hausdorff below the sampling density) picks, counted
    // from the base, or null when no level made reaches it.
    out["paper_rule_level"] = r.refinement.paper_level ? nlohmann::json(*r.refinement.paper_level)
                                                       : nlohmann::json(nullptr);
    return out;
}

void print_refinement(const SemiRegularReport& r)
{
    print_row("sampling density", format_number(r.refinement.sampling_density) + " (" +
                                      sampling_density_definition + ", " +
                                      std::to_string(r.sample_count) + " samples)");
    print_row("Hausdorff", hausdorff_definition);
    print_row("robust", robust_distance_definition);
    if (!r.exact_levels && r.refinement.stop_rule == StopRule::Automatic)
    {
        print_row("field residual", format_number(r.refinement.field_residual) +
                                        " (the same robust mean of |f| at the samples); detail "
                                        "threshold " +
                                        format_number(r.refinement.detail_threshold));
        print_row("vertex budget", std::to_string(r.refinement.vertex_budget) + " (the samples)");
    }
    print_row("VEN fix",
              "fold vertices whose fold the vertex-based edge normal fixed / fold "
              "vertices after projection along the face normal (§5.2.2)");
    std::printf("  %5s %10s %10s %12s %9s %12s %12s %9s %11s %8s\n", "level", "faces", "vertices",
                "Hausdorff", "% diag", "mean", "robust", "VEN fix", "unprojected", "seconds");
    const auto row = [&](std::size_t level, std::size_t faces, std::size_t vertices, double h,
                         double mean, double robust, const std::string& ven,
                         std::size_t unprojected, double seconds, const char* note) {
        std::printf("  %5zu %10zu %10zu %12s %9s %12s %12s %9s %11zu %8.3f%s\n", level, faces,
                    vertices, format_number(h).c_str(), percent_of(h, r.diagonal).c_str(),
                    format_number(mean).c_str(), format_number(robust).c_str(), ven.c_str(),
                    unprojected, seconds, note);
    };
    const auto level_row = [&](const RefineLevelStats& s, const char* note) {
        row(s.level, s.faces, s.vertices, s.hausdorff.value_or(0.0), s.mean_distance.value_or(0.0),
            s.robust_distance.value_or(0.0),
            std::to_string(s.folds_fixed_by_ven) + "/" + std::to_string(s.fold_vertices),
            s.unprojected, s.seconds, note);
    };
    row(0, r.hierarchy.face_count(0), r.hierarchy.vertex_count(0), r.refinement.initial_hausdorff,
        r.refinement.initial_mean_distance, r.refinement.initial_robust_distance, "-",
        r.base_unprojected, r.base_seconds, "");
    for (const RefineLevelStats& s : r.refinement.levels)
    {
        level_row(s, "");
    }
    if (r.refinement.dropped)
    {
        level_row(*r.refinement.dropped, "  (not kept)");
    }
    print_row("stopped", stop_reason(r));
    if (!r.exact_levels && r.refinement.stop_rule == StopRule::Automatic)
    {
        print_row("paper's rule", r.refinement.paper_level
                                      ? "§5.2.4 (Hausdorff below the sampling density) is met at "
                                        "level " +
                                            std::to_string(*r.refinement.paper_level)
                                      : std::string("§5.2.4 (Hausdorff below the sampling "
                                                    "density) is met at no level made"));
    }
}

nlohmann::json semi_regular_json(const SemiRegularOutput& run,
                                 const SemiRegularCommandOptions& options, const std::string& input,
                                 const std::string& output)
{
    nlohmann::json out = refinement_json(run.report, options.semi_regular);
    out["input"] = input;
    out["output"] = output;
    if (!options.save_hierarchy.empty())
    {
        out["hierarchy"] = options.save_hierarchy;
    }
    out["components"] = run.topology.components;
    out["boundary_loops"] = run.topology.boundary_loops;
    out["euler_characteristic"] = run.topology.euler_characteristic;
    out["manifold"] = run.topology.is_oriented_manifold();
    return out;
}

void print_semi_regular(const SemiRegularOutput& run, const SemiRegularCommandOptions& options)
{
    const MultiresMesh& hierarchy = run.report.hierarchy;
    print_refinement(run.report);
    print_row("output", std::to_string(hierarchy.face_count(hierarchy.finest_level())) +
                            " faces, " + std::to_string(hierarchy.vertex_count()) +
                            " vertices, level " + std::to_string(hierarchy.finest_level()) +
                            "; Euler " + std::to_string(run.topology.euler_characteristic) + ", " +
                            std::to_string(run.topology.boundary_loops) + " boundary loops");
    if (!options.save_hierarchy.empty())
    {
        print_row("hierarchy", options.save_hierarchy + " (" +
                                   std::to_string(hierarchy.level_count()) + " levels)");
    }
}

} // namespace pointform::cli

namespace pointform::cli {

SemiRegularOutput write_and_measure(SemiRegularReport report,
                                    const SemiRegularCommandOptions& options,
                                    const std::string& output, Timings& timings)
{
    SemiRegularOutput run{std::move(report), {}};
    write_semi_regular(output, options, run.report.hierarchy);
    timings.lap("write");
    run.topology =
        analyze_topology(run.report.hierarchy.level_mesh(run.report.hierarchy.finest_level()));
    return run;
}

} // namespace pointform::cli
