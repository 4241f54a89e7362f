// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// The options several subcommands share, each declared once here and bound straight into the
// library's options structs (enums through a transform of their names), with the library's
// defaults.

#pragma once

#include "pointform/hermite/orientation.h"
#include "pointform/hermite/surfels.h"
#include "pointform/implicit/point_field.h"
#include "pointform/polygonize/reconstruct.h"

#include <CLI/CLI.hpp>

#include <cstddef>
#include <string>
#include <vector>

namespace pointform::cli {

/// -k: neighbours of each point, besides itself (3 to 1000).
CLI::Option* add_k_option(CLI::App& cmd, std::size_t& k, const std::string& help);

/// --radius-scale: the factor on the automatic influence radius (> 0).
CLI::Option* add_radius_scale_option(CLI::App& cmd, double& scale, const std::string& help);
/// --sharp-creases (SurfelOptions::sharp_creases).
CLI::Option* add_sharp_creases_flag(CLI::App& cmd, bool& sharp);

/// --radius-regions FILE: read into `regions` (read_radius_regions()) as the command line is
/// parsed.
CLI::Option* add_radius_regions_option(CLI::App& cmd, std::vector<RadiusRegion>& regions,
                                       const std::string& help);

/// --fit quadric|blend|centroid|raw.
CLI::Option* add_fit_option(CLI::App& cmd, PlaneFit& fit, const std::string& help);
/// `--rim-reach F` (PointFieldOptions::rim_reach), in (0, 1].
CLI::Option* add_rim_reach_option(CLI::App& cmd, double& rim_reach);

/// \brief --max-handle: the longest handle loop cut as topological noise, in median influence
/// radii (ReconstructOptions::max_handle; `reconstruct` and `mc`).
CLI::Option* add_max_handle_option(CLI::App& cmd, double& max_handle);

/// \brief A line of what cut_short_handles() did, for the commands' summaries.
[[nodiscard]] std::string describe_handle_cuts(const HandleCutReport& cuts, double radii);

/// --rule hoppe|reflection.
CLI::Option* add_rule_option(CLI::App& cmd, OrientationRule& rule, const std::string& help);

/// --orient auto|mst|none|flip|towards:X,Y,Z|along:X,Y,Z (parse_orient()), into `mode` and
/// `target` as the command line is parsed; a bad value is a usage error.
CLI::Option* add_orient_option(CLI::App& cmd, OrientMode& mode, Vec3d& target,
                               const std::string& help);

/// -k, --radius-scale, --radius-regions, --orient and --reestimate of the commands that turn
/// samples into a field (surfels_from_samples()).
void add_surfel_input_options(CLI::App& cmd, SurfelsFromSamplesOptions& options);

/// What reconstruct, remesh and `model --semi-regular` share besides the library's options.
struct SemiRegularCommandOptions
{
    SemiRegularOptions semi_regular;
    std::string save_hierarchy;
    bool ascii = false;
    bool json = false;
};

/// Adds --levels (with `levels_help`), --predictor, --relax, --relaxation and --save-hierarchy.
/// \return the options added
std::vector<CLI::Option*> add_level_options(CLI::App& cmd, SemiRegularCommandOptions& options,
                                            const std::string& levels_help);

/// Adds add_level_options(), --stop, --ascii and --json.
void add_refine_options(CLI::App& cmd, SemiRegularCommandOptions& options);

/// Adds --base-faces. \return the option, for excludes()
CLI::Option* add_base_faces_option(CLI::App& cmd, SemiRegularOptions& options);

} // namespace pointform::cli
