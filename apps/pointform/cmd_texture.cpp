// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/core/error.h"
#include "pointform/core/parallel.h"
#include "pointform/io/hierarchy.h"
#include "pointform/io/io.h"
#include "pointform/io/png.h"
#include "pointform/multires/texture.h"
#include "pointform/render/render.h"
#include "pointform/report/report_json.h"

#include "common.h"
#include "output_transaction.h"
#include "textured_output.h"

#include <nlohmann/json.hpp>

#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <tuple>

namespace pointform::cli {
namespace {

struct TextureOptions
{
    std::string input;
    std::string output;
    long long level = -1;
    std::string image;
    bool checker = false;
    std::string bake_colors;
    long long normal_map_level = -1;
    int size = 0;
    std::string preview;
    std::string view = "30,20";
    std::string frame;
    bool json = false;
};

std::size_t level_option(long long value, const char* option)
{
    if (value < 0)
        throw InvalidInput(std::string(option) + " must not be negative, got " +
                           std::to_string(value));
    return static_cast<std::size_t>(value);
}

void run_texture(const TextureOptions& options, const GlobalOptions& global)
{
    set_thread_count(global.threads);
    Timings timings;
    (void)is_gltf_output(options.output); // refuse another extension before any work
    const MultiresMesh mesh = read_hierarchy(options.input);
    timings.lap("read");

    TextureRequest request;
    if (options.level >= 0)
        request.level = level_option(options.level, "--level");
    if (options.normal_map_level >= 0)
        request.normal_map_level = level_option(options.normal_map_level, "--normal-map-level");
    request.atlas.size = options.size;
    std::optional<PointCloud> scan;
    if (!options.image.empty())
    {
        request.source = TextureRequest::Source::Image;
        request.image = read_png(options.image);
    }
    else if (!options.bake_colors.empty())
    {
        request.source = TextureRequest::Source::BakeColors;
        scan = read_point_cloud(options.bake_colors);
        if (!scan->has_colors())
            throw InvalidInput(options.bake_colors +
                               ": the scan has no colours (red, green, blue) to bake");
    }
    timings.lap("inputs");
    const PointCloudView samples = scan ? PointCloudView(*scan) : PointCloudView();
    const TextureOutcome outcome = texture_hierarchy(mesh, request, scan ? &samples : nullptr);
    timings.lap("texture");

    OutputTransaction transaction;
    std::vector<std::filesystem::path> written = stage_textured_mesh(
        transaction, options.output, outcome.mesh, outcome.mesh.lods.size() - 1);
    if (!options.preview.empty())
    {
        RenderOptions render;
        std::tie(render.azimuth, render.elevation) =
            parse_pair(options.view, "--view", "AZIMUTH,ELEVATION in degrees (e.g. 30,20)");
        if (!options.frame.empty())
            render.frame = parse_box(options.frame, "--frame");
        const Image picture =
            render_textured_mesh(outcome.mesh, outcome.mesh.lods.size() - 1, render);
        transaction.stage(options.preview,
                          [&](const std::filesystem::path& path) { write_png(path, picture); });
        written.push_back(options.preview);
    }
    transaction.commit();
    timings.lap("write");

    if (options.json)
    {
        nlohmann::json out = report_json(outcome);
        out["input"] = options.input;
        nlohmann::json files = nlohmann::json::array();
        for (const auto& path : written)
            files.push_back(path.string());
        out["outputs"] = files;
        out["source"] = !options.image.empty()         ? "image"
                        : !options.bake_colors.empty() ? "bake-colors"
                                                       : "checker";
        add_run_report(out, timings);
        std::printf("%s\n", out.dump(2).c_str());
        return;
    }
    if (global.quiet)
        return;
    std::printf("%s -> %s: level %zu, %d x %d atlas of %zu charts (%s%% of the texels used)\n",
                options.input.c_str(), options.output.c_str(), outcome.level, outcome.atlas.size,
                outcome.atlas.size, outcome.atlas.corners.size(),
                format_number(100.0 * outcome.atlas.texel_usage).c_str());
    std::printf("  %5s %10s %10s %11s %11s %11s %11s %8s\n", "level", "faces", "vertices",
                "L2 stretch", "Linf", "angle", "area", "flipped");
    for (std::size_t i = 0; i < outcome.distortion.size(); ++i)
    {
        const AtlasDistortion& d = outcome.distortion[i];
        std::printf("  %5zu %10zu %10zu %11s %11s %11s %11s %8zu\n", d.level, d.faces,
                    outcome.mesh.lod_vertex_counts[i], format_number(d.l2_stretch).c_str(),
                    format_number(d.linf_stretch).c_str(),
                    format_number(d.angle_distortion).c_str(),
                    format_number(d.area_distortion).c_str(), d.flipped);
    }
    if (outcome.bake)
        print_row("baked", std::to_string(outcome.bake->texels) + " texels, colour error " +
                               format_number(outcome.bake->rms_color_error) + " RMS (0-255)");
    for (const auto& path : written)
        std::printf("  -> %s\n", path.string().c_str());
    print_timings(timings);
}

} // namespace

void register_texture(CLI::App& app, const GlobalOptions& global)
{
    auto options = std::make_shared<TextureOptions>();
    CLI::App* cmd = app.add_subcommand(
        "texture",
        "Texture mapping through the parameterization over the base mesh (one chart per base "
        "triangle): a checkerboard, an image, or the colours of a coloured scan baked into the "
        "atlas, and optionally a normal map; writes a textured glTF binary (every level as a "
        "level of detail) or OBJ + MTL + PNG");
    cmd->add_option("input", options->input, "Hierarchy file (.pfh)")->required();
    cmd->add_option("-o,--output", options->output, "Output: OUT.glb or OUT.obj")->required();
    cmd->add_option("-l,--level", options->level,
                    "The finest level textured, J (default: the finest)");
    auto* image = cmd->add_option("--image", options->image,
                                  "PNG used as the atlas (texel (u, v) shows the image at (u, v))");
    auto* checker =
        cmd->add_flag("--checker", options->checker,
                      "A checkerboard in texture space (the default): shows distortion");
    auto* bake = cmd->add_option("--bake-colors", options->bake_colors,
                                 "A coloured scan (PLY, LAS, PCD with RGB) whose colours are baked "
                                 "into the atlas");
    image->excludes(checker)->excludes(bake);
    checker->excludes(bake);
    cmd->add_option("--normal-map-level", options->normal_map_level,
                    "Export level j < J alone with a tangent-space normal map baked from J");
    cmd->add_option("--size", options->size,
                    "Texture size in texels a side, 16 to 16384 (default: from the level's face "
                    "count)")
        ->check(CLI::Range(min_atlas_size, max_atlas_size));
    cmd->add_option("--preview", options->preview,
                    "Also draw the finest exported level, textured (and normal-mapped), to a PNG");
    cmd->add_option("--view", options->view, "--preview's AZIMUTH,ELEVATION in degrees")
        ->capture_default_str();
    cmd->add_option("--frame", options->frame,
                    "--preview frames this box XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX (as render --frame)");
    cmd->add_flag("--json", options->json, "Print the report as JSON");
    cmd->callback([options, &global] { run_texture(*options, global); });
}

} // namespace pointform::cli
