// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/core/error.h"
#include "pointform/core/parallel.h"
#include "pointform/io/io.h"
#include "pointform/polygonize/reconstruct.h"

#include "common.h"
#include "options.h"
#include "semi_regular.h"

#include <nlohmann/json.hpp>

#include <cstdio>
#include <memory>

namespace pointform::cli {
namespace {

struct RemeshCommandOptions
{
    std::string input;
    std::string output;
    RemeshOptions remesh; ///< its semi_regular is refine.semi_regular's
    SemiRegularCommandOptions refine;
};

void run_remesh(const RemeshCommandOptions& options, const GlobalOptions& global)
{
    set_thread_count(global.threads);
    TerminalProgress progress(!global.quiet && !options.refine.json);
    Timings timings;
    const TriMesh mesh = read_mesh(options.input);
    try
    {
        check_remesh_input(mesh);
    }
    catch (const InvalidInput& e)
    {
        throw InvalidInput(options.input + ": " + e.what());
    }
    timings.lap("read");
    RemeshOptions remesh_options = options.remesh;
    remesh_options.semi_regular = options.refine.semi_regular;
    remesh_options.progress = progress.callback();
    RemeshReport report = remesh(mesh, remesh_options);
    for (const auto& [stage, seconds] : report.stage_seconds)
    {
        timings.add(stage, seconds);
    }
    const BaseMeshStats base = *report.semi_regular.base;
    nlohmann::json report_figures;
    if (options.refine.json)
        report_figures = report_json(report, remesh_options);
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
    print_row("input mesh", std::to_string(mesh.face_count()) + " faces, " +
                                std::to_string(mesh.vertex_count()) + " vertices");
    print_row("surfels", std::to_string(run.report.sample_count) +
                             " (the vertices with area-weighted normals, and " +
                             std::to_string(report.area_surfels) +
                             " area-uniform samples with face normals)");
    print_base_mesh(base);
    print_semi_regular(run, options.refine);
    print_timings(timings);
}

} // namespace

void register_remesh(CLI::App& app, const GlobalOptions& global)
{
    auto options = std::make_shared<RemeshCommandOptions>();
    CLI::App* cmd = app.add_subcommand(
        "remesh",
        "Irregular mesh -> semi-regular multiresolution mesh (paper §6, Fig. 13): its vertices "
        "and area-uniform samples become surfels (level 2), the mesh itself is decimated to the "
        "base mesh, which is refined on their field as `pointform reconstruct` does");
    cmd->add_option("input", options->input,
                    "Input mesh: an oriented 2-manifold (.ply, .obj, .off)")
        ->required();
    cmd->add_option("-o,--output", options->output, "Output mesh (.ply, .obj or .off)")->required();
    add_base_faces_option(*cmd, options->refine.semi_regular)
        ->description(
            "Faces of the base mesh, decimated from the input (default: a quarter of "
            "its faces, within [200, 20000])");
    add_refine_options(*cmd, options->refine);
    cmd->add_option("--samples", options->remesh.surfels.samples,
                    "Area-uniform samples added to the vertices (default: as many as vertices)");
    cmd->add_option("--seed", options->remesh.surfels.seed, "Seed of the area-uniform samples")
        ->capture_default_str();
    add_k_option(*cmd, options->remesh.surfels.k,
                 "Neighbours of each surfel for its influence radius");
    add_radius_scale_option(*cmd, options->remesh.surfels.radius_scale,
                            "Factor on the influence radius (distance to the k-th neighbour)");
    add_fit_option(*cmd, options->remesh.fit, "Local surfaces of the field (see `pointform mc`)");
    cmd->callback([options, &global] { run_remesh(*options, global); });
}

} // namespace pointform::cli
