// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/core/error.h"
#include "pointform/core/memory.h"
#include "pointform/core/parallel.h"
#include "pointform/io/io.h"
#include "pointform/metrics/hausdorff.h"
#include "pointform/metrics/surface_sampling.h"

#include "common.h"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

namespace pointform::cli {
namespace {

struct DistanceCommandOptions
{
    std::string a;
    std::string b;
    std::size_t samples = 100000;
    std::uint64_t seed = 1;
    std::vector<double> fscore; ///< --fscore: thresholds, fractions of the diagonal
    bool json = false;
};

/// Reads a shape: a mesh if the file has faces, else a point set (a mesh file without faces is
/// a point set too).
TriMesh read_shape(const std::string& path)
{
    ReadResult read = read_geometry(path);
    if (read.points.empty())
        throw InvalidInput(path + ": the file has no points");
    TriMesh shape;
    shape.vertices = std::move(read.points);
    shape.triangles = std::move(read.triangles);
    if (shape.face_count() > 0 && !(surface_area(shape) > 0.0))
        throw InvalidInput(path + ": every triangle of the mesh has zero area");
    return shape;
}

nlohmann::json shape_json(const std::string& file, const TriMesh& shape, std::size_t samples)
{
    nlohmann::json out = report_json(shape, samples);
    out["file"] = file;
    return out;
}

void print_table(const char* title, const DistanceSummary& s)
{
    std::printf("  %s\n", title);
    std::printf("    %-16s %14s %14s %14s\n", "", "A -> B", "B -> A", "symmetric");
    const auto row = [](const char* label, double x, double y, double z) {
        std::printf("    %-16s %14s %14s %14s\n", label, format_number(x).c_str(),
                    format_number(y).c_str(), format_number(z).c_str());
    };
    row("max (Hausdorff)", s.a_to_b.max, s.b_to_a.max, s.symmetric.max);
    row("mean", s.a_to_b.mean, s.b_to_a.mean, s.symmetric.mean);
    row("rms", s.a_to_b.rms, s.b_to_a.rms, s.symmetric.rms);
    row("p50", s.a_to_b.p50, s.b_to_a.p50, s.symmetric.p50);
    row("p90", s.a_to_b.p90, s.b_to_a.p90, s.symmetric.p90);
    row("p99", s.a_to_b.p99, s.b_to_a.p99, s.symmetric.p99);
    std::printf("    %-16s %14s\n", "chamfer", format_number(s.chamfer).c_str());
}

std::string shape_text(const TriMesh& shape, std::size_t samples)
{
    if (shape.face_count() == 0)
        return "point set, " + std::to_string(shape.vertex_count()) + " points";
    return "mesh, " + std::to_string(shape.vertex_count()) + " vertices, " +
           std::to_string(shape.face_count()) + " faces, " +
           std::to_string(compare_sample_count(shape, samples)) + " samples";
}

/// Bytes the comparison needs per sample of each mesh (its position, distance, closest-point
/// state and the sorted copy for the percentiles; measured: 40 at --samples 4000000).
constexpr double bytes_per_distance_sample = 64.0;

/// About how many bytes `compare` needs for `samples` samples on each of two meshes.
double estimate_distance_bytes(std::size_t samples)
{
    return 2.0 * bytes_per_distance_sample * static_cast<double>(samples);
}

void run_distance(const DistanceCommandOptions& options, const GlobalOptions& global)
{
    check_memory(estimate_distance_bytes(options.samples),
                 "--samples " + std::to_string(options.samples), "use fewer --samples");
    set_thread_count(global.threads);
    TerminalProgress progress(!global.quiet && !options.json);
    Timings timings;
    const TriMesh a = read_shape(options.a);
    const TriMesh b = read_shape(options.b);
    timings.lap("read");
    const DistanceComparison result = compare(a, b,
                                              {.samples = options.samples,
                                               .seed = options.seed,
                                               .include_vertices = true,
                                               .fscore_thresholds = options.fscore,
                                               .progress = progress.callback()});
    timings.lap("measure");
    progress.clear();

    if (options.json)
    {
        nlohmann::json out;
        out["a"] = shape_json(options.a, a, options.samples);
        out["b"] = shape_json(options.b, b, options.samples);
        out["samples_per_mesh"] = options.samples;
        out["seed"] = options.seed;
        out.update(report_json(result));
        add_run_report(out, timings);
        std::printf("%s\n", out.dump(2).c_str());
        return;
    }
    if (global.quiet)
        return;
    std::printf("A: %s (%s)\n", options.a.c_str(), shape_text(a, options.samples).c_str());
    std::printf("B: %s (%s)\n", options.b.c_str(), shape_text(b, options.samples).c_str());
    print_row("bounding box diagonal", format_number(result.diagonal) + " (of A and B together)");
    print_row("Hausdorff", format_number(result.absolute.hausdorff) + " (" +
                               format_number(result.relative.hausdorff) + " of the diagonal)");
    print_row("Chamfer", format_number(result.absolute.chamfer) + " (" +
                             format_number(result.relative.chamfer) + " of the diagonal)");
    print_table("absolute (input units)", result.absolute);
    print_table("relative to the bounding box diagonal", result.relative);
    for (const FScore& f : result.fscores)
        print_row("F-score at " + format_number(100.0 * f.threshold) + "%",
                  format_number(f.f) + " (precision " + format_number(f.precision) + ": B within " +
                      format_number(f.absolute_threshold) + " of A; recall " +
                      format_number(f.recall) + ": A within it of B)");
    print_timings(timings);
}

} // namespace

void register_distance(CLI::App& app, const GlobalOptions& global)
{
    auto options = std::make_shared<DistanceCommandOptions>();
    CLI::App* cmd = app.add_subcommand(
        "distance",
        "Measure two shapes against each other as MeshLab's Metro does: one-sided and symmetric "
        "Hausdorff (max), mean, RMS, Chamfer (mean A->B + mean B->A) and the 50/90/99th "
        "percentiles, absolute and relative to the diagonal of the bounding box of both");
    cmd->add_option("a", options->a,
                    "Shape A: a mesh (a file with faces: sampled area-uniformly, plus its "
                    "vertices, and measured against exactly, point to triangle) or a point set "
                    "(a file without faces, used as it is; measured against by nearest point)")
        ->required();
    cmd->add_option("b", options->b, "Shape B, as A")->required();
    cmd->add_option("--samples", options->samples,
                    "Random area-uniform samples on each mesh, besides its vertices")
        ->capture_default_str()
        ->check(CLI::PositiveNumber);
    cmd->add_option("--seed", options->seed, "Seed of the sampling")->capture_default_str();
    cmd->add_option("--fscore", options->fscore,
                    "F-score thresholds as fractions of the diagonal, e.g. 0.005,0.01: A is the "
                    "reference, B the reconstruction (precision: B's area-uniform samples "
                    "within the threshold of A; recall: A's within it of B; a mesh's vertices "
                    "count for the maxima only)")
        ->delimiter(',')
        ->check(CLI::PositiveNumber);
    cmd->add_flag("--json", options->json, "Print the statistics as JSON");
    cmd->callback([options, &global] { run_distance(*options, global); });
}

} // namespace pointform::cli
