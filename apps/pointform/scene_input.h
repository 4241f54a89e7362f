// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include "pointform/implicit/point_field.h"
#include "pointform/implicit/scans.h"
#include "pointform/implicit/scene.h"
#include "pointform/polygonize/scene_mesh.h"

#include <CLI/CLI.hpp>

#include <cstddef>
#include <memory>
#include <string>
#include <vector>

namespace pointform::cli {

/// \brief The options `pointform model` and `pointform morph` share.
struct SceneCommandOptions
{
    /// --bounds, --cell, --resolution.
    SceneGridOptions grid;
    /// How scans become fields: their surfels and point field. Scans answer deep-inside queries
    /// from their far grid (PointFieldOptions::far_grid); the morph command turns it off, since
    /// a morph takes inside values as distances.
    ScanOptions scans;
    bool ascii = false;
    bool json = false;
};

void add_scene_command_options(CLI::App& cmd, SceneCommandOptions& options);

/// \brief Turns scene arguments into fields; scans are shared between the arguments
/// (ScanLoading).
class SceneArguments
{
public:
    SceneArguments(const SceneCommandOptions& options, const ProgressCallback& progress);

    using Loaded = LoadedScene;

    /// \brief A scan file, a scene file or a scene expression (load_scene_argument()).
    [[nodiscard]] Loaded load(const std::string& argument)
    {
        return load_scene_argument(argument, scans_);
    }

    [[nodiscard]] const std::vector<LoadedScan>& scans() const { return scans_.scans(); }

private:
    ScanLoading scans_;
};

} // namespace pointform::cli
