// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/core/error.h"
#include "pointform/core/parallel.h"
#include "pointform/hermite/surfels.h"
#include "pointform/io/io.h"

#include "common.h"
#include "large_pages.h"
#include "options.h"
#include "output_transaction.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdio>
#include <memory>

namespace pointform::cli {
namespace {

struct NormalsCommandOptions
{
    std::string input;
    std::string output;
    SurfelOptions surfels;
    bool ascii = false;
    bool json = false;
};

void run_normals(const NormalsCommandOptions& options, const GlobalOptions& global)
{
    set_thread_count(global.threads);
    ask_for_huge_pages(); // its large arrays are dense: fewer page faults (large_pages.cpp)
    SurfelOptions surfel_options = options.surfels;

    TerminalProgress progress(!global.quiet && !options.json);
    surfel_options.progress = progress.callback();
    Timings timings;
    PointCloud cloud = read_point_cloud(options.input);
    cloud.normals.clear(); // estimated afresh; input normals play no part
    timings.lap("read");

    const SurfelResult result = compute_surfels(std::move(cloud), surfel_options);
    for (const auto& [stage, seconds] : result.stage_seconds)
        timings.add(stage, seconds);
    write_output(options.output, [&](const std::filesystem::path& path) {
        write_point_cloud(path, result.surfels, {.ascii = options.ascii});
    });
    timings.lap("write");
    progress.clear();

    const RadiusSummary& radius = result.radius;
    const auto& orientation = result.orientation;

    if (options.json)
    {
        nlohmann::json out;
        out["input"] = options.input;
        out["output"] = options.output;
        out["points"] = result.surfels.size();
        out["k"] = options.surfels.k;
        out["components"] = orientation.components;
        out["flipped"] = orientation.flipped;
        out["crease_refits"] = result.crease_refits;
        out["towards_sensor"] = result.towards_sensor;
        out["thin_parts"] = orientation.thin_parts;
        out["thin_part_turned"] = orientation.thin_part_turned;
        out["degenerate"] = result.degenerate;
        out["inherited"] = orientation.inherited;
        out["unoriented"] = orientation.unoriented.size();
        out["isolated"] = result.isolated.size();
        out["copies"] = result.copies.size();
        out["unoriented_indices"] = std::vector<std::uint32_t>(
            orientation.unoriented.begin(),
            orientation.unoriented.begin() + static_cast<std::ptrdiff_t>(std::min<std::size_t>(
                                                 orientation.unoriented.size(), 100)));
        out["radius"] = {{"min", radius.min}, {"median", radius.median}, {"max", radius.max}};
        add_run_report(out, timings);
        std::printf("%s\n", out.dump(2).c_str());
        return;
    }
    if (global.quiet)
        return;
    std::printf("%s -> %s\n", options.input.c_str(), options.output.c_str());
    print_row("points", std::to_string(result.surfels.size()));
    print_row("components", std::to_string(orientation.components));
    if (result.towards_sensor)
        print_row("orientation", "towards the " + describe_sensor(*result.surfels.sensor) +
                                     " (the input is a depth image seen from it)");
    print_row("normals flipped", std::to_string(orientation.flipped));
    if (options.surfels.sharp_creases)
        print_row("crease refits",
                  std::to_string(result.crease_refits) +
                      (result.crease_refits == 0 ? " (none at a crease, or a noisy cloud)"
                                                 : " (normals refitted to their own face)"));
    if (orientation.thin_parts > 0)
        print_row("thin parts", std::to_string(orientation.thin_parts) +
                                    " (faces apart by less than the noise; " +
                                    std::to_string(orientation.thin_part_turned) +
                                    " normals turned away from the other face)");
    print_row("degenerate (inherited)", std::to_string(result.degenerate));
    print_row("unoriented", std::to_string(orientation.unoriented.size()));
    print_row("isolated", std::to_string(result.isolated.size()) +
                              (result.isolated.empty() ? "" : " (alone far from the rest; kept)"));
    print_row("copies", std::to_string(result.copies.size()) +
                            (result.copies.empty()
                                 ? ""
                                 : " (at the place of an earlier sample; its normal and radius)"));
    print_row("radius min/median/max", format_number(radius.min) + " / " +
                                           format_number(radius.median) + " / " +
                                           format_number(radius.max));
    print_timings(timings);
    if (!orientation.unoriented.empty())
        std::fprintf(stderr,
                     "pointform: warning: %zu samples could not be oriented (first index %u); "
                     "their normals are written as zero\n",
                     orientation.unoriented.size(), orientation.unoriented.front());
}

} // namespace

void register_normals(CLI::App& app, const GlobalOptions& global)
{
    auto options = std::make_shared<NormalsCommandOptions>();
    CLI::App* cmd = app.add_subcommand(
        "normals",
        "Level 1 -> 2: estimate, consistently orient and give an influence radius to every "
        "sample (paper §4); writes PLY with x y z nx ny nz radius");
    cmd->add_option("input", options->input,
                    "Point set or mesh: .ply .xyz .pts .csv .txt .pwn .off .obj .pcd .las")
        ->required();
    cmd->add_option("-o,--output", options->output, "Output surfels (.ply, or .xyz)")->required();
    add_k_option(*cmd, options->surfels.k,
                 "Neighbours of each point, besides itself, for PCA and the radius");
    cmd->add_option("--graph-k", options->surfels.graph_k,
                    "Neighbours a point in the orientation graph (0 = min(k, 10))")
        ->capture_default_str();
    add_radius_scale_option(
        *cmd, options->surfels.radius_scale,
        "Factor on the automatic influence radius (distance to the k-th neighbour)");
    add_radius_regions_option(
        *cmd, options->surfels.radius_regions,
        "JSON file of balls and boxes that set the radius: {\"regions\": [{\"ball\": "
        "{\"center\": [x,y,z], \"radius\": R}, \"set\": r}, {\"box\": {\"min\": "
        "[..], \"max\": [..]}, \"scale\": s}]}");
    add_orient_option(*cmd, options->surfels.orient, options->surfels.orient_target,
                      "auto (towards the sensor of a depth image, an organized PCD with its "
                      "VIEWPOINT; mst otherwise), mst (consistent, outward on closed surfaces), "
                      "none, flip (mst, then inward), towards:X,Y,Z (a viewpoint) or along:X,Y,Z "
                      "(a direction)");
    add_sharp_creases_flag(*cmd, options->surfels.sharp_creases);
    add_rule_option(*cmd, options->surfels.rule,
                    "MST propagation rule: hoppe (robust to noise) or reflection (thin walls "
                    "and creases in clean data)");
    cmd->add_flag("--ascii", options->ascii, "Write ascii PLY instead of binary");
    cmd->add_flag("--json", options->json,
                  "Print the report (counts, stage timings, peak memory) as JSON");
    cmd->callback([options, &global] { run_normals(*options, global); });
}

} // namespace pointform::cli
