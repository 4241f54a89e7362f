// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "scene_input.h"

#include "pointform/core/error.h"
#include "pointform/io/io.h"

#include "options.h"

#include <cmath>
#include <cstdio>
#include <sstream>
#include <utility>

namespace pointform::cli {
namespace {

Aabb parse_bounds(const std::string& text)
{
    std::istringstream in(text);
    std::array<double, 6> v{};
    for (std::size_t i = 0; i < v.size(); ++i)
    {
        char comma = ',';
        if (!(in >> v[i]) || (i + 1 < v.size() && !(in >> comma)) || comma != ',' ||
            !std::isfinite(v[i]))
        {
            throw CLI::ValidationError("--bounds",
                                       "expected six finite numbers "
                                       "xmin,ymin,zmin,xmax,ymax,zmax, got '" +
                                           text + "'");
        }
    }
    if (!(in >> std::ws).eof())
    {
        throw CLI::ValidationError("--bounds",
                                   "expected six numbers xmin,ymin,zmin,xmax,ymax,zmax, "
                                   "got '" +
                                       text + "'");
    }
    Aabb box;
    box.min = Vec3d(v[0], v[1], v[2]);
    box.max = Vec3d(v[3], v[4], v[5]);
    if (!(box.min.array() < box.max.array()).all())
    {
        throw CLI::ValidationError("--bounds",
                                   "each minimum must be below its maximum, got '" + text + "'");
    }
    return box;
}

} // namespace

void add_scene_command_options(CLI::App& cmd, SceneCommandOptions& options)
{
    auto* resolution = cmd.add_option("--resolution", options.grid.resolution,
                                      "Cells along the longest side of the polygonized box")
                           ->check(CLI::Range(2, 1000000));
    cmd.add_option("--cell", options.grid.cell,
                   "Cell size in the input's units (default: 0.4 of the smallest median "
                   "influence radius of the scans, or the longest side / 128 without scans)")
        ->check(CLI::PositiveNumber)
        ->excludes(resolution);
    cmd.add_option_function<std::string>(
        "--bounds",
        [&options](const std::string& text) { options.grid.bounds = parse_bounds(text); },
        "Box to polygonize, xmin,ymin,zmin,xmax,ymax,zmax (default: the scene's "
        "bounds; required when the scene is unbounded, e.g. a half_space in a union)");
    add_fit_option(cmd, options.scans.field.fit,
                   "Local surfaces of the scans' fields: quadric, blend, centroid or raw (see "
                   "`mc`)");
    add_surfel_input_options(cmd, options.scans.surfels);
    cmd.add_flag("--ascii", options.ascii, "Write ascii PLY instead of binary");
    cmd.add_flag("--json", options.json, "Print the report as JSON");
}

namespace {

ScanOptions with_progress(ScanOptions options, const ProgressCallback& progress)
{
    options.surfels.progress = progress;
    return options;
}

} // namespace

SceneArguments::SceneArguments(const SceneCommandOptions& options, const ProgressCallback& progress)
    : scans_(with_progress(options.scans, progress))
{}

} // namespace pointform::cli
