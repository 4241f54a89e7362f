// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "scene_input.h"

#include "pointform/core/error.h"
#include "pointform/io/io.h"

#include "common.h"
#include "options.h"

#include <cmath>
#include <cstdio>
#include <sstream>
#include <utility>

namespace pointform::cli {
namespace {} // namespace

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
        [&options](const std::string& text) { options.grid.bounds = parse_box(text, "--bounds"); },
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
