// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/core/error.h"
#include "pointform/core/parallel.h"
#include "pointform/geometry/mesh_topology.h"
#include "pointform/implicit/point_field.h"
#include "pointform/polygonize/base_mesh.h"
#include "pointform/polygonize/components.h"
#include "pointform/polygonize/marching_cubes.h"

#include "common.h"
#include "semi_regular.h"
#include "surfel_input.h"

#include <nlohmann/json.hpp>

#include <cstdio>
#include <memory>
#include <optional>

namespace pointform::cli {
namespace {

struct ReconstructOptions
{
    std::string input;
    std::string output;
    std::string base_mesh;
    int resolution = 0;
    double cell = 0.0;
    std::string fit = "quadric";
    std::optional<long long> min_component_samples;
    SurfelInputOptions surfels;
    SemiRegularOptions refine;
};

void run_reconstruct(const ReconstructOptions& options, const GlobalOptions& global)
{
    set_thread_count(global.threads);
    TerminalProgress progress(!global.quiet && !options.refine.json);
    Timings timings;
    SurfelInput input = load_surfels(options.input, options.surfels, progress.callback());
    timings.lap(input.estimated_normals ? "read + surfels" : "read");

    const PointField field(input.surfels, {.fit = parse_plane_fit(options.fit)});
    timings.lap("field");

    // M0: picked over the samples (§5.1, Fig. 6), or the simplified marching-cubes mesh (Fig. 5).
    TriMesh base;
    std::optional<BaseMeshStats> base_stats;
    std::optional<PickedBaseMesh> picked;
    double cell = 0.0;
    double coarsening = 1.0;
    std::size_t intermediate_faces = 0;
    ComponentFilterReport debris;
    std::size_t intermediate_vertices = 0;
    std::size_t degenerate_triangles = 0;
    std::size_t degenerate_kept = 0;
    if (!options.base_mesh.empty())
    {
        picked = read_picked_base_mesh(options.base_mesh, field.surfels(), field);
        base = picked->mesh;
        timings.lap("base mesh (picked)");
    }
    else
    {
        cell = options.cell;
        // The field's cell; without --cell or --resolution, the intermediate mesh's grid is
        // coarsened where the field's would make more faces than the base mesh needs.
        IntermediateGrid intermediate{.cell = cell};
        if (options.resolution > 0)
        {
            intermediate.cell = cell_for_resolution(input.surfels.bounds(), options.resolution);
        }
        else if (cell <= 0.0)
        {
            intermediate = intermediate_grid(field, default_cell_size(field));
        }
        cell = intermediate.cell;
        coarsening = intermediate.coarsening;
        const CellGrid grid = grid_over(field.bounds(), cell);
        check_marching_cubes_memory(field, cell);
        MarchingCubesResult mc =
            marching_cubes(field, grid,
                           {.min_defined_corners = intermediate.min_defined_corners,
                            .progress = progress.callback()});
        timings.lap("marching cubes");
        if (mc.mesh.face_count() == 0)
        {
            throw Error(
                "marching cubes made no triangles: the field has no defined zero crossing at "
                "this cell size (try a smaller --cell or a larger --radius-scale)");
        }
        intermediate_faces = mc.mesh.face_count();
        intermediate_vertices = mc.mesh.vertex_count();
        degenerate_triangles = mc.stats.degenerate_triangles;
        degenerate_kept = mc.stats.degenerate_kept;
        debris = remove_unsupported_components(
            mc.mesh, field.surfels(),
            options.min_component_samples ? static_cast<std::size_t>(*options.min_component_samples)
                                          : default_min_component_samples(field.surfels().size()));
        timings.lap("debris");
        const std::size_t target = base_face_target(options.refine, mc.mesh, default_base_share,
                                                    input.surfels.size(), coarsening);
        if (options.refine.levels)
        {
            check_refinement_memory(target, static_cast<std::size_t>(*options.refine.levels));
        }
        BaseMeshResult built = build_base_mesh(
            mc.mesh, field, {.target_faces = target, .progress = progress.callback()});
        base = std::move(built.mesh);
        base_stats = built.stats;
        timings.lap("base mesh");
    }
    const double base_seconds = timings.stages().back().second;

    const SemiRegularOutput run =
        refine_and_write(base, field, options.refine, options.output, base_seconds,
                         base_stats ? base_stats->unprojected : 0, timings, progress);
    if (options.refine.json)
    {
        nlohmann::json out = semi_regular_json(run, options.refine, options.input, options.output);
        out["estimated_normals"] = input.estimated_normals;
        out["fit"] = options.fit;
        if (base_stats)
        {
            out["cell"] = cell;
            out["intermediate_coarsening"] = coarsening;
            out["intermediate_faces"] = intermediate_faces;
            out["intermediate_vertices"] = intermediate_vertices;
            out["degenerate_triangles"] = degenerate_triangles;
            out["degenerate_kept"] = degenerate_kept;
            out["debris"] = {{"components", debris.components},
                             {"removed_components", debris.removed_components},
                             {"removed_faces", debris.removed_faces},
                             {"min_samples", debris.min_samples}};
            out["base_mesh"] = base_mesh_json(*base_stats);
            out["base_mesh"]["source"] = "automatic";
        }
        else
        {
            const AngleStats angles = angle_stats(picked->mesh);
            nlohmann::json b;
            b["source"] = options.base_mesh;
            b["faces"] = picked->mesh.face_count();
            b["vertices"] = picked->mesh.vertex_count();
            b["reoriented_faces"] = picked->reoriented_faces;
            b["max_snap_distance"] = picked->max_snap_distance;
            b["min_angle_degrees"] = angles.min_degrees;
            b["share_below_20_degrees"] = angles.share_below_20;
            b["euler_characteristic"] = picked->topology.euler_characteristic;
            b["boundary_loops"] = picked->topology.boundary_loops;
            b["components"] = picked->topology.components;
            out["base_mesh"] = b;
        }
        add_run_report(out, timings);
        std::printf("%s\n", out.dump(2).c_str());
        return;
    }
    if (global.quiet)
    {
        return;
    }
    std::printf("%s -> %s\n", options.input.c_str(), options.output.c_str());
    print_row("samples", std::to_string(input.surfels.size()) +
                             (input.estimated_normals ? " (normals estimated)" : " (surfels)"));
    if (base_stats)
    {
        print_row("intermediate mesh",
                  std::to_string(intermediate_faces) + " faces (marching cubes, cell " +
                      format_number(cell) +
                      (coarsening > 1.0
                           ? " = " + format_number(coarsening) + " x the field's, for the base mesh"
                           : std::string()) +
                      ", " + options.fit + " field; degenerate " +
                      describe_degenerate(degenerate_triangles, degenerate_kept) + ")");
        print_row("debris", "removed " + std::to_string(debris.removed_components) + " of " +
                                std::to_string(debris.components) + " components (" +
                                std::to_string(debris.removed_faces) + " faces) that fewer than " +
                                std::to_string(debris.min_samples) + " samples are nearest to");
        print_base_mesh(*base_stats);
    }
    else
    {
        const AngleStats angles = angle_stats(picked->mesh);
        print_row("base mesh", std::to_string(picked->mesh.face_count()) + " faces over " +
                                   std::to_string(picked->mesh.vertex_count()) +
                                   " picked samples (" + options.base_mesh + "; " +
                                   std::to_string(picked->reoriented_faces) + " reoriented)");
        print_row("base min angle", format_number(angles.min_degrees) + "° (" +
                                        format_number(100.0 * angles.share_below_20) +
                                        "% of the triangles below 20°)");
    }
    print_semi_regular(run, options.refine);
    print_timings(timings);
    warn_unoriented(options.input, input.unoriented);
}

} // namespace

void register_reconstruct(CLI::App& app, const GlobalOptions& global)
{
    auto options = std::make_shared<ReconstructOptions>();
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
    CLI::Option* base_faces = add_base_faces_option(*cmd, options->refine);
    cmd->add_option("--base-mesh", options->base_mesh,
                    "Picked base mesh (§5.1, Fig. 6): an OBJ whose vertices snap to the nearest "
                    "samples, or a text file of sample-index triples 'i j k', one triangle a line")
        ->excludes(base_faces);
    add_refine_options(*cmd, options->refine);
    auto* resolution = cmd->add_option("--resolution", options->resolution,
                                       "Marching cubes: cells along the longest side of the "
                                       "bounding box")
                           ->check(CLI::Range(2, 1000000));
    cmd->add_option("--cell", options->cell,
                    "Marching cubes: cell size in the input's units (default: 0.4 of the median "
                    "influence radius)")
        ->check(CLI::PositiveNumber)
        ->excludes(resolution);
    cmd->add_option("--min-component-samples", options->min_component_samples,
                    "Remove the marching-cubes components that fewer than N samples are nearest "
                    "to (debris of stray samples or flipped normals) before the base mesh; "
                    "default: 0.1% of the samples, at least 32; 0 keeps every component")
        ->check(CLI::NonNegativeNumber);
    cmd->add_option("--fit", options->fit,
                    "Local surfaces of the field: quadric, blend, centroid or raw (see `pointform "
                    "mc`)")
        ->capture_default_str()
        ->check(CLI::IsMember({"quadric", "blend", "centroid", "raw"}));
    add_surfel_input_options(*cmd, options->surfels);
    cmd->callback([options, &global] { run_reconstruct(*options, global); });
}

} // namespace pointform::cli
