// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/core/error.h"
#include "pointform/core/parallel.h"
#include "pointform/geometry/mesh_topology.h"
#include "pointform/implicit/scene.h"
#include "pointform/io/io.h"
#include "pointform/polygonize/marching_cubes.h"
#include "pointform/polygonize/reconstruct.h"
#include "pointform/polygonize/scene_mesh.h"

#include "common.h"
#include "options.h"
#include "output_transaction.h"
#include "scene_input.h"
#include "semi_regular.h"
#include "surfel_input.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>
#include <vector>

namespace pointform::cli {
namespace {

struct ModelCommandOptions
{
    std::string input;
    std::string output;
    SceneCommandOptions scene;
    bool semi_regular = false;
    /// With --semi-regular; its --ascii and --json are the scene's.
    SemiRegularCommandOptions refine;
};

nlohmann::json box_json(const Aabb& box)
{
    return {{"min", {box.min.x(), box.min.y(), box.min.z()}},
            {"max", {box.max.x(), box.max.y(), box.max.z()}}};
}

void run_model(const ModelCommandOptions& options, const GlobalOptions& global)
{
    set_thread_count(global.threads);
    TerminalProgress progress(!global.quiet && !options.scene.json);
    Timings timings;
    SceneArguments arguments(options.scene, progress.callback());
    const SceneArguments::Loaded scene = arguments.load(options.input);
    timings.lap(arguments.scans().empty() ? "scene" : "scene + surfels");

    SemiRegularCommandOptions refine = options.refine;
    refine.ascii = options.scene.ascii;
    SceneMeshOptions mesh_options{.grid = options.scene.grid, .progress = progress.callback()};
    if (options.semi_regular)
    {
        mesh_options.semi_regular = refine.semi_regular;
    }
    const SceneMeshReport report = scene_mesh(*scene.field, arguments.scans(), mesh_options);
    for (const auto& [stage, seconds] : report.stage_seconds)
    {
        timings.add(stage, seconds);
    }
    const SceneGrid& grid = report.grid;
    const MarchingCubesResult& result = report.marching_cubes;
    const std::optional<SemiRegularReport>& semi = report.semi_regular;
    if (semi)
    {
        write_semi_regular(options.output, refine, semi->hierarchy);
    }
    else
    {
        write_output(options.output, [&](const std::filesystem::path& path) {
            write_mesh(path, result.mesh, {.ascii = options.scene.ascii});
        });
    }
    timings.lap("write");
    const TriMesh& written = report.mesh();
    const MeshTopology topo = analyze_topology(written);
    progress.clear();

    if (options.scene.json)
    {
        nlohmann::json out;
        out["input"] = options.input;
        out["input_kind"] = std::string(to_string(scene.kind));
        out["output"] = options.output;
        nlohmann::json scans = nlohmann::json::array();
        for (const LoadedScan& scan : arguments.scans())
        {
            scans.push_back({{"path", scan.path},
                             {"samples", scan.samples},
                             {"estimated_normals", scan.estimated_normals},
                             {"median_radius", scan.field->median_radius()}});
        }
        out["scans"] = scans;
        out["fit"] = std::string(to_string(options.scene.scans.field.fit));
        out["bounds"] = box_json(grid.box);
        out["cell"] = grid.cell;
        out["grid_cells"] = grid.grid.cells;
        out["polygonization"] = semi ? "semi-regular" : "marching cubes";
        if (semi)
        {
            out["marching_cubes_faces"] = result.mesh.face_count();
            out["base_mesh"] = report_json(*semi->base);
            nlohmann::json levels = nlohmann::json::array();
            for (const RefineLevelStats& level : semi->refinement.levels)
            {
                levels.push_back({{"level", level.level},
                                  {"faces", level.faces},
                                  {"unprojected", level.unprojected},
                                  {"folded_faces", level.folded_faces},
                                  {"seconds", level.seconds}});
            }
            out["levels"] = levels;
            out["max_abs_field_at_vertices"] = report.residual.max;
            out["mean_abs_field_at_vertices"] = report.residual.mean;
            if (!options.refine.save_hierarchy.empty())
            {
                out["hierarchy"] = options.refine.save_hierarchy;
            }
        }
        out["vertices"] = written.vertex_count();
        out["faces"] = written.face_count();
        out["components"] = topo.components;
        out["boundary_loops"] = topo.boundary_loops;
        out["euler_characteristic"] = topo.euler_characteristic;
        out["manifold"] = topo.is_oriented_manifold();
        out["closed"] = topo.is_closed();
        out["cells_visited"] = result.stats.cells_visited;
        out["surface_cells"] = result.stats.surface_cells;
        out["undefined_cells"] = result.stats.undefined_cells;
        out["degenerate_triangles"] = result.stats.degenerate_triangles;
        out["degenerate_kept"] = result.stats.degenerate_kept;
        out["field_evaluations"] = result.stats.field_evaluations;
        out["dense"] = result.stats.dense;
        add_run_report(out, timings);
        std::printf("%s\n", out.dump(2).c_str());
        return;
    }
    if (global.quiet)
    {
        return;
    }
    std::printf("%s (%s) -> %s\n", options.input.c_str(),
                std::string(to_string(scene.kind)).c_str(), options.output.c_str());
    for (const LoadedScan& scan : arguments.scans())
    {
        print_row("scan", scan.path + ": " + std::to_string(scan.samples) + " samples" +
                              (scan.estimated_normals ? " (normals estimated)" : " (surfels)"));
    }
    const Vec3d size = grid.box.size();
    print_row("cell", format_number(grid.cell) + " (grid " + std::to_string(grid.grid.cells[0]) +
                          " x " + std::to_string(grid.grid.cells[1]) + " x " +
                          std::to_string(grid.grid.cells[2]) + " over a box of " +
                          format_number(size.x()) + " x " + format_number(size.y()) + " x " +
                          format_number(size.z()) + ")");
    if (semi)
    {
        print_row("marching cubes", std::to_string(result.mesh.face_count()) + " faces");
        print_base_mesh(*semi->base);
        for (const RefineLevelStats& level : semi->refinement.levels)
        {
            print_row("level " + std::to_string(level.level),
                      std::to_string(level.faces) + " faces, " + std::to_string(level.unprojected) +
                          " vertices left unprojected, " + std::to_string(level.folded_faces) +
                          " folded faces");
        }
        print_row("|f| at the vertices", "max " + format_number(report.residual.max) + ", mean " +
                                             format_number(report.residual.mean) +
                                             " (where the field is defined)");
        if (!options.refine.save_hierarchy.empty())
        {
            print_row("hierarchy", options.refine.save_hierarchy + " (" +
                                       std::to_string(semi->hierarchy.level_count()) + " levels)");
        }
    }
    print_row("vertices", std::to_string(written.vertex_count()));
    print_row("faces", std::to_string(written.face_count()));
    print_row("components", std::to_string(topo.components));
    print_row("boundary loops", std::to_string(topo.boundary_loops));
    print_row("Euler characteristic", std::to_string(topo.euler_characteristic));
    print_row("degenerate triangles",
              describe_degenerate(result.stats.degenerate_triangles, result.stats.degenerate_kept) +
                  " in marching cubes");
    print_timings(timings);
    for (const LoadedScan& scan : arguments.scans())
    {
        warn_unoriented(scan.path, scan.unoriented);
        warn_isolated(scan.path, scan.isolated, scan.copies, scan.off_surface);
    }
}

} // namespace

void register_model(CLI::App& app, const GlobalOptions& global)
{
    auto options = std::make_shared<ModelCommandOptions>();
    CLI::App* cmd = app.add_subcommand(
        "model",
        "Level 2 modeling: builds a scene of scans, primitives and operators (Boolean, blend, "
        "offset, shell, morph, transforms; paper §4.2) and polygonizes it with marching cubes, "
        "or with the semi-regular mesh of §5");
    cmd->add_option("scene", options->input,
                    "A scene expression, e.g. 'difference(scan(\"bunny.ply\"), sphere([0,0.1,0], "
                    "0.03))', or a file: a scene file (any extension but a point format's; "
                    "scans resolve against its folder) or a scan (.ply, .xyz, ...)")
        ->required();
    cmd->add_option("-o,--output", options->output, "Output mesh (.ply, .obj or .off)")->required();
    add_scene_command_options(*cmd, options->scene);
    CLI::Option* semi = cmd->add_flag(
        "--semi-regular", options->semi_regular,
        "Polygonize with the semi-regular multiresolution mesh (§5) instead of marching cubes: "
        "the marching-cubes mesh simplified to a base mesh, then refined by 1-to-4 splits with "
        "every new vertex projected onto the scene's surface, to --levels J");
    std::vector<CLI::Option*> refine = add_level_options(
        *cmd, options->refine,
        "With --semi-regular: refine exactly to level J (0 = the base mesh only; default " +
            std::to_string(default_scene_levels) + ")");
    refine.push_back(
        add_base_faces_option(*cmd, options->refine.semi_regular)
            ->description(
                "With --semi-regular: faces of the base mesh (default: the "
                "marching-cubes mesh's faces / 16, within [max(8 per component, 200), 80000])"));
    for (CLI::Option* option : refine)
    {
        option->needs(semi);
    }
    std::string functions;
    const std::string summary = scene_function_summary();
    std::size_t start = 0;
    while (start < summary.size())
    {
        const std::size_t end = summary.find('\n', start);
        functions += "  " + summary.substr(start, end - start) + "\n";
        start = end == std::string::npos ? summary.size() : end + 1;
    }
    cmd->footer(
        "Scene language (see include/pointform/implicit/scene.h): `let name = expr` "
        "bindings, # comments, and a final expression; vectors [x, y, z]; keyword "
        "arguments name = value. Functions:\n" +
        functions);
    cmd->callback([options, &global] { run_model(*options, global); });
}

} // namespace pointform::cli
