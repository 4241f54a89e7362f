// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "semi_regular.h"

#include "pointform/core/error.h"
#include "pointform/io/hierarchy.h"
#include "pointform/io/io.h"
#include "pointform/metrics/hausdorff.h"
#include "pointform/report/report_json.h"

#include "common.h"
#include "output_transaction.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

namespace pointform::cli {
namespace {

std::string percent_of(double value, double diagonal)
{
    return diagonal > 0.0 ? format_number(100.0 * value / diagonal) + "%" : "-";
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
    if (stats.holes_filled > 0)
        print_row("holes filled", std::to_string(stats.holes_filled) + " (" +
                                      std::to_string(stats.hole_vertices) + " vertices added; " +
                                      format_number(100.0 * stats.hole_area_share) +
                                      "% of the base mesh's area; --fill-holes 0 keeps them)");
    print_row("base topology",
              stats.topology_kept
                  ? std::string(stats.holes_filled > 0 ? "kept, the holes filled" : "kept") +
                        " (Euler characteristic " +
                        std::to_string(stats.topology_after.euler_characteristic) + ", " +
                        std::to_string(stats.topology_after.boundary_loops) + " boundary loops, " +
                        std::to_string(stats.topology_after.components) + " components)"
                  : "CHANGED: " + stats.topology_change);
    print_row("base unprojected", std::to_string(stats.unprojected) + " vertices off f = 0");
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
        if (r.refinement.denoise_rounds > 0)
            print_row("denoised", std::to_string(r.refinement.denoise_rounds) +
                                      " rounds of Taubin smoothing of the finest level (its "
                                      "details were noise); farthest move " +
                                      format_number(r.refinement.denoise_max_move));
        if (r.refinement.face_fit_vertices > 0)
            print_row("face fit", std::to_string(r.refinement.face_fit_vertices) +
                                      " vertices moved along their normals so that the faces "
                                      "fit the field in the least-squares sense; median move " +
                                      format_number(r.refinement.face_fit_median_move) +
                                      ", farthest " +
                                      format_number(r.refinement.face_fit_max_move));
        else if (r.refinement.face_fit_median_move > 0.0)
            print_row(
                "face fit",
                "none: the median move " + format_number(r.refinement.face_fit_median_move) +
                    (r.refinement.face_fit_probes > 0
                         ? " (over " + std::to_string(r.refinement.face_fit_probes) + " vertices)"
                         : std::string()) +
                    " is below a quarter of the field residual (noise)");
        if (r.refinement.spikes > 0)
            print_row("spikes", std::to_string(r.refinement.spikes) +
                                    " vertices that stood off their neighbours' surface alone, "
                                    "put back on the field from the neighbours' centroid");
        if (r.refinement.unsupported.regions > 0)
            print_row("faired", std::to_string(r.refinement.unsupported.regions) +
                                    " regions no sample supports (filled holes and their "
                                    "rims; " +
                                    std::to_string(r.refinement.unsupported.membranes) +
                                    " as membranes, the rest as thin plates, " +
                                    std::to_string(r.refinement.unsupported.creases) +
                                    " of them out to a crease), " +
                                    std::to_string(r.refinement.unsupported.vertices) +
                                    " vertices; farthest move " +
                                    format_number(r.refinement.unsupported.max_move));
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

nlohmann::json semi_regular_json(nlohmann::json report, const SemiRegularOutput& run,
                                 const SemiRegularCommandOptions& options, const std::string& input,
                                 const std::string& output)
{
    nlohmann::json out = std::move(report);
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
