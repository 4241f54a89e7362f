// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include "pointform/hermite/surfels.h"
#include "pointform/implicit/point_field.h"

#include <CLI/CLI.hpp>

#include <string>

namespace pointform::cli {

/// \brief The options every command that turns samples into a field shares.
struct SurfelInputOptions
{
    std::size_t k = 16;
    double radius_scale = default_field_radius_scale;
    std::string radius_regions;
    bool reestimate = false;
};

void add_surfel_input_options(CLI::App& cmd, SurfelInputOptions& options);

/// \brief What load_surfels did.
struct SurfelInput
{
    PointCloud surfels;
    bool estimated_normals = false; ///< normals were estimated and oriented here
    bool estimated_radii = false;   ///< radii were computed here
    std::size_t components = 0;     ///< orientation components (when estimated)
    std::size_t unoriented = 0;
};

/// \brief Reads samples and makes them surfels: raw points get normals estimated and oriented
/// as `pointform normals` does; surfels (a file with normals) keep theirs, and get automatic
/// radii when the file has none. --radius-scale and --radius-regions apply to computed radii.
[[nodiscard]] SurfelInput load_surfels(const std::string& path, const SurfelInputOptions& options,
                                       const ProgressCallback& progress);

/// \brief Warns on stderr that `unoriented` samples of `path` (no usable normal) were left out;
/// says nothing when there were none.
void warn_unoriented(const std::string& path, std::size_t unoriented);

} // namespace pointform::cli
