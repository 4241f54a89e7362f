// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include "pointform/core/progress.h"
#include "pointform/core/types.h"
#include "pointform/geometry/aabb.h"
#include "pointform/hermite/surfels.h"
#include "pointform/report/report_json.h" // format_number

#include <CLI/CLI.hpp>
#include <nlohmann/json_fwd.hpp>

#include <chrono>
#include <string>
#include <utility>
#include <vector>

namespace pointform::cli {

/// Options every subcommand shares.
struct GlobalOptions
{
    int threads = 0;    ///< 0 = all cores
    bool quiet = false; ///< no progress, no summary on stdout except requested JSON
};

/// \brief Renders progress on stderr when it is a terminal and a stage has taken more than a
/// second; silent when stderr is piped or --quiet is given.
class TerminalProgress
{
public:
    explicit TerminalProgress(bool enabled);
    ~TerminalProgress();
    TerminalProgress(const TerminalProgress&) = delete;
    TerminalProgress& operator=(const TerminalProgress&) = delete;

    /// The callback to hand to library options.
    [[nodiscard]] const ProgressCallback& callback() const { return callback_; }
    /// Clears the progress line, if one is shown.
    void clear();

private:
    bool enabled_;
    bool shown_ = false;
    std::string stage_;
    std::chrono::steady_clock::time_point stage_start_;
    ProgressCallback callback_;
};

/// \brief Wall-clock stage timings.
class Timings
{
public:
    void lap(const std::string& stage);
    void add(const std::string& stage, double seconds);
    [[nodiscard]] const std::vector<std::pair<std::string, double>>& stages() const
    {
        return stages_;
    }
    [[nodiscard]] double total() const;

private:
    std::vector<std::pair<std::string, double>> stages_;
    std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

/// \brief Adds what every JSON report ends with: "timings_s" (each stage and the total),
/// "threads", "parallel" (parallel_stats() of the run) and "peak_rss_bytes".
void add_run_report(nlohmann::json& out, const Timings& timings);

/// \brief Prints the "seconds" row: each stage, then the total.
void print_timings(const Timings& timings);

/// \brief Peak resident memory of this process so far, in bytes.
[[nodiscard]] std::size_t peak_rss_bytes();

/// \brief Parses "XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX" (six finite numbers, each minimum below its
/// maximum) for `option`. \throw CLI::ValidationError naming the option
[[nodiscard]] Aabb parse_box(const std::string& text, const std::string& option);

/// \brief Parses "A,B" into two finite numbers for `option`; `expected` describes them.
/// \throw CLI::ValidationError naming the option
[[nodiscard]] std::pair<double, double> parse_pair(const std::string& text,
                                                   const std::string& option,
                                                   const std::string& expected);

/// \brief Parses "X,Y,Z" into a vector. \throw CLI::ValidationError on malformed input.
[[nodiscard]] Vec3d parse_vec3(const std::string& text, const std::string& what);

/// \brief Prints a one-line JSON-free summary row "label: value" aligned for humans.
void print_row(const std::string& label, const std::string& value);

/// \brief The marching-cubes triangles of next to zero area and what became of them, for
/// reports: "N (F flipped, K kept; none dropped)".
[[nodiscard]] std::string describe_degenerate(std::size_t degenerate, std::size_t kept);

/// \brief Where the surfels' normals came from, for the "samples" row: " (surfels)",
/// " (normals estimated)", or that they face the depth image's sensor.
[[nodiscard]] std::string describe_normals(const SurfelsFromSamples& input);

/// \brief A sensor's position for reports: "sensor at (x, y, z)".
[[nodiscard]] std::string describe_sensor(const Vec3d& sensor);

/// \brief Registers the subcommands; each is defined in its own cmd_<verb>.cpp.
void register_info(CLI::App& app, const GlobalOptions& global);
void register_normals(CLI::App& app, const GlobalOptions& global);
void register_sample(CLI::App& app, const GlobalOptions& global);
void register_mc(CLI::App& app, const GlobalOptions& global);
void register_render(CLI::App& app, const GlobalOptions& global);
void register_distance(CLI::App& app, const GlobalOptions& global);
void register_model(CLI::App& app, const GlobalOptions& global);
void register_morph(CLI::App& app, const GlobalOptions& global);
void register_lod(CLI::App& app, const GlobalOptions& global);
void register_export(CLI::App& app, const GlobalOptions& global);
void register_texture(CLI::App& app, const GlobalOptions& global);
void register_deform(CLI::App& app, const GlobalOptions& global);
void register_reconstruct(CLI::App& app, const GlobalOptions& global);
void register_remesh(CLI::App& app, const GlobalOptions& global);
void register_view(CLI::App& app, const GlobalOptions& global);

} // namespace pointform::cli
