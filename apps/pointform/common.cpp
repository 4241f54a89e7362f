// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "common.h"

#include "pointform/core/parallel.h"

#include <nlohmann/json.hpp>

#include <sys/resource.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>

namespace pointform::cli {

TerminalProgress::TerminalProgress(bool enabled) : enabled_(enabled && ::isatty(STDERR_FILENO) == 1)
{
    callback_ = [this](std::string_view stage, double fraction) {
        if (!enabled_)
            return true;
        const auto now = std::chrono::steady_clock::now();
        if (stage != stage_)
        {
            clear();
            stage_ = std::string(stage);
            stage_start_ = now;
        }
        // Only work that lasts more than a second earns a progress line.
        if (now - stage_start_ < std::chrono::seconds(1))
            return true;
        std::fprintf(stderr, "\r%-28s %5.1f%%", stage_.c_str(), 100.0 * fraction);
        std::fflush(stderr);
        shown_ = true;
        return true;
    };
}

TerminalProgress::~TerminalProgress()
{
    clear();
}

void TerminalProgress::clear()
{
    if (shown_)
    {
        std::fprintf(stderr, "\r%40s\r", "");
        std::fflush(stderr);
        shown_ = false;
    }
}

void Timings::lap(const std::string& stage)
{
    const auto now = std::chrono::steady_clock::now();
    stages_.emplace_back(stage, std::chrono::duration<double>(now - last_).count());
    last_ = now;
}

void Timings::add(const std::string& stage, double seconds)
{
    stages_.emplace_back(stage, seconds);
    last_ = std::chrono::steady_clock::now();
}

double Timings::total() const
{
    double sum = 0.0;
    for (const auto& [stage, seconds] : stages_)
        sum += seconds;
    return sum;
}

std::size_t peak_rss_bytes()
{
    rusage usage{};
    ::getrusage(RUSAGE_SELF, &usage);
    return static_cast<std::size_t>(usage.ru_maxrss) * 1024U; // Linux reports KiB
}

Vec3d parse_vec3(const std::string& text, const std::string& what)
{
    std::istringstream in(text);
    Vec3d v;
    char comma1 = 0;
    char comma2 = 0;
    if (!(in >> v.x() >> comma1 >> v.y() >> comma2 >> v.z()) || comma1 != ',' || comma2 != ',' ||
        !(in >> std::ws).eof() || !v.allFinite())
        throw CLI::ValidationError(what, "expected three finite numbers X,Y,Z, got '" + text + "'");
    return v;
}

std::string describe_normals(const SurfelsFromSamples& input)
{
    if (!input.estimated_normals)
        return " (surfels)";
    return input.towards_sensor
               ? " (normals estimated, facing the sensor the depth image was seen from)"
               : " (normals estimated)";
}

std::string describe_sensor(const Vec3d& sensor)
{
    return "sensor at (" + format_number(sensor.x()) + ", " + format_number(sensor.y()) + ", " +
           format_number(sensor.z()) + ")";
}

std::string describe_degenerate(std::size_t degenerate, std::size_t kept)
{
    return std::to_string(degenerate) + " (" + std::to_string(degenerate - kept) + " flipped, " +
           std::to_string(kept) + " kept; none dropped)";
}

void print_row(const std::string& label, const std::string& value)
{
    std::printf("  %-22s %s\n", (label + ":").c_str(), value.c_str());
}

void add_run_report(nlohmann::json& out, const Timings& timings)
{
    nlohmann::json stages = nlohmann::json::object();
    for (const auto& [stage, seconds] : timings.stages())
    {
        stages[stage] = seconds;
    }
    stages["total"] = timings.total();
    out["timings_s"] = stages;
    out["threads"] = thread_count();
    // What the parallel runtime did in this process: shows the work really was split in blocks
    // run by several threads (tests compare outputs across --threads with it).
    const ParallelStats parallel = parallel_stats();
    out["parallel"] = {{"loops", parallel.loops},
                       {"blocks", parallel.blocks},
                       {"multi_block_loops", parallel.multi_block_loops},
                       {"max_team_threads", parallel.max_team_threads},
                       {"max_threads_per_loop", parallel.max_threads_per_loop}};
    out["peak_rss_bytes"] = peak_rss_bytes();
}

void print_timings(const Timings& timings)
{
    std::string times;
    for (const auto& [stage, seconds] : timings.stages())
    {
        times += (times.empty() ? "" : ", ") + stage + " " + format_number(seconds);
    }
    print_row("seconds", times + " (total " + format_number(timings.total()) + ")");
}

Aabb parse_box(const std::string& text, const std::string& option)
{
    std::istringstream in(text);
    std::array<double, 6> v{};
    for (std::size_t i = 0; i < v.size(); ++i)
    {
        char comma = ',';
        if (!(in >> v[i]) || (i + 1 < v.size() && !(in >> comma)) || comma != ',' ||
            !std::isfinite(v[i]))
        {
            throw CLI::ValidationError(option,
                                       "expected six finite numbers "
                                       "xmin,ymin,zmin,xmax,ymax,zmax, got '" +
                                           text + "'");
        }
    }
    if (!(in >> std::ws).eof())
    {
        throw CLI::ValidationError(option,
                                   "expected six numbers xmin,ymin,zmin,xmax,ymax,zmax, "
                                   "got '" +
                                       text + "'");
    }
    Aabb box;
    box.min = Vec3d(v[0], v[1], v[2]);
    box.max = Vec3d(v[3], v[4], v[5]);
    if (!(box.min.array() < box.max.array()).all())
    {
        throw CLI::ValidationError(option,
                                   "each minimum must be below its maximum, got '" + text + "'");
    }
    return box;
}

std::pair<double, double> parse_pair(const std::string& text, const std::string& option,
                                     const std::string& expected)
{
    std::istringstream in(text);
    double a = 0.0;
    double b = 0.0;
    char comma = 0;
    if (!(in >> a >> comma >> b) || comma != ',' || !(in >> std::ws).eof() || !std::isfinite(a) ||
        !std::isfinite(b))
        throw CLI::ValidationError(option, "expected " + expected + ", got '" + text + "'");
    return {a, b};
}

} // namespace pointform::cli
