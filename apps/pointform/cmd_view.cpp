// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "common.h"
#include "view_server.h"

#include <cstdio>
#include <memory>
#include <string>

namespace pointform::cli {
namespace {

struct ViewOptions
{
    std::string input;
    std::string host = "127.0.0.1";
    int port = 8080;
};

/// "http://HOST:PORT/", with an IPv6 address in brackets.
std::string url_of(const std::string& host, int port)
{
    const bool ipv6 = host.find(':') != std::string::npos;
    return "http://" + (ipv6 ? "[" + host + "]" : host) + ":" + std::to_string(port) + "/";
}

void run_view(const ViewOptions& options, const GlobalOptions& global)
{
    // Read first: a file that cannot be read is reported (exit 3) before anything listens.
    const ViewData data = read_view_data(options.input);
    const StaticFiles files = read_static_files(PF_VIEWER_DIR);
    for (const std::string& missing : files.missing)
        std::fprintf(stderr,
                     "pointform view: warning: %s is missing (bash scripts/setup.sh installs "
                     "three.js with npm ci in viewer/); the page will not work\n",
                     missing.c_str());

    serve_view(data, files, options.host, options.port, [&](int port) {
        if (!global.quiet)
        {
            std::printf("pointform view: %s (%s", options.input.c_str(), kind_name(data.kind));
            if (data.level_count() > 1)
                std::printf(", %zu levels", data.level_count());
            std::printf(")\n");
        }
        // The URL is printed even with --quiet: it is what the command is for (tests read it).
        std::printf("%s\n", url_of(options.host, port).c_str());
        if (!global.quiet)
            std::printf("Ctrl-C stops the server.\n");
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
        "Serves a page that shows FILE in a web browser (three.js): a hierarchy's levels, a mesh "
        "or a point cloud; prints the URL and serves until Ctrl-C. Only the page and FILE's data "
        "are served (docs/viewer.md)");
    cmd->add_option("input", options->input,
                    "Hierarchy (.pfh), mesh (.ply, .obj, .off) or point cloud")
        ->required();
    cmd->add_option("-p,--port", options->port, "TCP port; 0 picks a free one (default 8080)")
        ->check(CLI::Range(0, 65535));
    cmd->add_option("--host", options->host,
                    "Address to listen on (default 127.0.0.1, this machine only; use an SSH "
                    "tunnel rather than 0.0.0.0 to view from elsewhere)");
    cmd->callback([options, &global] { run_view(*options, global); });
}

} // namespace pointform::cli
