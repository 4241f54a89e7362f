// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/core/error.h"
#include "pointform/core/parallel.h"
#include "pointform/geometry/mesh_topology.h"
#include "pointform/implicit/operators.h"
#include "pointform/io/io.h"
#include "pointform/polygonize/marching_cubes.h"

#include "common.h"
#include "output_transaction.h"
#include "scene_input.h"

#include <nlohmann/json.hpp>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <system_error>

namespace pointform::cli {
namespace {

struct MorphCommandOptions
{
    std::string from;
    std::string to;
    std::string prefix;
    int steps = 10;
    SceneCommandOptions scene;
};

struct MorphStep
{
    double t = 0.0;
    std::string path;
    std::size_t vertices = 0;
    std::size_t faces = 0;
    MeshTopology topology;
    double seconds = 0.0;
};

/// PREFIX_000.ply ... PREFIX_N.ply, with at least three digits.
std::string step_path(const std::string& prefix, int step, int steps)
{
    const int width = std::max(3, static_cast<int>(std::to_string(steps).size()));
    std::string number = std::to_string(step);
    number.insert(0, static_cast<std::size_t>(width) - number.size(), '0');
    return prefix + "_" + number + ".ply";
}

void run_morph(const MorphCommandOptions& options, const GlobalOptions& global)
{
    set_thread_count(global.threads);
    TerminalProgress progress(!global.quiet && !options.scene.json);
    Timings timings;
    SceneCommandOptions scene = options.scene;
    scene.scans.field.far_grid =
        false; // a morph's surface lies deep inside a member: exact inside values
    SceneArguments arguments(scene, progress.callback());
    const SceneArguments::Loaded from = arguments.load(options.from);
    const SceneArguments::Loaded to = arguments.load(options.to);
    // Refuses fields whose bounds do not overlap before anything is polygonized.
    (void)make_morph(from.field, to.field, 0.0);
    timings.lap(arguments.scans().empty() ? "scenes" : "scenes + surfels");

    Aabb box = from.field->bounds();
    const Aabb to_box = to.field->bounds();
    box.extend(to_box.min);
    box.extend(to_box.max);
    const SceneGrid grid = choose_scene_grid(box, options.scene.grid, arguments.scans());

    std::vector<MorphStep> steps;
    OutputTransaction written;
    for (int i = 0; i <= options.steps; ++i)
    {
        const auto start = std::chrono::steady_clock::now();
        MorphStep step;
        step.t = static_cast<double>(i) / static_cast<double>(options.steps);
        step.path = step_path(options.prefix, i, options.steps);
        const auto field = make_morph(from.field, to.field, step.t);
        MarchingCubesResult result =
            marching_cubes(*field, grid.grid, {.progress = progress.callback()});
        if (result.mesh.face_count() == 0)
        {
            throw Error("marching cubes made no triangles at t = " + format_number(step.t) +
                        " (check --bounds, try a smaller --cell or a larger --radius-scale)");
        }
        written.stage(step.path, [&](const std::filesystem::path& path) {
            write_mesh(path, result.mesh, {.ascii = options.scene.ascii});
        });
        step.vertices = result.mesh.vertex_count();
        step.faces = result.mesh.face_count();
        step.topology = analyze_topology(result.mesh);
        step.seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        steps.push_back(std::move(step));
    }
    written.commit(); // every step, or none
    timings.lap("marching cubes + write");
    progress.clear();

    if (options.scene.json)
    {
        nlohmann::json out;
        out["from"] = options.from;
        out["from_kind"] = std::string(to_string(from.kind));
        out["to"] = options.to;
        out["to_kind"] = std::string(to_string(to.kind));
        out["cell"] = grid.cell;
        out["grid_cells"] = grid.grid.cells;
        out["bounds"] = {{"min", {grid.box.min.x(), grid.box.min.y(), grid.box.min.z()}},
                         {"max", {grid.box.max.x(), grid.box.max.y(), grid.box.max.z()}}};
        nlohmann::json scans = nlohmann::json::array();
        for (const LoadedScan& scan : arguments.scans())
        {
            scans.push_back({{"path", scan.path},
                             {"samples", scan.samples},
                             {"estimated_normals", scan.estimated_normals}});
        }
        out["scans"] = scans;
        nlohmann::json list = nlohmann::json::array();
        for (const MorphStep& step : steps)
        {
            list.push_back({{"t", step.t},
                            {"output", step.path},
                            {"vertices", step.vertices},
                            {"faces", step.faces},
                            {"components", step.topology.components},
                            {"boundary_loops", step.topology.boundary_loops},
                            {"euler_characteristic", step.topology.euler_characteristic},
                            {"manifold", step.topology.is_oriented_manifold()},
                            {"seconds", step.seconds}});
        }
        out["steps"] = list;
        add_run_report(out, timings);
        std::printf("%s\n", out.dump(2).c_str());
        return;
    }
    if (global.quiet)
    {
        return;
    }
    std::printf("%s (%s) -> %s (%s): %d steps\n", options.from.c_str(),
                std::string(to_string(from.kind)).c_str(), options.to.c_str(),
                std::string(to_string(to.kind)).c_str(), options.steps);
    print_row("cell", format_number(grid.cell) + " (grid " + std::to_string(grid.grid.cells[0]) +
                          " x " + std::to_string(grid.grid.cells[1]) + " x " +
                          std::to_string(grid.grid.cells[2]) + ")");
    for (const MorphStep& step : steps)
    {
        print_row("t = " + format_number(step.t),
                  step.path + ": " + std::to_string(step.faces) + " faces, " +
                      std::to_string(step.topology.components) +
                      (step.topology.components == 1 ? " component, " : " components, ") +
                      std::to_string(step.topology.boundary_loops) + " boundary loops, Euler " +
                      std::to_string(step.topology.euler_characteristic) + ", " +
                      format_number(step.seconds) + " s");
    }
    print_timings(timings);
}

} // namespace

void register_morph(CLI::App& app, const GlobalOptions& global)
{
    auto options = std::make_shared<MorphCommandOptions>();
    CLI::App* cmd = app.add_subcommand(
        "morph",
        "Metamorphosis (paper §4.2): writes PREFIX_000.ply ... PREFIX_N.ply, the surfaces of "
        "(1 - t) f_A + t f_B for t = i/N, all on one grid over both inputs' bounds");
    cmd->add_option("from", options->from, "A: a scan, a scene file or a scene expression")
        ->required();
    cmd->add_option("to", options->to, "B: a scan, a scene file or a scene expression")->required();
    cmd->add_option("-o,--output", options->prefix,
                    "Output prefix: PREFIX_000.ply ... PREFIX_N.ply")
        ->required();
    cmd->add_option("--steps", options->steps, "N: the sequence has N + 1 meshes, t = 0 ... 1")
        ->capture_default_str()
        ->check(CLI::Range(1, 10000));
    add_scene_command_options(*cmd, options->scene);
    cmd->callback([options, &global] { run_morph(*options, global); });
}

} // namespace pointform::cli
