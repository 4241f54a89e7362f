// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/core/error.h"
#include "pointform/core/memory.h"
#include "pointform/core/parallel.h"
#include "pointform/io/io.h"
#include "pointform/render/render.h"

#include "common.h"
#include "output_transaction.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <memory>
#include <sstream>
#include <tuple>
#include <utility>

namespace pointform::cli {
namespace {

struct RenderCommandOptions
{
    std::string input;
    std::string output;
    std::string size = "1024,768";
    std::string view = "30,20";
    std::string up = "y";
    std::string frame;
    bool wireframe = false;
    bool orthographic = false;
    double field_of_view = 30.0;
    int supersampling = 2;
    bool points = false;
    double splat_scale = 1.0;
    bool use_radii = false;
    bool flat = false;
    bool json = false;
};

/// Parses --size "W,H": whole numbers of pixels, 1..16384 each.
std::pair<int, int> parse_size(const std::string& text)
{
    const auto [w, h] = parse_pair(text, "--size", "W,H in pixels (e.g. 1024,768)");
    const auto whole = [](double v) {
        return v == std::floor(v) && v >= 1.0 && v <= 16384.0;
    };
    if (!whole(w) || !whole(h))
        throw CLI::ValidationError("--size", "'" + text +
                                                 "': width and height must be whole numbers "
                                                 "of pixels from 1 to 16384");
    return {static_cast<int>(w), static_cast<int>(h)};
}

Vec3d parse_up(const std::string& text)
{
    const bool negative = !text.empty() && text.front() == '-';
    const std::string axis = negative ? text.substr(1) : text;
    Vec3d up;
    if (axis == "x")
        up = Vec3d::UnitX();
    else if (axis == "y")
        up = Vec3d::UnitY();
    else if (axis == "z")
        up = Vec3d::UnitZ();
    else if (text.find(',') != std::string::npos)
    {
        up = parse_vec3(text, "--up");
        if (up.squaredNorm() == 0.0)
            throw CLI::ValidationError("--up", "the direction must not be zero");
        return up;
    }
    else
        throw CLI::ValidationError("--up", "'" + text + "': expected x, y, z, -x, -y, -z or X,Y,Z");
    return negative ? Vec3d(-up) : up;
}

bool has_png_extension(const std::string& path)
{
    std::string ext = std::filesystem::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return ext == ".png";
}

/// Bytes per supersample (colour and depth) while rendering (measured: 8 at 2000 x 2000 x 8²).
constexpr double bytes_per_supersample = 12.0;

/// About how many bytes rendering a `width` x `height` image at `supersampling` needs.
double estimate_render_bytes(int width, int height, int supersampling)
{
    return bytes_per_supersample * static_cast<double>(width) * static_cast<double>(height) *
           static_cast<double>(supersampling) * static_cast<double>(supersampling);
}

void run_render(const RenderCommandOptions& options, const GlobalOptions& global)
{
    set_thread_count(global.threads);
    if (!has_png_extension(options.output))
        throw CLI::ValidationError("--output", "'" + options.output + "': only .png is written");
    RenderOptions render_options;
    std::tie(render_options.width, render_options.height) = parse_size(options.size);
    std::tie(render_options.azimuth, render_options.elevation) =
        parse_pair(options.view, "--view", "AZIMUTH,ELEVATION in degrees (e.g. 30,20)");
    if (std::abs(render_options.elevation) > 90.0)
        throw CLI::ValidationError(
            "--view", "'" + options.view + "': the elevation must be within -90..90 degrees");
    render_options.up = parse_up(options.up);
    render_options.projection =
        options.orthographic ? Projection::Orthographic : Projection::Perspective;
    render_options.field_of_view = options.field_of_view;
    if (!options.frame.empty())
        render_options.frame = parse_box(options.frame, "--frame");
    render_options.supersampling = options.supersampling;
    check_memory(estimate_render_bytes(render_options.width, render_options.height,
                                       render_options.supersampling),
                 "a " + std::to_string(render_options.width) + " x " +
                     std::to_string(render_options.height) + " image at supersampling " +
                     std::to_string(render_options.supersampling),
                 "use a smaller --size or --supersampling");
    render_options.wireframe = options.wireframe;
    render_options.splat_scale = options.splat_scale;
    render_options.use_radii = options.use_radii;
    render_options.estimate_normals = !options.flat;

    Timings timings;
    ReadResult geometry = read_geometry(options.input);
    timings.lap("read");
    if (geometry.points.empty())
        throw InvalidInput(options.input + ": nothing to render (no points)");
    const bool as_mesh = !geometry.triangles.empty() && !options.points;
    const std::size_t vertex_count = geometry.points.size();
    const std::size_t face_count = geometry.triangles.size();
    Image image;
    if (as_mesh)
        image = render_mesh({std::move(geometry.points), std::move(geometry.triangles)},
                            render_options);
    else
        image = render_points(geometry.points, render_options);
    timings.lap("render");
    write_output(options.output,
                 [&](const std::filesystem::path& path) { write_png(path, image); });
    timings.lap("write");

    const std::string kind = as_mesh ? "mesh" : "points";
    if (options.json)
    {
        nlohmann::json out;
        out["input"] = options.input;
        out["output"] = options.output;
        out["drawn_as"] = kind;
        out["vertices"] = vertex_count;
        out["faces"] = face_count;
        out["width"] = image.width;
        out["height"] = image.height;
        out["view"] = {render_options.azimuth, render_options.elevation};
        add_run_report(out, timings);
        std::printf("%s\n", out.dump(2).c_str());
        return;
    }
    if (global.quiet)
        return;
    std::printf("%s -> %s\n", options.input.c_str(), options.output.c_str());
    print_row("drawn as", as_mesh ? kind + " (" + std::to_string(face_count) + " faces)"
                                  : kind + " (" + std::to_string(vertex_count) + ")");
    print_row("image", std::to_string(image.width) + " x " + std::to_string(image.height));
    print_timings(timings);
}

} // namespace

void register_render(CLI::App& app, const GlobalOptions& global)
{
    auto options = std::make_shared<RenderCommandOptions>();
    CLI::App* cmd = app.add_subcommand(
        "render",
        "Draw a mesh (shaded, optionally with its edges) or a point cloud (discs shaded by "
        "normal) to a PNG, headless on the CPU. Front faces blue-grey, back faces orange: "
        "inside-out parts and holes show up. Point clouds without normals get them estimated "
        "(as 'normals' does) unless --flat is given");
    cmd->add_option("input", options->input,
                    "Mesh or point set: .ply .off .obj .xyz .pts .csv .txt .pwn .pcd .las")
        ->required();
    cmd->add_option("-o,--output", options->output, "Output image (.png)")->required();
    cmd->add_option("--size", options->size, "Image size W,H in pixels")->capture_default_str();
    cmd->add_option("--view", options->view,
                    "AZIMUTH,ELEVATION in degrees: the camera orbits the bounding-box centre "
                    "(0,0 looks along -z for y-up, along +y for z-up)")
        ->capture_default_str();
    cmd->add_option("--up", options->up, "Up axis of the model: x, y, z, -x, -y, -z or X,Y,Z")
        ->capture_default_str();
    cmd->add_option("--frame", options->frame,
                    "XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX: frame this world box instead of the object, "
                    "so pictures of several objects (before and after an edit) share one camera");
    cmd->add_flag("--wireframe", options->wireframe, "Draw the edges of the visible faces");
    cmd->add_flag("--ortho", options->orthographic, "Orthographic instead of perspective");
    cmd->add_option("--fov", options->field_of_view,
                    "Perspective opening angle across the shorter side, degrees")
        ->capture_default_str()
        ->check(CLI::Range(1.0, 160.0));
    cmd->add_option("--supersampling", options->supersampling,
                    "Anti-aliasing: samples per pixel along each axis")
        ->capture_default_str()
        ->check(CLI::Range(1, 8));
    cmd->add_flag("--points", options->points, "Draw a mesh's vertices as points");
    cmd->add_option("--splat-scale", options->splat_scale,
                    "Factor on the disc radius of points (automatic: distance to the 8th "
                    "nearest sample)")
        ->capture_default_str()
        ->check(CLI::PositiveNumber);
    cmd->add_flag("--use-radii", options->use_radii,
                  "Points: discs of the file's radius property (influence radii) when present");
    cmd->add_flag("--flat", options->flat,
                  "Points without normals: flat discs instead of estimating normals");
    cmd->add_flag("--json", options->json, "Print the report (counts, timings) as JSON");
    cmd->callback([options, &global] { run_render(*options, global); });
}

} // namespace pointform::cli
