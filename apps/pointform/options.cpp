// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "options.h"

#include "pointform/core/error.h"
#include "pointform/hermite/radius.h"
#include "pointform/polygonize/refine.h"
#include "pointform/report/report_json.h" // format_number

#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace pointform::cli {
namespace {

template <typename Enum>
using EnumNames = std::vector<std::pair<std::string, Enum>>;

/// A transform of an enum's names into the values CLI11 assigns (the underlying integers),
/// refusing every other text, the integers included; "{a,b,c}" in the help.
template <typename Enum>
CLI::Validator enum_transform(const EnumNames<Enum>& names)
{
    std::string list;
    for (const auto& [text, item] : names)
        list += (list.empty() ? "{" : ",") + text;
    list += "}";
    return CLI::Validator(
        [names, list](std::string& text) -> std::string {
            for (const auto& [name, item] : names)
                if (name == text)
                {
                    text = std::to_string(static_cast<std::underlying_type_t<Enum>>(item));
                    return {};
                }
            return text + " not in " + list;
        },
        list);
}

/// Binds an enum option through enum_transform(), showing `value`'s name as the default.
template <typename Enum>
CLI::Option* add_enum_option(CLI::App& cmd, const std::string& name, Enum& value,
                             const EnumNames<Enum>& names, const std::string& help)
{
    std::string default_name;
    for (const auto& [text, item] : names)
        if (item == value)
            default_name = text;
    // Bound through a function: CLI11 would otherwise look for the enum's to_string(), which
    // the library's overloads answer with a string_view.
    return cmd
        .add_option_function<Enum>(
            name, [&value](const Enum& parsed) { value = parsed; }, help)
        ->transform(enum_transform(names))
        ->type_name("TEXT")
        ->default_str(default_name);
}

/// --levels: a whole number from 0 to max_exact_levels.
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
                    return "--levels must be an integer, not '" + text + "'";
            }
            catch (const std::exception&)
            {
                return "--levels must be an integer, not '" + text + "'";
            }
            if (value < 0 || value > static_cast<long long>(max_exact_levels))
                return "--levels must be between 0 and " + std::to_string(max_exact_levels) +
                       " (each level has 4 times the faces of the one below: level 8 has 65536 "
                       "times the base mesh's), not " +
                       text;
            return {};
        },
        "0.." + std::to_string(max_exact_levels));
}

/// --base-faces: a whole number, at least 1.
CLI::Validator at_least_one_face()
{
    return CLI::Validator(
        [](std::string& text) -> std::string {
            try
            {
                std::size_t used = 0;
                if (std::stoll(text, &used) >= 1 && used == text.size())
                    return {};
            }
            catch (const std::exception&)
            {}
            return "--base-faces must be a whole number of faces, at least 1, not '" + text + "'";
        },
        "N >= 1");
}

} // namespace

CLI::Option* add_k_option(CLI::App& cmd, std::size_t& k, const std::string& help)
{
    return cmd.add_option("-k", k, help)->capture_default_str()->check(CLI::Range(3, 1000));
}

CLI::Option* add_radius_scale_option(CLI::App& cmd, double& scale, const std::string& help)
{
    return cmd.add_option("--radius-scale", scale, help)
        ->capture_default_str()
        ->check(CLI::PositiveNumber);
}

CLI::Option* add_radius_regions_option(CLI::App& cmd, std::vector<RadiusRegion>& regions,
                                       const std::string& help)
{
    return cmd.add_option_function<std::string>(
        "--radius-regions",
        [&regions](const std::string& path) { regions = read_radius_regions(path); }, help);
}

CLI::Option* add_fit_option(CLI::App& cmd, PlaneFit& fit, const std::string& help)
{
    return add_enum_option(cmd, "--fit", fit,
                           {{"quadric", PlaneFit::Quadric},
                            {"blend", PlaneFit::Blend},
                            {"centroid", PlaneFit::Centroid},
                            {"raw", PlaneFit::Raw}},
                           help);
}

CLI::Option* add_rim_reach_option(CLI::App& cmd, double& rim_reach)
{
    return cmd
        .add_option("--rim-reach", rim_reach,
                    "How far past a rim of the samples (a hole's edge, a scan's border) the "
                    "field reaches, as a fraction of an influence radius; 1 = a whole radius "
                    "(the paper's field, which extrapolates the rim's surfaces into the hole)")
        ->check(CLI::Range(1e-6, 1.0))
        ->capture_default_str();
}

CLI::Option* add_max_handle_option(CLI::App& cmd, double& max_handle)
{
    return cmd
        .add_option("--max-handle", max_handle,
                    "Cut the marching-cubes mesh's handles whose loop is at most this many "
                    "median influence radii long, and cap both sides (topological noise: tunnels "
                    "where the field's sheets meet past their samples); 0 keeps every handle")
        ->check(CLI::Range(0.0, max_handle_radii))
        ->capture_default_str();
}

std::string describe_handle_cuts(const HandleCutReport& cuts, double radii)
{
    if (cuts.skipped_not_manifold)
        return "none cut (the mesh is not an oriented 2-manifold)";
    if (cuts.genus_before == 0)
        return "none (genus 0)";
    const std::string bound = format_number(cuts.max_length) + " (" + format_number(radii) +
                              " median influence radii, --max-handle)";
    if (cuts.cuts == 0)
        return "genus " + std::to_string(cuts.genus_before) +
               ", no loop round a handle of at most " + bound;
    return "genus " + std::to_string(cuts.genus_before) + " -> " +
           std::to_string(cuts.genus_after) + ": cut " + std::to_string(cuts.cuts) + " loop" +
           (cuts.cuts == 1 ? "" : "s") + " of at most " + bound + " (the longest " +
           format_number(cuts.longest_cut) + "), capped both sides";
}

CLI::Option* add_rule_option(CLI::App& cmd, OrientationRule& rule, const std::string& help)
{
    return add_enum_option(
        cmd, "--rule", rule,
        {{"hoppe", OrientationRule::Hoppe}, {"reflection", OrientationRule::Reflection}}, help);
}

CLI::Option* add_orient_option(CLI::App& cmd, OrientMode& mode, Vec3d& target,
                               const std::string& help)
{
    const CLI::Validator valid(
        [](const std::string& text) -> std::string {
            try
            {
                static_cast<void>(parse_orient(text));
                return {};
            }
            catch (const InvalidInput& error)
            {
                return error.what();
            }
        },
        "");
    return cmd
        .add_option_function<std::string>(
            "--orient",
            [&mode, &target](const std::string& text) {
                const OrientChoice choice = parse_orient(text);
                mode = choice.mode;
                target = choice.target;
            },
            help)
        ->check(valid)
        ->type_name("TEXT")
        ->default_str("auto");
}

void add_surfel_input_options(CLI::App& cmd, SurfelsFromSamplesOptions& options)
{
    add_k_option(cmd, options.k,
                 "Neighbours of each point, besides itself, for normals and the radius");
    add_radius_scale_option(cmd, options.radius_scale,
                            "Factor on the automatic influence radius (distance to the k-th "
                            "neighbour); larger values close larger holes");
    add_radius_regions_option(
        cmd, options.radius_regions,
        "JSON file of balls and boxes that set the radius (see `pointform normals`)");
    add_orient_option(
        cmd, options.orient, options.orient_target,
        "How estimated normals are oriented: auto (towards the sensor of a depth "
        "image, an organized PCD with its VIEWPOINT; mst otherwise), mst, none "
        "(PCA's signs), flip, towards:X,Y,Z (a viewpoint) or along:X,Y,Z (a direction, e.g. "
        "along:0,0,1 for airborne LiDAR; see `pointform normals`)");
    cmd.add_flag("--reestimate", options.reestimate,
                 "Estimate and orient normals even if the input has them");
    add_sharp_creases_flag(cmd, options.sharp_creases)
        ->description(
            "Where normals are estimated here (raw points, or --reestimate): in a clean "
            "cloud, refit each normal at a crease to its own face instead of keeping "
            "the PCA normal, a blend of the faces' there (see `pointform normals`)");
    cmd.add_flag("--keep-off-surface", options.keep_off_surface,
                 "Keep the samples that stand off the surface of their nearest (stray returns "
                 "near it, left out by default; a face seen at a grazing angle may have a few)");
}

CLI::Option* add_sharp_creases_flag(CLI::App& cmd, bool& sharp)
{
    return cmd.add_flag(
        "--sharp-creases", sharp,
        "In a clean cloud, refit each estimated normal at a crease to its own face (by "
        "reweighted least squares, as the field's quadrics do) instead of keeping the PCA "
        "normal, a blend of the faces' there");
}

std::vector<CLI::Option*> add_level_options(CLI::App& cmd, SemiRegularCommandOptions& options,
                                            const std::string& levels_help)
{
    SemiRegularOptions& semi = options.semi_regular;
    std::vector<CLI::Option*> added;
    added.push_back(cmd.add_option("--levels", semi.levels, levels_help)->check(levels_range()));
    added.push_back(add_enum_option(
        cmd, "--predictor", semi.predictor,
        {{"midpoint", Predictor::Midpoint}, {"butterfly", Predictor::Butterfly}},
        "Where a new edge vertex starts before its projection onto the surface: midpoint, or "
        "butterfly (the displaced butterfly subdivision)"));
    added.push_back(
        cmd.add_option("--relax", semi.relax_iterations,
                       "Rounds of tangential relaxation of the new vertices per level (§5.2.3), "
                       "each followed by their re-projection, then two more of the new vertices "
                       "of thin triangles (an angle under 20°) only; 0 keeps the projected "
                       "predictions")
            ->capture_default_str()
            ->check(CLI::Range(0, 10)));
    added.push_back(add_enum_option(
        cmd, "--relaxation", semi.relaxation,
        {{"across", Relaxation::AcrossEdge}, {"umbrella", Relaxation::Umbrella}},
        "Which part of the umbrella move relaxation makes: across (the part across the parent "
        "edge, which keeps the split ratio) or umbrella (all of it, as in the paper)"));
    added.push_back(cmd.add_option("--save-hierarchy", options.save_hierarchy,
                                   "Also write every level as a hierarchy file (.pfh; extract "
                                   "levels with `pointform lod`)"));
    return added;
}

void add_refine_options(CLI::App& cmd, SemiRegularCommandOptions& options)
{
    add_level_options(cmd, options,
                      "Refine exactly to level J (0 = the base mesh only); default: until the "
                      "--stop rule says so (at most level " +
                          std::to_string(default_max_level) + ")");
    add_enum_option(cmd, "--stop", options.semi_regular.stop_rule,
                    {{"auto", StopRule::Automatic}, {"paper", StopRule::Paper}},
                    "When refinement stops without --levels: auto (the default: while the next "
                    "level would move the mesh by more than a tenth of the field's residual at "
                    "the samples, and would have no more vertices than there are samples) or "
                    "paper (§5.2.4: until the largest distance from a sample is below the "
                    "sampling density)");
    cmd.add_option("--denoise", options.semi_regular.denoise_rounds,
                   "Rounds of Taubin smoothing of the finest level when the automatic stop "
                   "ends on noise (the next level's details would follow the field's noise); "
                   "0 keeps the projected level")
        ->check(CLI::Range(std::size_t{0}, max_denoise_rounds))
        ->capture_default_str();
    cmd.add_flag("!--no-hole-fairing", options.semi_regular.fair_unsupported,
                 "Keep the finest level as projected where no sample supports it (filled holes "
                 "and their rims) instead of fairing it to the smoothest surface that continues "
                 "the mesh around it");
    cmd.add_flag("!--no-face-fit", options.semi_regular.fit_faces,
                 "Keep the finest level's vertices on the field (the paper's interpolating "
                 "level) instead of fitting its flat faces to the field in the least-squares "
                 "sense (which takes out their sag inside curved parts; with the automatic "
                 "stop only, and not where the level was smoothed for noise)");
    cmd.add_flag("--ascii", options.ascii, "Write ascii PLY instead of binary");
    cmd.add_flag("--json", options.json, "Print the report as JSON");
}

CLI::Option* add_base_faces_option(CLI::App& cmd, SemiRegularOptions& options)
{
    return cmd
        .add_option("--base-faces", options.base_faces,
                    "Faces of the automatic base mesh (default: the intermediate mesh's faces / "
                    "16, within [200, 80000], then fitted to the vertex budget: see docs)")
        ->check(at_least_one_face());
}

} // namespace pointform::cli
