// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// What `pointform reconstruct`, `pointform remesh` and `model --semi-regular` share once the
// library has made the semi-regular mesh (polygonize/reconstruct.h): writing the finest level
// (and the hierarchy), and the per-level report.

#pragma once

#include "pointform/geometry/mesh_topology.h"
#include "pointform/geometry/multires_mesh.h"
#include "pointform/polygonize/base_mesh.h"
#include "pointform/polygonize/reconstruct.h"

#include "common.h"
#include "options.h"

#include <nlohmann/json.hpp>

#include <string>

namespace pointform::cli {

/// \brief Writes the finest level to `output` (format by extension) and, if asked, the
/// hierarchy, as one OutputTransaction: both files or neither, and pre-existing files keep
/// their bytes when a write fails.
void write_semi_regular(const std::string& output, const SemiRegularCommandOptions& options,
                        const MultiresMesh& hierarchy);

/// A semi-regular mesh as written, and its finest level's topology.
struct SemiRegularOutput
{
    SemiRegularReport report;
    MeshTopology topology;
};

/// \brief Writes the output (write_semi_regular), lapping "write" in `timings`, and measures
/// the finest level's topology.
[[nodiscard]] SemiRegularOutput write_and_measure(SemiRegularReport report,
                                                  const SemiRegularCommandOptions& options,
                                                  const std::string& output, Timings& timings);

/// \brief The JSON report: the library's `report` (report_json()) with the input, the output,
/// the hierarchy file if one was written, and the output's topology.
[[nodiscard]] nlohmann::json semi_regular_json(nlohmann::json report, const SemiRegularOutput& run,
                                               const SemiRegularCommandOptions& options,
                                               const std::string& input, const std::string& output);

/// \brief Prints the per-level table (print_refinement), the output's counts and topology, and
/// the hierarchy file if one was written.
void print_semi_regular(const SemiRegularOutput& run, const SemiRegularCommandOptions& options);

/// Prints the automatic base mesh's stats as rows.
void print_base_mesh(const BaseMeshStats& stats);

/// Prints the sampling density, the per-level table and why refinement stopped.
void print_refinement(const SemiRegularReport& report);

} // namespace pointform::cli
