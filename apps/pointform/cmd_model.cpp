// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/core/error.h"
#include "pointform/core/parallel.h"
#include "pointform/geometry/mesh_topology.h"
#include "pointform/implicit/scene.h"
#include "pointform/io/io.h"
#include "pointform/polygonize/marching_cubes.h"

#include "common.h"
#include "scene_input.h"

#include <nlohmann/json.hpp>

#include <cstdio>
#include <memory>

namespace pointform::cli {
namespace {

struct ModelCommandOptions
{
    std::string input;
    std::string output;
    SceneCommandOptions scene;
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

    const SceneGrid grid =
        choose_scene_grid(scene.field->bounds(), options.scene, arguments.scans());
    MarchingCubesResult result =
        marching_cubes(*scene.field, grid.grid, {.progress = progress.callback()});
    timings.lap("marching cubes");
    if (result.mesh.face_count() == 0)
    {
        throw Error(
            "marching cubes made no triangles: the scene's surface does not cross the "
            "polygonized box, or the field is undefined there (check --bounds, try a "
            "smaller --cell or a larger --radius-scale)");
    }
    write_mesh(options.output, result.mesh, {.ascii = options.scene.ascii});
    timings.lap("write");
    const MeshTopology topo = analyze_topology(result.mesh);
    progress.clear();

    if (options.scene.json)
    {
        nlohmann::json out;
        out["input"] = options.input;
        out["input_kind"] = to_string(scene.kind);
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
        out["fit"] = options.scene.fit;
        out["bounds"] = box_json(grid.box);
        out["cell"] = grid.cell;
        out["grid_cells"] = grid.grid.cells;
        out["vertices"] = result.mesh.vertex_count();
        out["faces"] = result.mesh.face_count();
        out["components"] = topo.components;
        out["boundary_loops"] = topo.boundary_loops;
        out["euler_characteristic"] = topo.euler_characteristic;
        out["manifold"] = topo.is_oriented_manifold();
        out["closed"] = topo.is_closed();
        out["cells_visited"] = result.stats.cells_visited;
        out["surface_cells"] = result.stats.surface_cells;
        out["undefined_cells"] = result.stats.undefined_cells;
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
    std::printf("%s (%s) -> %s\n", options.input.c_str(), to_string(scene.kind),
                options.output.c_str());
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
    print_row("vertices", std::to_string(result.mesh.vertex_count()));
    print_row("faces", std::to_string(result.mesh.face_count()));
    print_row("components", std::to_string(topo.components));
    print_row("boundary loops", std::to_string(topo.boundary_loops));
    print_row("Euler characteristic", std::to_string(topo.euler_characteristic));
    print_timings(timings);
    for (const LoadedScan& scan : arguments.scans())
    {
        warn_unoriented(scan.path, scan.unoriented);
    }
}

} // namespace

void register_model(CLI::App& app, const GlobalOptions& global)
{
    auto options = std::make_shared<ModelCommandOptions>();
    CLI::App* cmd = app.add_subcommand(
        "model",
        "Level 2 modeling: builds a scene of scans, primitives and operators (Boolean, blend, "
        "offset, shell, morph, transforms; paper §4.2) and polygonizes it with marching cubes");
    cmd->add_option("scene", options->input,
                    "A scene expression, e.g. 'difference(scan(\"bunny.ply\"), sphere([0,0.1,0], "
                    "0.03))', or a file: a scene file (any extension but a point format's; "
                    "scans resolve against its folder) or a scan (.ply, .xyz, ...)")
        ->required();
    cmd->add_option("-o,--output", options->output, "Output mesh (.ply, .obj or .off)")->required();
    add_scene_command_options(*cmd, options->scene);
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
