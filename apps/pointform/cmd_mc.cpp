// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/core/error.h"
#include "pointform/core/parallel.h"
#include "pointform/geometry/mesh_topology.h"
#include "pointform/implicit/point_field.h"
#include "pointform/io/io.h"
#include "pointform/metrics/hausdorff.h"
#include "pointform/polygonize/base_mesh.h"
#include "pointform/polygonize/components.h"
#include "pointform/polygonize/handles.h"
#include "pointform/polygonize/marching_cubes.h"
#include "pointform/polygonize/reconstruct.h"
#include "pointform/report/report_json.h"

#include "common.h"
#include "options.h"
#include "output_transaction.h"
#include "surfel_input.h"

#include <nlohmann/json.hpp>

#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <tuple>
#include <utility>

namespace pointform::cli {
namespace {

struct McCommandOptions
{
    std::string input;
    std::string output;
    int resolution = 0;
    double cell = 0.0;
    PlaneFit fit = PlaneFit::Quadric;
    double rim_reach = PointFieldOptions{}.rim_reach;
    double fill_holes = ReconstructOptions{}.fill_holes;
    std::optional<std::size_t> min_component_samples;
    double max_handle = ReconstructOptions{}.max_handle;
    SurfelsFromSamplesOptions surfels;
    bool ascii = false;
    bool json = false;
};

void run_mc(const McCommandOptions& options, const GlobalOptions& global)
{
    set_thread_count(global.threads);
    TerminalProgress progress(!global.quiet && !options.json);
    Timings timings;
    SurfelsFromSamples input = load_surfels(options.input, options.surfels, progress.callback());
    timings.lap(input.estimated_normals ? "read + surfels" : "read");

    auto field = std::make_unique<const PointField>(
        input.surfels, PointFieldOptions{.fit = options.fit, .rim_reach = options.rim_reach});
    timings.lap("field");
    const double cell =
        choose_cell_size(*field, input.surfels.bounds(), options.resolution, options.cell);
    // Marching cubes of the field, its debris removed.
    const auto polygonize = [&](const PointField& f, const std::string& suffix) {
        const CellGrid grid = grid_over(f.bounds(), cell);
        check_marching_cubes_memory(f, cell);
        MarchingCubesResult made = marching_cubes(f, grid, {.progress = progress.callback()});
        timings.lap("marching cubes" + suffix);
        if (made.mesh.face_count() == 0)
        {
            throw Error(
                "marching cubes made no triangles: the field has no defined zero crossing "
                "at this cell size (try a smaller --cell or a larger --radius-scale)");
        }
        const ComponentFilterReport removed = remove_unsupported_components(
            made.mesh, input.surfels,
            options.min_component_samples ? *options.min_component_samples
                                          : default_min_component_samples(input.surfels.size()));
        timings.lap("debris" + suffix);
        return std::pair{std::move(made), removed};
    };
    auto [result, debris] = polygonize(*field, "");
    // A sponge: the field again with its fits at the noise's scale, as reconstruct makes it.
    std::size_t sponge = 0;
    std::size_t sponge_cells = 0;
    if (const std::optional<SpongeRefit> refit = sponge_refit(*field, result.mesh))
    {
        sponge = refit->genus;
        sponge_cells = refit->options.noise_scale_region.cells.size();
        field.reset();
        field = std::make_unique<const PointField>(input.surfels, refit->options);
        timings.lap("field (noise scale)");
        std::tie(result, debris) = polygonize(*field, " (noise scale)");
    }
    const HandleCutReport handles =
        cut_short_handles(result.mesh, options.max_handle * field->median_radius());
    timings.lap("handles");
    const HoleFillStats holes = fill_mesh_holes(result.mesh, options.fill_holes);
    timings.lap("fill holes");
    write_output(options.output, [&](const std::filesystem::path& path) {
        write_mesh(path, result.mesh, {.ascii = options.ascii});
    });
    timings.lap("write");

    const MeshTopology topo = analyze_topology(result.mesh);
    const DistanceStats distance =
        summarize_distances(distances_to_mesh(input.surfels, result.mesh));
    timings.lap("distance");
    progress.clear();
    const double diagonal = input.surfels.bounds().diagonal();

    if (options.json)
    {
        nlohmann::json out;
        out["input"] = options.input;
        out["output"] = options.output;
        out["samples"] = input.surfels.size();
        out["estimated_normals"] = input.estimated_normals;
        out["fit"] = std::string(to_string(options.fit));
        out["rim_reach"] = options.rim_reach;
        out["min_component_samples"] = debris.min_samples;
        out["components_removed"] = debris.removed_components;
        out["components_scattered"] = debris.scattered_components;
        out["stray_samples"] = field->stray_samples().size();
        out["faces_removed"] = debris.removed_faces;
        out["max_handle"] = options.max_handle;
        out["handles"] = report_json(handles);
        out["field_noise_scale"] = {
            {"refitted", sponge > 0}, {"sponge_genus", sponge}, {"cells", sponge_cells}};
        out["fill_holes"] = options.fill_holes;
        out["holes_filled"] = holes.holes_filled;
        out["hole_vertices"] = holes.hole_vertices;
        out["hole_area_share"] = holes.hole_area_share;
        out["holes_skipped_not_manifold"] = holes.skipped_not_manifold;
        out["cell"] = cell;
        out["vertices"] = result.mesh.vertex_count();
        out["faces"] = result.mesh.face_count();
        out["components"] = topo.components;
        out["boundary_loops"] = topo.boundary_loops;
        out["euler_characteristic"] = topo.euler_characteristic;
        out["manifold"] = topo.is_oriented_manifold();
        out["cells_visited"] = result.stats.cells_visited;
        out["surface_cells"] = result.stats.surface_cells;
        out["undefined_cells"] = result.stats.undefined_cells;
        out["degenerate_triangles"] = result.stats.degenerate_triangles;
        out["degenerate_kept"] = result.stats.degenerate_kept;
        out["field_evaluations"] = result.stats.field_evaluations;
        out["hausdorff_samples_to_mesh"] = distance.max;
        out["mean_samples_to_mesh"] = distance.mean;
        out["rms_samples_to_mesh"] = distance.rms;
        out["hausdorff_relative"] = diagonal > 0.0 ? distance.max / diagonal : 0.0;
        add_run_report(out, timings);
        std::printf("%s\n", out.dump(2).c_str());
        return;
    }
    if (global.quiet)
    {
        return;
    }
    std::printf("%s -> %s\n", options.input.c_str(), options.output.c_str());
    print_row("samples", std::to_string(input.surfels.size()) + describe_normals(input));
    print_row("cell", format_number(cell) + " (" + std::string(to_string(options.fit)) + " field)");
    print_row("vertices", std::to_string(result.mesh.vertex_count()));
    print_row("faces", std::to_string(result.mesh.face_count()));
    print_row(
        "components",
        std::to_string(topo.components) + " (" + std::to_string(debris.removed_components) +
            " removed: fewer than " + std::to_string(debris.min_samples) + " samples nearest" +
            (debris.scattered_components > 0 ? ", or held up by scattered samples (" +
                                                   std::to_string(debris.scattered_components) + ")"
                                             : std::string()) +
            ")" +
            (field->stray_samples().empty()
                 ? std::string()
                 : "; " + std::to_string(field->stray_samples().size()) +
                       " stray samples, not where marching cubes starts"));
    print_row("handles", describe_handle_cuts(handles, options.max_handle));
    print_row("holes filled", holes.skipped_not_manifold
                                  ? std::string("none (the mesh is not an oriented 2-manifold)")
                                  : std::to_string(holes.holes_filled) + " (" +
                                        std::to_string(holes.hole_vertices) + " vertices, " +
                                        format_number(100.0 * holes.hole_area_share) +
                                        "% of the area)");
    print_row("boundary loops", std::to_string(topo.boundary_loops));
    print_row("Euler characteristic", std::to_string(topo.euler_characteristic));
    print_row("degenerate triangles",
              describe_degenerate(result.stats.degenerate_triangles, result.stats.degenerate_kept));
    print_row("Hausdorff samples->mesh",
              format_number(distance.max) + " (" + format_number(100.0 * distance.max / diagonal) +
                  "% of the diagonal; mean " + format_number(distance.mean) + ")");
    print_timings(timings);
    warn_unoriented(options.input, input.unoriented);
    warn_isolated(options.input, input.isolated, input.copies, input.off_surface);
}

} // namespace

void register_mc(CLI::App& app, const GlobalOptions& global)
{
    auto options = std::make_shared<McCommandOptions>();
    CLI::App* cmd = app.add_subcommand(
        "mc",
        "Level 2 -> mesh: marching cubes on the point field over the cells near the samples "
        "(paper §4, Fig. 4), its debris removed, its short handles cut and the scan's holes "
        "closed as reconstruct does them (--min-component-samples, --max-handle, "
        "--fill-holes); "
        "prints counts, boundary loops and the Hausdorff distance from the samples to the "
        "mesh");
    cmd->add_option("input", options->input,
                    "Raw points (normals are estimated and oriented) or surfels (a file with "
                    "normals, and radius if present)")
        ->required();
    cmd->add_option("-o,--output", options->output, "Output mesh (.ply, .obj or .off)")->required();
    auto* resolution = cmd->add_option("--resolution", options->resolution,
                                       "Cells along the longest side of the bounding box")
                           ->check(CLI::Range(2, 1000000));
    cmd->add_option("--cell", options->cell,
                    "Cell size in the input's units (default: from the sampling density: "
                    "0.4 of the median influence radius)")
        ->check(CLI::PositiveNumber)
        ->excludes(resolution);
    add_fit_option(*cmd, options->fit,
                   "Local surfaces of the field: quadric (smooth blend of nearby local quadric "
                   "fits, the most accurate on exact and on noisy samples), blend (of centroid "
                   "planes), centroid (Hoppe's plane) or raw (the paper's plane)");
    cmd->add_option("--min-component-samples", options->min_component_samples,
                    "Remove the components that fewer than N samples are nearest to (debris of "
                    "stray samples or flipped normals), as reconstruct does; default: 0.1% of "
                    "the samples, at least 32; 0 keeps every component")
        ->check(CLI::NonNegativeNumber);
    add_max_handle_option(*cmd, options->max_handle);
    cmd->add_option("--fill-holes", options->fill_holes,
                    "Close the mesh's holes whose rim encloses at most this fraction of their "
                    "component's area with faired patches, as reconstruct does (0 keeps the "
                    "zero set as it is)")
        ->check(CLI::Range(0.0, 0.999999))
        ->capture_default_str();
    add_rim_reach_option(*cmd, options->rim_reach);
    add_surfel_input_options(*cmd, options->surfels);
    cmd->add_flag("--ascii", options->ascii, "Write ascii PLY instead of binary");
    cmd->add_flag("--json", options->json, "Print the report as JSON");
    cmd->callback([options, &global] { run_mc(*options, global); });
}

} // namespace pointform::cli
