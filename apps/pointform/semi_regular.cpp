// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "semi_regular.h"

#include "pointform/core/error.h"
#include "pointform/core/memory.h"
#include "pointform/io/hierarchy.h"
#include "pointform/io/io.h"
#include "pointform/metrics/hausdorff.h"

#include "common.h"
#include "output_transaction.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <numbers>

namespace pointform::cli {
namespace {

/// Bytes a refinement needs per face of the level it makes: the hierarchy's positions (double)
/// and parent edges, the faces and edge vertices of the level below, the extracted output mesh,
/// the triangle BVH of the distance measurement and the per-vertex refinement state.
constexpr double bytes_per_refined_face = 256.0;

constexpr const char* sampling_density_definition =
    "median over the samples of the distance to the nearest other sample";
constexpr const char* robust_distance_definition =
    "mean of the smallest 95% of the distances from the samples to the mesh";
constexpr const char* hausdorff_definition =
    "one-sided Hausdorff distance: the largest distance from a sample to the mesh (exact "
    "closest point on the triangles)";

double faces_at_level(std::size_t base_faces, std::size_t level)
{
    return static_cast<double>(base_faces) * std::pow(4.0, static_cast<double>(level));
}

bool fits(std::size_t base_faces, std::size_t level)
{
    const double faces = faces_at_level(base_faces, level);
    return faces <= static_cast<double>(std::numeric_limits<std::uint32_t>::max()) &&
           fits_in_memory(estimate_refinement_bytes(base_faces, level));
}

std::string percent_of(double value, double diagonal)
{
    return diagonal > 0.0 ? format_number(100.0 * value / diagonal) + "%" : "-";
}

std::string stop_reason(const SemiRegularResult& r)
{
    const std::size_t finest = r.hierarchy.finest_level();
    const double last =
        r.report.levels.empty() ? r.report.initial_hausdorff : *r.report.levels.back().hausdorff;
    const double robust = r.report.levels.empty() ? r.report.initial_robust_distance
                                                  : *r.report.levels.back().robust_distance;
    if (r.report.stop_rule == StopRule::Automatic)
    {
        const double detail = r.report.levels.empty()
                                  ? r.report.initial_next_detail
                                  : r.report.levels.back().next_detail.value_or(0.0);
        switch (r.report.stop)
        {
            case RefineStop::SmallDetails:
                return "level " + std::to_string(finest + 1) + " would move its new vertices by " +
                       format_number(detail) + " on average, not more than the threshold " +
                       format_number(r.report.detail_threshold) +
                       " (a tenth of the field's residual at the samples, " +
                       format_number(r.report.field_residual) +
                       ", or a thousandth of the sampling density): level " +
                       std::to_string(finest) +
                       " is as close as the field allows (robust distance " +
                       format_number(robust) + ")";
            case RefineStop::NoisyDetails:
                return "level " + std::to_string(finest + 1) + " would move its new vertices by " +
                       format_number(detail) +
                       " on average, less than the field's residual at the samples (" +
                       format_number(r.report.field_residual) +
                       ") and not half as much as the level before: these details follow the "
                       "noise, so level " +
                       std::to_string(finest) + " is the output (robust distance " +
                       format_number(robust) + ")";
            case RefineStop::VertexBudget:
                return "level " + std::to_string(finest + 1) +
                       " would have more vertices than the budget of " +
                       std::to_string(r.report.vertex_budget) +
                       " (the number of samples), so level " + std::to_string(finest) +
                       " is the output (robust distance " + format_number(robust) + ")";
            default:
                break;
        }
    }
    const std::string distances = "Hausdorff " + format_number(last) + ", sampling density " +
                                  format_number(r.report.sampling_density);
    switch (r.report.stop)
    {
        case RefineStop::BelowSamplingDensity:
            return finest == 0
                       ? "the base mesh is already within the sampling density (" + distances + ")"
                       : "the Hausdorff distance from the samples fell below the sampling "
                         "density at level " +
                             std::to_string(finest) + " (" + distances + ")";
        case RefineStop::Stalled:
            return "level " + std::to_string(finest + 1) +
                   " lowered the Hausdorff distance by less than 5%, so it is not kept and level " +
                   std::to_string(finest) + " is the output (" + distances +
                   "): the samples still farther than the density lie where refinement cannot "
                   "reach (outliers, noise, beyond a hole's rim)";
        case RefineStop::LevelCap:
        case RefineStop::VertexBudget:
        case RefineStop::SmallDetails:
        case RefineStop::NoisyDetails:
            break;
    }
    return "reached the level cap " + std::to_string(r.level_cap) +
           (r.cap_from_memory ? " (the deepest level that fits in memory)"
                              : " (the default; --levels J refines further)") +
           " with the distance still above the sampling density (" + distances + ")";
}

nlohmann::json level_json(const RefineLevelStats& s, double diagonal)
{
    nlohmann::json out;
    out["level"] = s.level;
    out["faces"] = s.faces;
    out["vertices"] = s.vertices;
    out["new_vertices"] = s.new_vertices;
    out["hausdorff"] = s.hausdorff.value_or(0.0);
    out["hausdorff_relative"] = diagonal > 0.0 ? s.hausdorff.value_or(0.0) / diagonal : 0.0;
    out["mean_distance"] = s.mean_distance.value_or(0.0);
    out["robust_distance"] = s.robust_distance.value_or(0.0);
    out["p90_distance"] = s.p90_distance.value_or(0.0);
    if (s.next_detail)
    {
        out["next_detail"] = *s.next_detail;
    }
    out["fold_vertices"] = s.fold_vertices;
    out["folds_fixed_by_ven"] = s.folds_fixed_by_ven;
    out["folds_unresolved"] = s.folds_unresolved;
    out["unprojected"] = s.unprojected;
    out["relaxed"] = s.relaxed;
    out["relax_undone"] = s.relax_undone;
    out["folded_faces"] = s.folded_faces;
    out["seconds"] = s.seconds;
    return out;
}

CLI::Validator levels_range()
{
    return CLI::Validator(
        [](std::string& text) -> std::string {
            long long value = 0;
            try
            {
                std::size_t used = 0;
                value = std::stoll(text, &used);
                if (used != text.size())
                {
                    return "--levels must be an integer, not '" + text + "'";
                }
            }
            catch (const std::exception&)
            {
                return "--levels must be an integer, not '" + text + "'";
            }
            if (value < 0 || value > max_levels_option)
            {
                return "--levels must be between 0 and " + std::to_string(max_levels_option) +
                       " (each level has 4 times the faces of the one below: level 8 has 65536 "
                       "times the base mesh's), not " +
                       text;
            }
            return {};
        },
        "0.." + std::to_string(max_levels_option));
}

} // namespace

void add_refine_options(CLI::App& cmd, SemiRegularOptions& options)
{
    add_level_options(cmd, options,
                      "Refine exactly to level J (0 = the base mesh only); default: until the "
                      "--stop rule says so (at most level " +
                          std::to_string(default_max_level) + ")");
    cmd.add_option("--stop", options.stop,
                   "When refinement stops without --levels: auto (the default: while the next "
                   "level would move the mesh by more than a tenth of the field's residual at "
                   "the samples, and would have no more vertices than there are samples) or "
                   "paper (§5.2.4: until the largest distance from a sample is below the "
                   "sampling density)")
        ->capture_default_str()
        ->check(CLI::IsMember({"auto", "paper"}));
    cmd.add_flag("--ascii", options.ascii, "Write ascii PLY instead of binary");
    cmd.add_flag("--json", options.json, "Print the report as JSON");
}

std::vector<CLI::Option*> add_level_options(CLI::App& cmd, SemiRegularOptions& options,
                                            const std::string& levels_help)
{
    std::vector<CLI::Option*> added;
    added.push_back(cmd.add_option("--levels", options.levels, levels_help)->check(levels_range()));
    added.push_back(
        cmd.add_option("--predictor", options.predictor,
                       "Where a new edge vertex starts before its projection onto the surface: "
                       "midpoint, or butterfly (the displaced butterfly subdivision)")
            ->capture_default_str()
            ->check(CLI::IsMember({"midpoint", "butterfly"})));
    added.push_back(
        cmd.add_option("--relax", options.relax,
                       "Rounds of tangential relaxation of the new vertices per level (§5.2.3), "
                       "each followed by their re-projection; 0 keeps the projected predictions")
            ->capture_default_str()
            ->check(CLI::Range(0, 10)));
    added.push_back(
        cmd.add_option("--relaxation", options.relaxation,
                       "Which part of the umbrella move relaxation makes: across (the part "
                       "across the parent edge, which keeps the split ratio) or umbrella (all of "
                       "it, as in the paper)")
            ->capture_default_str()
            ->check(CLI::IsMember({"across", "umbrella"})));
    added.push_back(cmd.add_option("--save-hierarchy", options.save_hierarchy,
                                   "Also write every level as a hierarchy file (.pfh; extract "
                                   "levels with `pointform lod`)"));
    return added;
}

RefineOptions refine_options_of(const SemiRegularOptions& options, ProgressCallback progress)
{
    RefineOptions refine_options;
    refine_options.predictor = parse_predictor(options.predictor);
    refine_options.relax_iterations = options.relax;
    refine_options.relaxation = parse_relaxation(options.relaxation);
    refine_options.stop_rule = parse_stop_rule(options.stop);
    refine_options.progress = std::move(progress);
    return refine_options;
}

CLI::Option* add_base_faces_option(CLI::App& cmd, SemiRegularOptions& options)
{
    return cmd
        .add_option("--base-faces", options.base_faces,
                    "Faces of the automatic base mesh (default: the intermediate mesh's faces / "
                    "64, within [200, 20000])")
        ->check(CLI::Validator(
            [](std::string& text) -> std::string {
                try
                {
                    std::size_t used = 0;
                    if (std::stoll(text, &used) >= 1 && used == text.size())
                    {
                        return {};
                    }
                }
                catch (const std::exception&)
                {}
                return "--base-faces must be a whole number of faces, at least 1, not '" + text +
                       "'";
            },
            "N >= 1"));
}

std::size_t base_face_target(const SemiRegularOptions& options, const TriMesh& intermediate,
                             std::size_t share, std::size_t samples, double coarsening)
{
    if (!options.base_faces)
    {
        const std::size_t target = default_base_faces(intermediate, share, coarsening);
        if (samples == 0 || options.levels || parse_stop_rule(options.stop) != StopRule::Automatic)
        {
            return target;
        }
        return std::min(intermediate.face_count(), fit_base_faces_to_budget(target, samples));
    }
    const long long wanted = *options.base_faces;
    if (wanted < 1)
    {
        throw InvalidInput("--base-faces must be at least 1, not " + std::to_string(wanted));
    }
    if (static_cast<unsigned long long>(wanted) > intermediate.face_count())
    {
        throw InvalidInput("--base-faces " + std::to_string(wanted) +
                           " is larger than the intermediate (marching-cubes) mesh, which has " +
                           std::to_string(intermediate.face_count()) +
                           " faces; the base mesh simplifies it");
    }
    return static_cast<std::size_t>(wanted);
}

void check_refinement_memory(std::size_t base_faces, std::size_t level)
{
    const double faces = faces_at_level(base_faces, level);
    if (faces > static_cast<double>(std::numeric_limits<std::uint32_t>::max()))
    {
        throw InvalidInput("level " + std::to_string(level) + " of a base mesh of " +
                           std::to_string(base_faces) + " faces would have " +
                           format_number(faces) +
                           " faces, more than 32-bit indices allow; use fewer --levels or "
                           "--base-faces");
    }
    char what[160];
    std::snprintf(what, sizeof what,
                  "level %zu of a base mesh of %zu faces (%.4g faces at that level)", level,
                  base_faces, faces);
    check_memory(estimate_refinement_bytes(base_faces, level), what,
                 "use fewer --levels or --base-faces");
}

double estimate_refinement_bytes(std::size_t base_faces, std::size_t level)
{
    return bytes_per_refined_face * faces_at_level(base_faces, level);
}

std::size_t affordable_level(std::size_t base_faces, std::size_t cap)
{
    std::size_t level = 0;
    while (level < cap && fits(base_faces, level + 1))
    {
        ++level;
    }
    return level;
}

SemiRegularResult refine_semi_regular(const TriMesh& base, const PointField& field,
                                      const SemiRegularOptions& options,
                                      const ProgressCallback& progress)
{
    const PointCloud& samples = field.surfels();
    SemiRegularResult r;
    r.hierarchy = MultiresMesh(base);
    r.diagonal = samples.bounds().diagonal();
    r.sample_count = samples.size();
    r.predictor = options.predictor;
    r.relaxation = options.relaxation;
    r.relax_rounds = options.relax;
    RefineOptions refine_options = refine_options_of(options, progress);
    const std::size_t base_faces = base.face_count();
    if (options.levels)
    {
        const auto levels = static_cast<std::size_t>(*options.levels);
        check_refinement_memory(base_faces, levels);
        r.exact_levels = true;
        r.level_cap = levels;
        refine_options.stop_rule = StopRule::Exact;
        refine_options.max_level = levels;
        r.report = refine(r.hierarchy, field, samples, refine_options);
        r.report.stop = RefineStop::LevelCap;
        r.stop_reason = "--levels " + std::to_string(levels) + ": refined exactly to level " +
                        std::to_string(levels);
        return r;
    }
    r.level_cap = affordable_level(base_faces, default_max_level);
    r.cap_from_memory = r.level_cap < default_max_level;
    refine_options.max_level = r.level_cap;
    r.report = refine(r.hierarchy, field, samples, refine_options);
    r.dropped = r.report.dropped;
    r.stop_reason = stop_reason(r);
    return r;
}

void write_semi_regular(const std::string& output, const SemiRegularOptions& options,
                        const MultiresMesh& hierarchy)
{
    OutputTransaction transaction;
    transaction.stage(output, [&](const std::filesystem::path& path) {
        write_mesh(path, hierarchy.level_mesh(hierarchy.finest_level()), {.ascii = options.ascii});
    });
    if (!options.save_hierarchy.empty())
    {
        transaction.stage(options.save_hierarchy, [&](const std::filesystem::path& path) {
            write_hierarchy(path, hierarchy);
        });
    }
    transaction.commit(); // the mesh and the hierarchy, or neither
}

AngleStats angle_stats(const TriMesh& mesh)
{
    AngleStats stats;
    if (mesh.face_count() == 0)
    {
        return stats;
    }
    double smallest = 180.0;
    double sum = 0.0;
    std::size_t below = 0;
    for (const Triangle& t : mesh.triangles)
    {
        const Vec3d p[3] = {mesh.vertices.positions[t[0]].cast<double>(),
                            mesh.vertices.positions[t[1]].cast<double>(),
                            mesh.vertices.positions[t[2]].cast<double>()};
        double min_angle = 180.0;
        for (int k = 0; k < 3; ++k)
        {
            const Vec3d a = p[(k + 1) % 3] - p[k];
            const Vec3d b = p[(k + 2) % 3] - p[k];
            const double denom = a.norm() * b.norm();
            const double angle = denom > 0.0 ? std::acos(std::clamp(a.dot(b) / denom, -1.0, 1.0)) *
                                                   180.0 / std::numbers::pi
                                             : 0.0;
            min_angle = std::min(min_angle, angle);
        }
        smallest = std::min(smallest, min_angle);
        sum += min_angle;
        below += min_angle < 20.0 ? 1 : 0;
    }
    const auto faces = static_cast<double>(mesh.face_count());
    stats.min_degrees = smallest;
    stats.mean_min_degrees = sum / faces;
    stats.share_below_20 = static_cast<double>(below) / faces;
    return stats;
}

nlohmann::json base_mesh_json(const BaseMeshStats& stats)
{
    nlohmann::json out;
    out["input_faces"] = stats.input_faces;
    out["target_faces"] = stats.target_faces;
    out["faces"] = stats.faces;
    out["vertices"] = stats.vertices;
    out["min_angle_degrees"] = stats.min_angle_degrees;
    out["mean_min_angle_degrees"] = stats.mean_min_angle_degrees;
    out["share_below_20_degrees"] = stats.share_below_20_degrees;
    out["share_below_20_degrees_off_boundary"] = stats.share_below_20_degrees_off_boundary;
    out["smoothing_rounds"] = stats.smoothing_rounds;
    out["flips"] = stats.flips;
    out["boundary_tolerance"] = stats.boundary_tolerance;
    out["unprojected"] = stats.unprojected;
    out["max_vertex_move"] = stats.max_vertex_move;
    out["topology_kept"] = stats.topology_kept;
    out["topology_change"] = stats.topology_change;
    out["euler_characteristic"] = stats.topology_after.euler_characteristic;
    out["boundary_loops"] = stats.topology_after.boundary_loops;
    out["components"] = stats.topology_after.components;
    out["seconds"] = stats.seconds;
    return out;
}

void print_base_mesh(const BaseMeshStats& stats)
{
    print_row("base mesh", std::to_string(stats.faces) + " faces, " +
                               std::to_string(stats.vertices) + " vertices (target " +
                               std::to_string(stats.target_faces) + ", from " +
                               std::to_string(stats.input_faces) + " faces)");
    print_row("base min angle",
              format_number(stats.min_angle_degrees) + "° (mean of minima " +
                  format_number(stats.mean_min_angle_degrees) + "°; " +
                  format_number(100.0 * stats.share_below_20_degrees) +
                  "% of the triangles below 20°, " +
                  format_number(100.0 * stats.share_below_20_degrees_off_boundary) +
                  "% away from the boundary)");
    print_row("base topology",
              stats.topology_kept
                  ? "kept (Euler characteristic " +
                        std::to_string(stats.topology_after.euler_characteristic) + ", " +
                        std::to_string(stats.topology_after.boundary_loops) + " boundary loops, " +
                        std::to_string(stats.topology_after.components) + " components)"
                  : "CHANGED: " + stats.topology_change);
    print_row("base unprojected", std::to_string(stats.unprojected) + " vertices off f = 0");
}

nlohmann::json refinement_json(const SemiRegularResult& r)
{
    nlohmann::json out;
    out["samples"] = r.sample_count;
    out["sampling_density"] = r.report.sampling_density;
    out["sampling_density_definition"] = sampling_density_definition;
    out["hausdorff_definition"] = hausdorff_definition;
    out["diagonal"] = r.diagonal;
    nlohmann::json levels = nlohmann::json::array();
    nlohmann::json base;
    base["level"] = 0;
    base["faces"] = r.hierarchy.face_count(0);
    base["vertices"] = r.hierarchy.vertex_count(0);
    base["hausdorff"] = r.report.initial_hausdorff;
    base["hausdorff_relative"] = r.diagonal > 0.0 ? r.report.initial_hausdorff / r.diagonal : 0.0;
    base["mean_distance"] = r.report.initial_mean_distance;
    base["robust_distance"] = r.report.initial_robust_distance;
    base["p90_distance"] = r.report.initial_p90_distance;
    if (r.report.stop_rule == StopRule::Automatic)
    {
        base["next_detail"] = r.report.initial_next_detail;
    }
    base["folds_fixed_by_ven"] = 0;
    base["unprojected"] = r.base_unprojected;
    base["seconds"] = r.base_seconds;
    levels.push_back(base);
    for (const RefineLevelStats& s : r.report.levels)
    {
        levels.push_back(level_json(s, r.diagonal));
    }
    out["levels"] = levels;
    if (r.dropped)
    {
        out["dropped_level"] = level_json(*r.dropped, r.diagonal);
    }
    out["finest_level"] = r.hierarchy.finest_level();
    out["faces"] = r.hierarchy.face_count(r.hierarchy.finest_level());
    out["vertices"] = r.hierarchy.vertex_count();
    out["predictor"] = r.predictor;
    out["relaxation"] = {{"move", r.relaxation}, {"rounds", r.relax_rounds}};
    out["exact_levels"] = r.exact_levels;
    out["level_cap"] = r.level_cap;
    out["level_cap_from_memory"] = r.cap_from_memory;
    out["stop"] = r.exact_levels ? std::string("levels") : std::string(to_string(r.report.stop));
    out["stop_reason"] = r.stop_reason;
    out["stop_rule"] =
        r.exact_levels ? std::string("levels") : std::string(to_string(r.report.stop_rule));
    out["robust_distance_definition"] = robust_distance_definition;
    if (!r.exact_levels && r.report.stop_rule == StopRule::Automatic)
    {
        out["vertex_budget"] = r.report.vertex_budget;
        out["field_residual"] = r.report.field_residual;
        out["detail_threshold"] = r.report.detail_threshold;
    }
    // The level the paper's rule (§5.2.4: Hausdorff below the sampling density) picks, counted
    // from the base, or null when no level made reaches it.
    out["paper_rule_level"] =
        r.report.paper_level ? nlohmann::json(*r.report.paper_level) : nlohmann::json(nullptr);
    return out;
}

void print_refinement(const SemiRegularResult& r)
{
    print_row("sampling density", format_number(r.report.sampling_density) + " (" +
                                      sampling_density_definition + ", " +
                                      std::to_string(r.sample_count) + " samples)");
    print_row("Hausdorff", hausdorff_definition);
    print_row("robust", robust_distance_definition);
    if (!r.exact_levels && r.report.stop_rule == StopRule::Automatic)
    {
        print_row("field residual", format_number(r.report.field_residual) +
                                        " (the same robust mean of |f| at the samples); detail "
                                        "threshold " +
                                        format_number(r.report.detail_threshold));
        print_row("vertex budget", std::to_string(r.report.vertex_budget) + " (the samples)");
    }
    print_row("VEN fix",
              "fold vertices whose fold the vertex-based edge normal fixed / fold "
              "vertices after projection along the face normal (§5.2.2)");
    std::printf("  %5s %10s %10s %12s %9s %12s %12s %9s %11s %8s\n", "level", "faces", "vertices",
                "Hausdorff", "% diag", "mean", "robust", "VEN fix", "unprojected", "seconds");
    const auto row = [&](std::size_t level, std::size_t faces, std::size_t vertices, double h,
                         double mean, double robust, const std::string& ven,
                         std::size_t unprojected, double seconds, const char* note) {
        std::printf("  %5zu %10zu %10zu %12s %9s %12s %12s %9s %11zu %8.3f%s\n", level, faces,
                    vertices, format_number(h).c_str(), percent_of(h, r.diagonal).c_str(),
                    format_number(mean).c_str(), format_number(robust).c_str(), ven.c_str(),
                    unprojected, seconds, note);
    };
    const auto level_row = [&](const RefineLevelStats& s, const char* note) {
        row(s.level, s.faces, s.vertices, s.hausdorff.value_or(0.0), s.mean_distance.value_or(0.0),
            s.robust_distance.value_or(0.0),
            std::to_string(s.folds_fixed_by_ven) + "/" + std::to_string(s.fold_vertices),
            s.unprojected, s.seconds, note);
    };
    row(0, r.hierarchy.face_count(0), r.hierarchy.vertex_count(0), r.report.initial_hausdorff,
        r.report.initial_mean_distance, r.report.initial_robust_distance, "-", r.base_unprojected,
        r.base_seconds, "");
    for (const RefineLevelStats& s : r.report.levels)
    {
        level_row(s, "");
    }
    if (r.dropped)
    {
        level_row(*r.dropped, "  (not kept)");
    }
    print_row("stopped", r.stop_reason);
    if (!r.exact_levels && r.report.stop_rule == StopRule::Automatic)
    {
        print_row("paper's rule", r.report.paper_level
                                      ? "§5.2.4 (Hausdorff below the sampling density) is met at "
                                        "level " +
                                            std::to_string(*r.report.paper_level)
                                      : std::string("§5.2.4 (Hausdorff below the sampling "
                                                    "density) is met at no level made"));
    }
}

SemiRegularOutput refine_and_write(const TriMesh& base, const PointField& field,
                                   const SemiRegularOptions& options, const std::string& output,
                                   double base_seconds, std::size_t base_unprojected,
                                   Timings& timings, TerminalProgress& progress)
{
    SemiRegularOutput run{refine_semi_regular(base, field, options, progress.callback()), {}};
    run.result.base_seconds = base_seconds;
    run.result.base_unprojected = base_unprojected;
    timings.lap("refinement");
    write_semi_regular(output, options, run.result.hierarchy);
    timings.lap("write");
    progress.clear();
    run.topology =
        analyze_topology(run.result.hierarchy.level_mesh(run.result.hierarchy.finest_level()));
    return run;
}

nlohmann::json semi_regular_json(const SemiRegularOutput& run, const SemiRegularOptions& options,
                                 const std::string& input, const std::string& output)
{
    nlohmann::json out = refinement_json(run.result);
    out["input"] = input;
    out["output"] = output;
    if (!options.save_hierarchy.empty())
    {
        out["hierarchy"] = options.save_hierarchy;
    }
    out["components"] = run.topology.components;
    out["boundary_loops"] = run.topology.boundary_loops;
    out["euler_characteristic"] = run.topology.euler_characteristic;
    out["manifold"] = run.topology.is_oriented_manifold();
    return out;
}

void print_semi_regular(const SemiRegularOutput& run, const SemiRegularOptions& options)
{
    const MultiresMesh& hierarchy = run.result.hierarchy;
    print_refinement(run.result);
    print_row("output", std::to_string(hierarchy.face_count(hierarchy.finest_level())) +
                            " faces, " + std::to_string(hierarchy.vertex_count()) +
                            " vertices, level " + std::to_string(hierarchy.finest_level()) +
                            "; Euler " + std::to_string(run.topology.euler_characteristic) + ", " +
                            std::to_string(run.topology.boundary_loops) + " boundary loops");
    if (!options.save_hierarchy.empty())
    {
        print_row("hierarchy", options.save_hierarchy + " (" +
                                   std::to_string(hierarchy.level_count()) + " levels)");
    }
}

} // namespace pointform::cli
