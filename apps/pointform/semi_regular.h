// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// What `pointform reconstruct` and `pointform remesh` share: from a base mesh M0 on a point
// field, refinement to a semi-regular hierarchy (§5.2), its stopping rule (§5.2.4), writing the
// finest level (and the hierarchy), and the per-level report.

#pragma once

#include "pointform/geometry/mesh_topology.h"
#include "pointform/geometry/multires_mesh.h"
#include "pointform/implicit/point_field.h"
#include "pointform/polygonize/base_mesh.h"
#include "pointform/polygonize/refine.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json_fwd.hpp>

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

namespace pointform::cli {

/// The level cap of the refinement when --levels is not given.
inline constexpr std::size_t default_max_level = 6;
/// The largest --levels accepted.
inline constexpr long long max_levels_option = 8;

/// Options of the refinement part, shared by reconstruct and remesh.
struct SemiRegularOptions
{
    std::optional<long long> base_faces; ///< --base-faces N (automatic base mesh)
    std::optional<long long> levels;     ///< --levels J: refine exactly to J
    std::string predictor = "midpoint";
    int relax = RefineOptions{}.relax_iterations; ///< --relax N: relaxation rounds per level
    std::string relaxation = "across";            ///< --relaxation across|umbrella
    std::string stop = "auto";                    ///< --stop auto|paper
    std::string save_hierarchy;
    bool ascii = false;
    bool json = false;
};

/// Adds --levels, --stop, --predictor, --relax, --relaxation, --save-hierarchy, --ascii and
/// --json.
void add_refine_options(CLI::App& cmd, SemiRegularOptions& options);
/// Adds --levels (with `levels_help`), --predictor, --relax, --relaxation and --save-hierarchy.
/// \return the options added
std::vector<CLI::Option*> add_level_options(CLI::App& cmd, SemiRegularOptions& options,
                                            const std::string& levels_help);
/// \brief The refinement options that --predictor, --relax and --relaxation ask for.
[[nodiscard]] RefineOptions refine_options_of(const SemiRegularOptions& options,
                                              ProgressCallback progress);
/// Adds --base-faces. \return the option, for excludes()
CLI::Option* add_base_faces_option(CLI::App& cmd, SemiRegularOptions& options);

/// \brief The automatic base-face target for `intermediate`: --base-faces (checked: at least 1
/// and at most the intermediate mesh's faces) or default_base_faces() with `share`; without
/// --levels and with the automatic stop, that default is fitted to the vertex budget
/// `samples` (fit_base_faces_to_budget) when `samples` > 0. `coarsening`: that of the
/// intermediate mesh's grid (intermediate_grid()).
/// \throw InvalidInput with the option's name
[[nodiscard]] std::size_t base_face_target(const SemiRegularOptions& options,
                                           const TriMesh& intermediate,
                                           std::size_t share = default_base_share,
                                           std::size_t samples = 0, double coarsening = 1.0);

/// \brief Refuses, before anything is allocated, a level whose F0·4^J faces would not fit in
/// memory (check_memory(): the cgroup limit or MemAvailable) or in 32-bit indices.
/// \throw InvalidInput saying how much it would need
void check_refinement_memory(std::size_t base_faces, std::size_t level);

/// \brief About how many bytes refining `base_faces` faces to `level` needs (256 per face of
/// that level).
[[nodiscard]] double estimate_refinement_bytes(std::size_t base_faces, std::size_t level);

/// \brief The deepest level ≤ `cap` whose faces fit in memory (at least 0).
[[nodiscard]] std::size_t affordable_level(std::size_t base_faces, std::size_t cap);

/// The refinement and what it did.
struct SemiRegularResult
{
    MultiresMesh hierarchy;
    RefineReport report; ///< report.initial_* describe the base mesh M0
    double base_seconds = 0.0;
    std::size_t base_unprojected = 0;
    bool exact_levels = false;    ///< --levels J: refined exactly to J
    std::size_t level_cap = 0;    ///< the cap used without --levels
    bool cap_from_memory = false; ///< the cap was lowered to fit in memory
    std::string stop_reason;      ///< why it stopped, in words
    double diagonal = 0.0;        ///< of the samples' bounding box
    std::size_t sample_count = 0;
    std::string predictor;
    std::string relaxation; ///< "across" or "umbrella", with the rounds per level
    int relax_rounds = 0;
    /// A level that stalled is measured but not kept: four times the faces for next to nothing.
    /// Its stats, when that happened.
    std::optional<RefineLevelStats> dropped;
};

/// \brief Refines `base` on `field` (whose surfels are the samples the distances are measured
/// from): exactly to --levels J, or until the stop rule of --stop (refine(), StopRule) says so or
/// the cap is reached.
[[nodiscard]] SemiRegularResult refine_semi_regular(const TriMesh& base, const PointField& field,
                                                    const SemiRegularOptions& options,
                                                    const ProgressCallback& progress);

/// \brief Writes the finest level to `output` (format by extension) and, if asked, the
/// hierarchy, as one OutputTransaction: both files or neither, and pre-existing files keep
/// their bytes when a write fails.
void write_semi_regular(const std::string& output, const SemiRegularOptions& options,
                        const MultiresMesh& hierarchy);

class Timings;
class TerminalProgress;

/// What reconstruct and remesh do once they have a base mesh, and what came of it.
struct SemiRegularOutput
{
    SemiRegularResult result;
    MeshTopology topology; ///< of the finest level, as written
};

/// \brief Refines `base` (refine_semi_regular), writes the output (write_semi_regular), lapping
/// "refinement" and "write" in `timings`, and measures the finest level's topology.
[[nodiscard]] SemiRegularOutput refine_and_write(const TriMesh& base, const PointField& field,
                                                 const SemiRegularOptions& options,
                                                 const std::string& output, double base_seconds,
                                                 std::size_t base_unprojected, Timings& timings,
                                                 TerminalProgress& progress);

/// \brief The JSON report's shared part: the refinement (refinement_json), input, output, the
/// hierarchy file if one was written, and the output's topology.
[[nodiscard]] nlohmann::json semi_regular_json(const SemiRegularOutput& run,
                                               const SemiRegularOptions& options,
                                               const std::string& input, const std::string& output);

/// \brief Prints the per-level table (print_refinement), the output's counts and topology, and
/// the hierarchy file if one was written.
void print_semi_regular(const SemiRegularOutput& run, const SemiRegularOptions& options);

/// \brief Smallest angle of any triangle, mean of the per-triangle smallest angles and the
/// share below 20°, degrees.
struct AngleStats
{
    double min_degrees = 0.0;
    double mean_min_degrees = 0.0;
    double share_below_20 = 0.0;
};
[[nodiscard]] AngleStats angle_stats(const TriMesh& mesh);

/// JSON of the automatic base mesh's stats.
[[nodiscard]] nlohmann::json base_mesh_json(const BaseMeshStats& stats);
/// Prints the automatic base mesh's stats as rows.
void print_base_mesh(const BaseMeshStats& stats);

/// JSON of the refinement: sampling density, its definition, levels (0 = base), stop.
[[nodiscard]] nlohmann::json refinement_json(const SemiRegularResult& result);
/// Prints the sampling density, the per-level table and why refinement stopped.
void print_refinement(const SemiRegularResult& result);

} // namespace pointform::cli
