// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/core/error.h"
#include "pointform/core/parallel.h"
#include "pointform/io/hierarchy.h"
#include "pointform/io/io.h"
#include "pointform/metrics/sampling_density.h"

#include "common.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>

namespace pointform::cli {
namespace {

struct InfoOptions
{
    std::string input;
    bool json = false;
};

/// The sampling density (measure_sampling_density()), or zeros for fewer than two distinct
/// points.
SamplingDensity sampling_density_of(const PointCloud& cloud, const ProgressCallback& progress)
{
    if (cloud.size() < 2)
        return {};
    try
    {
        return measure_sampling_density(cloud, progress);
    }
    catch (const InvalidInput&) // every point coincides
    {
        return {};
    }
}

nlohmann::json vec_json(const Vec3d& v)
{
    return nlohmann::json::array({v.x(), v.y(), v.z()});
}

std::string vec_text(const Vec3d& v)
{
    return format_number(v.x()) + " " + format_number(v.y()) + " " + format_number(v.z());
}

/// A hierarchy file's summary: its levels (`pointform lod` extracts them).
void run_hierarchy_info(const InfoOptions& options, const GlobalOptions& global)
{
    const MultiresMesh mesh = read_hierarchy(options.input);
    nlohmann::json levels = nlohmann::json::array();
    for (std::size_t l = 0; l < mesh.level_count(); ++l)
        levels.push_back(
            {{"level", l}, {"vertices", mesh.vertex_count(l)}, {"faces", mesh.face_count(l)}});
    if (options.json)
    {
        const nlohmann::json out = {
            {"file", options.input},
            {"format", "pointform hierarchy version " + std::to_string(hierarchy_format_version)},
            {"origin", vec_json(mesh.origin())},
            {"levels", levels}};
        std::printf("%s\n", out.dump(2).c_str());
        return;
    }
    if (global.quiet)
        return;
    std::printf("%s\n", options.input.c_str());
    print_row("format", "pointform hierarchy version " + std::to_string(hierarchy_format_version));
    for (const auto& level : levels)
        print_row("level " + level["level"].dump(),
                  level["vertices"].dump() + " vertices, " + level["faces"].dump() + " faces");
    if (mesh.origin() != Vec3d::Zero())
        print_row("storage origin", vec_text(mesh.origin()));
}

void run_info(const InfoOptions& options, const GlobalOptions& global)
{
    set_thread_count(global.threads);
    if (is_hierarchy_file(options.input))
    {
        run_hierarchy_info(options, global);
        return;
    }
    TerminalProgress progress(!global.quiet && !options.json);
    const ReadResult read = read_geometry(options.input);
    const PointCloud& cloud = read.points;
    const Aabb box = cloud.bounds();
    const SamplingDensity density = sampling_density_of(cloud, progress.callback());
    progress.clear();

    std::vector<std::string> attributes = {"positions"};
    if (cloud.has_normals())
        attributes.emplace_back("normals");
    if (cloud.has_colors())
        attributes.emplace_back("colors");
    if (cloud.has_radii())
        attributes.emplace_back("radii");
    if (!read.triangles.empty())
        attributes.emplace_back("faces");

    if (options.json)
    {
        nlohmann::json out;
        out["file"] = options.input;
        out["format"] = read.description;
        out["points"] = cloud.size();
        out["faces"] = read.triangles.size();
        out["dropped_points"] = read.dropped_points;
        out["attributes"] = attributes;
        out["origin"] = vec_json(cloud.origin);
        if (!box.is_empty())
            out["bounding_box"] = {{"min", vec_json(box.min)},
                                   {"max", vec_json(box.max)},
                                   {"size", vec_json(box.size())},
                                   {"diagonal", box.diagonal()}};
        out["nearest_neighbor_distance"] = {{"mean", density.mean}, {"median", density.median}};
        std::printf("%s\n", out.dump(2).c_str());
        return;
    }
    if (global.quiet)
        return;
    std::printf("%s\n", options.input.c_str());
    print_row("format", read.description);
    print_row("points", std::to_string(cloud.size()));
    if (read.dropped_points > 0)
        print_row("dropped (non-finite)", std::to_string(read.dropped_points));
    if (!read.triangles.empty())
        print_row("faces", std::to_string(read.triangles.size()));
    std::string list;
    for (const auto& a : attributes)
        list += (list.empty() ? "" : ", ") + a;
    print_row("attributes", list);
    if (!box.is_empty())
    {
        print_row("bounding box min", vec_text(box.min));
        print_row("bounding box max", vec_text(box.max));
        print_row("size", vec_text(box.size()));
        print_row("diagonal", format_number(box.diagonal()));
    }
    if (cloud.origin != Vec3d::Zero())
        print_row("storage origin", vec_text(cloud.origin));
    print_row("nn distance mean", format_number(density.mean));
    print_row("nn distance median", format_number(density.median));
}

} // namespace

void register_info(CLI::App& app, const GlobalOptions& global)
{
    auto options = std::make_shared<InfoOptions>();
    CLI::App* cmd = app.add_subcommand(
        "info", "Print point count, bounding box, sampling density and attributes of a file");
    cmd->add_option("input", options->input,
                    "Point set or mesh: .ply .xyz .pts .csv .txt .pwn .off .obj .pcd .las; or a "
                    "hierarchy file (.pfh)")
        ->required();
    cmd->add_flag("--json", options->json, "Print the summary as JSON");
    cmd->callback([options, &global] { run_info(*options, global); });
}

} // namespace pointform::cli
