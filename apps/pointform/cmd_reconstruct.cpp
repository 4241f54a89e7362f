// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/core/parallel.h"
#include "pointform/polygonize/reconstruct.h"

#include "common.h"
#include "options.h"
#include "semi_regular.h"
#include "surfel_input.h"

#include <nlohmann/json.hpp>

#include <cstdio>
#include <memory>
#include <optional>

namespace pointform::cli {
namespace {

struct ReconstructCommandOptions
{
    std::string input;
    std::string output;
    SurfelsFromSamplesOptions surfels;
    ReconstructOptions reconstruct; ///< its semi_regular is refine.semi_regular's
    SemiRegularCommandOptions refine;
};

void run_reconstruct(const ReconstructCommandOptions& options, const GlobalOptions& global)
{
    set_thread_count(global.threads);
    TerminalProgress progress(!global.quiet && !options.refine.json);
    Timings timings;
    SurfelsFromSamples input = load_surfels(options.input, options.surfels, progress.callback());
    timings.lap(input.estimated_normals ? "read + surfels" : "read");
    const std::size_t samples = input.surfels.size();

    ReconstructOptions reconstruct_options = options.reconstruct;
    reconstruct_options.semi_regular = options.refine.semi_regular;
    reconstruct_options.progress = progress.callback();
    ReconstructReport report = reconstruct(std::move(input.surfels), reconstruct_options);
    for (const auto& [stage, seconds] : report.stage_seconds)
    {
        timings.add(stage, seconds);
    }
    const std::optional<BaseMeshStats> base_stats = report.semi_regular.base;
    const std::string fit(to_string(options.reconstruct.fit));
    const std::string& base_mesh = options.reconstruct.base_mesh.native();
    nlohmann::json report_figures;
    if (options.refine.json)
    {
        report_figures = report_json(report, reconstruct_options);
        report_figures["estimated_normals"] = input.estimated_normals;
        report_figures["surfels"] = report_json(input);
    }
    const SemiRegularOutput run =
        write_and_measure(std::move(report.semi_regular), options.refine, options.output, timings);
    progress.clear();
    if (options.refine.json)
    {
        nlohmann::json out = semi_regular_json(std::move(report_figures), run, options.refine,
                                               options.input, options.output);
        add_run_report(out, timings);
        std::printf("%s\n", out.dump(2).c_str());
        return;
    }
    if (global.quiet)
    {
        return;
    }
    std::printf("%s -> %s\n", options.input.c_str(), options.output.c_str());
    print_row("samples", std::to_string(samples) + describe_normals(input));
    if (base_stats)
    {
        print_row("intermediate mesh",
                  std::to_string(report.intermediate_faces) + " faces (marching cubes, cell " +
                      format_number(report.cell) +
                      (report.coarsening > 1.0 ? " = " + format_number(report.coarsening) +
                                                     " x the field's, for the base mesh"
                                               : std::string()) +
                      ", " + fit + " field; degenerate " +
                      describe_degenerate(report.degenerate_triangles, report.degenerate_kept) +
                      ")");
        print_row(
            "debris",
            "removed " + std::to_string(report.debris.removed_components) + " of " +
                std::to_string(report.debris.components) + " components (" +
                std::to_string(report.debris.removed_faces) + " faces) that fewer than " +
                std::to_string(report.debris.min_samples) + " samples are nearest to" +
                (report.debris.scattered_components > 0
                     ? " or that scattered samples hold up (" +
                           std::to_string(report.debris.scattered_components) + ")"
                     : std::string()) +
                (report.stray_samples > 0 ? "; " + std::to_string(report.stray_samples) +
                                                " stray samples, not where marching cubes starts"
                                          : std::string()));
        print_row("handles", describe_handle_cuts(report.handles, options.reconstruct.max_handle));
        print_base_mesh(*base_stats);
    }
    else
    {
        const PickedBaseMesh& picked = *report.picked;
        print_row("base mesh", std::to_string(picked.mesh.face_count()) + " faces over " +
                                   std::to_string(picked.mesh.vertex_count()) +
                                   " picked samples (" + base_mesh + "; " +
                                   std::to_string(picked.reoriented_faces) + " reoriented)");
        print_row("base min angle", format_number(report.picked_angles.min_degrees) + "° (" +
                                        format_number(100.0 * report.picked_angles.sliver_share) +
                                        "% of the triangles below 20°)");
    }
    print_semi_regular(run, options.refine);
    print_timings(timings);
    warn_unoriented(options.input, input.unoriented);
    warn_isolated(options.input, input.isolated, input.copies, input.off_surface);
}

} // namespace

void register_reconstruct(CLI::App& app, const GlobalOptions& global)
{
    auto options = std::make_shared<ReconstructCommandOptions>();
    CLI::App* cmd = app.add_subcommand(
        "reconstruct",
        "Points -> semi-regular multiresolution mesh (paper §5): surfels, their field, marching "
        "cubes, a base mesh (simplified, or picked with --base-mesh), then 1-to-4 refinement "
        "projected onto the field until the one-sided Hausdorff distance from the samples is "
        "below their sampling density (or to --levels J); writes the finest level");
    cmd->add_option("input", options->input,
                    "Raw points (normals are estimated and oriented) or surfels (a file with "
                    "normals, and radius if present)")
        ->required();
    cmd->add_option("-o,--output", options->output, "Output mesh (.ply, .obj or .off)")->required();
    CLI::Option* base_faces = add_base_faces_option(*cmd, options->refine.semi_regular);
    cmd->add_option("--base-mesh", options->reconstruct.base_mesh,
                    "Picked base mesh (§5.1, Fig. 6): an OBJ whose vertices snap to the nearest "
                    "samples, or a text file of sample-index triples 'i j k', one triangle a line")
        ->excludes(base_faces);
    cmd->add_option("--fill-holes", options->reconstruct.fill_holes,
                    "Close the automatic base mesh's holes whose rim encloses at most this "
                    "fraction of their component's area (0 keeps every hole)")
        ->check(CLI::Range(0.0, 0.999999))
        ->capture_default_str();
    add_max_handle_option(*cmd, options->reconstruct.max_handle);
    add_rim_reach_option(*cmd, options->reconstruct.rim_reach);
    add_refine_options(*cmd, options->refine);
    auto* resolution = cmd->add_option("--resolution", options->reconstruct.resolution,
                                       "Marching cubes: cells along the longest side of the "
                                       "bounding box")
                           ->check(CLI::Range(2, 1000000));
    cmd->add_option("--cell", options->reconstruct.cell,
                    "Marching cubes: cell size in the input's units (default: 0.4 of the median "
                    "influence radius)")
        ->check(CLI::PositiveNumber)
        ->excludes(resolution);
    cmd->add_option("--min-component-samples", options->reconstruct.min_component_samples,
                    "Remove the marching-cubes components that fewer than N samples are nearest "
                    "to (debris of stray samples or flipped normals) before the base mesh; "
                    "default: 0.1% of the samples, at least 32; 0 keeps every component")
        ->check(CLI::NonNegativeNumber);
    add_fit_option(*cmd, options->reconstruct.fit,
                   "Local surfaces of the field: quadric, blend, centroid or raw (see `pointform "
                   "mc`)");
    add_surfel_input_options(*cmd, options->surfels);
    cmd->callback([options, &global] { run_reconstruct(*options, global); });
}

} // namespace pointform::cli
