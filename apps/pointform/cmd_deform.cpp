// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/core/error.h"
#include "pointform/core/parallel.h"
#include "pointform/io/hierarchy.h"
#include "pointform/io/io.h"
#include "pointform/multires/deformation.h"
#include "pointform/multires/details.h"
#include "pointform/multires/edit_file.h"
#include "pointform/multires/lattice.h"
#include "pointform/report/report_json.h"

#include "common.h"
#include "output_transaction.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdio>
#include <memory>
#include <string>

namespace pointform::cli {
namespace {

struct DeformOptions
{
    std::string input;
    std::string output;
    std::string mesh;
    std::string edit;
    std::string lattice;
    bool plain = false;
    bool ascii = false;
    bool json = false;
};

void run_deform(const DeformOptions& options, const GlobalOptions& global)
{
    set_thread_count(global.threads);
    Timings timings;
    MultiresMesh mesh = read_hierarchy(options.input);
    timings.lap("read");
    DeformRequest request;
    if (!options.edit.empty())
        request.edit = read_multires_edit(options.edit);
    else
        request.lattice = read_lattice(options.lattice);
    request.lattice_mode = options.plain ? LatticeMode::Plain : LatticeMode::Details;
    timings.lap("parse");
    const DeformOutcome outcome = deform_hierarchy(mesh, request);
    const DeformReport& report = outcome.deformation;
    const std::vector<DetailLevelStats>& details = outcome.details;
    const double diagonal = outcome.diagonal;
    timings.lap("deform");

    OutputTransaction outputs;
    outputs.stage(options.output,
                  [&](const std::filesystem::path& path) { write_hierarchy(path, mesh); });
    if (!options.mesh.empty())
        outputs.stage(options.mesh, [&](const std::filesystem::path& path) {
            write_mesh(path, mesh.level_mesh(mesh.finest_level()), {.ascii = options.ascii});
        });
    outputs.commit();
    timings.lap("write");

    if (options.json)
    {
        nlohmann::json out = report_json(outcome);
        out["input"] = options.input;
        out["output"] = options.output;
        if (!options.mesh.empty())
            out["mesh"] = options.mesh;
        add_run_report(out, timings);
        std::printf("%s\n", out.dump(2).c_str());
        return;
    }
    if (global.quiet)
        return;
    std::printf("%s -> %s: %s of level %zu, %s predictor\n", options.input.c_str(),
                options.output.c_str(), outcome.mode.c_str(), report.level,
                std::string(to_string(mesh.predictor())).c_str());
    if (!options.edit.empty())
    {
        print_row("region vertices", std::to_string(report.region_vertices));
        print_row("handle vertices", std::to_string(report.handle_vertices));
        print_row("solved vertices", std::to_string(report.free_vertices));
        if (report.unconstrained_vertices > 0)
            print_row("unconstrained (kept)", std::to_string(report.unconstrained_vertices));
    }
    print_row("largest move", format_number(report.largest_displacement) + " (" +
                                  format_number(100.0 * report.largest_displacement / diagonal) +
                                  "% of the diagonal)");
    std::printf("  %5s %12s %12s %14s %14s\n", "level", "vertices", "moved", "largest move",
                "normal details");
    for (const LevelMotion& motion : report.levels)
    {
        const auto stats = std::find_if(details.begin(), details.end(),
                                        [&](const auto& s) { return s.level == motion.level; });
        const std::string share =
            stats == details.end() ? "-" : format_number(100.0 * stats->normal_share) + "%";
        std::printf("  %5zu %12zu %12zu %14s %14s\n", motion.level, motion.vertices, motion.moved,
                    format_number(motion.largest).c_str(), share.c_str());
    }
    if (!options.mesh.empty())
        std::printf("level %zu -> %s\n", mesh.finest_level(), options.mesh.c_str());
    print_timings(timings);
}

} // namespace

void register_deform(CLI::App& app, const GlobalOptions& global)
{
    auto options = std::make_shared<DeformOptions>();
    CLI::App* cmd = app.add_subcommand(
        "deform",
        "Multiresolution editing of a hierarchy (.pfh): an edit of one level (handles, targets, "
        "region; a bi-Laplacian solve) or a free-form deformation lattice, the finer levels "
        "following by their details (docs/deform.md)");
    cmd->add_option("input", options->input, "Hierarchy file (.pfh)")->required();
    cmd->add_option("-o,--output", options->output, "Deformed hierarchy (.pfh)")->required();
    cmd->add_option("--mesh", options->mesh,
                    "Also write the deformed finest level as a mesh (.ply, .obj or .off)");
    auto* edit = cmd->add_option("--edit", options->edit,
                                 "Edit file (JSON): level, handles and targets, region");
    auto* lattice = cmd->add_option("--lattice", options->lattice,
                                    "Lattice file (JSON): a Bernstein free-form deformation");
    auto* plain = cmd->add_flag("--plain", options->plain,
                                "With --lattice: move every vertex of every level through the "
                                "lattice (plain FFD) instead of letting the details ride along");
    edit->excludes(lattice);
    plain->needs(lattice);
    cmd->add_flag("--ascii", options->ascii, "Write ascii PLY instead of binary");
    cmd->add_flag("--json", options->json, "Print the report as JSON");
    cmd->callback([options, edit, lattice, &global] {
        if (edit->count() == 0 && lattice->count() == 0)
            throw InvalidInput("deform: give --edit EDIT.json or --lattice LATTICE.json");
        run_deform(*options, global);
    });
}

} // namespace pointform::cli
