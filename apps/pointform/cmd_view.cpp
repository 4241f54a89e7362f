// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/core/error.h"
#include "pointform/core/parallel.h"

#include "common.h"
#include "view_server.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>
#include <system_error>
#include <vector>

namespace pointform::cli {
namespace {

struct ViewOptions
{
    std::vector<std::string> inputs;
    std::string host = "127.0.0.1";
    int port = 8080;
};

/// At most this many files on one page.
constexpr std::size_t max_view_files = 8;

/// "http://HOST:PORT/", with an IPv6 address in brackets.
std::string url_of(const std::string& host, int port)
{
    const bool ipv6 = host.find(':') != std::string::npos;
    return "http://" + (ipv6 ? "[" + host + "]" : host) + ":" + std::to_string(port) + "/";
}

/// Where the page's files are: $POINTFORM_VIEWER_DIR, else share/pointform/viewer beside an
/// installed executable (bin/../share/...), else viewer/ of the source tree it was built from.
std::filesystem::path viewer_directory()
{
    if (const char* dir = std::getenv("POINTFORM_VIEWER_DIR"); dir != nullptr && *dir != '\0')
        return dir;
    std::error_code error;
    const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", error);
    if (!error &&
        exe.parent_path().filename() == std::filesystem::path(PF_INSTALL_BINDIR).filename())
    {
        const std::filesystem::path installed =
            exe.parent_path().parent_path() / PF_VIEWER_INSTALL_SUBDIR;
        if (std::filesystem::is_regular_file(installed / "web" / "index.html", error))
            return installed;
    }
    return PF_VIEWER_DIR;
}

void run_view(const ViewOptions& options, const GlobalOptions& global)
{
    set_thread_count(global.threads);
    if (options.inputs.size() > max_view_files)
        throw InvalidInput("at most " + std::to_string(max_view_files) + " files, not " +
                           std::to_string(options.inputs.size()));
    // Read first: a file that cannot be read is reported (exit 3) before anything listens.
    std::vector<ViewData> layers;
    for (const std::string& input : options.inputs)
        layers.push_back(read_view_data(input));
    const std::filesystem::path viewer_dir = viewer_directory();
    const StaticFiles files = read_static_files(viewer_dir);
    for (const std::string& missing : files.missing)
        std::fprintf(stderr,
                     "pointform view: warning: %s is missing (bash scripts/setup.sh installs "
                     "three.js with npm ci in viewer/); the page will not work\n",
                     missing.c_str());

    std::vector<std::string> descriptions;
    for (std::size_t k = 0; k < layers.size(); ++k)
    {
        std::string d = options.inputs[k] + " (" + kind_name(layers[k].kind);
        if (layers[k].level_count() > 1)
            d += ", " + std::to_string(layers[k].level_count()) + " levels";
        descriptions.push_back(d + ")");
    }
    const bool pickable = std::any_of(layers.begin(), layers.end(), [](const ViewData& d) {
        return d.kind == ViewData::Kind::Points;
    });
    serve_view(std::move(layers), files, options.host, options.port, [&](int port) {
        if (!global.quiet)
            for (const std::string& d : descriptions)
                std::printf("pointform view: %s\n", d.c_str());
        // The URL is printed even with --quiet: it is what the command is for (tests read it).
        std::printf("%s\n", url_of(options.host, port).c_str());
        if (!global.quiet)
        {
            if (pickable)
                std::printf("Pick samples on the page to make a base mesh and reconstruct.\n");
            std::printf("Ctrl-C stops the server.\n");
        }
        std::fflush(stdout);
    });
    if (!global.quiet)
        std::printf("pointform view: stopped\n");
}

} // namespace

void register_view(CLI::App& app, const GlobalOptions& global)
{
    auto options = std::make_shared<ViewOptions>();
    CLI::App* cmd = app.add_subcommand(
        "view",
        "Serves a page that shows FILES in a web browser (three.js): a hierarchy's levels, "
        "meshes, point clouds; on a point cloud, a base mesh picked by hand is reconstructed "
        "(as reconstruct --base-mesh) and its levels shown. Prints the URL and serves until "
        "Ctrl-C. Only the page and the files' data are served (docs/viewer.md)");
    cmd->add_option("inputs", options->inputs,
                    "Up to 8 files, drawn together: hierarchies (.pfh), meshes (.ply, .obj, "
                    ".off), point clouds (the first one is the samples: picked on, distances "
                    "measured from)")
        ->required();
    cmd->add_option("-p,--port", options->port, "TCP port; 0 picks a free one (default 8080)")
        ->check(CLI::Range(0, 65535));
    cmd->add_option("--host", options->host,
                    "Address to listen on (default 127.0.0.1, this machine only; use an SSH "
                    "tunnel rather than 0.0.0.0 to view from elsewhere)");
    cmd->callback([options, &global] { run_view(*options, global); });
}

} // namespace pointform::cli
