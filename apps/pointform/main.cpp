// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/core/error.h"
#include "pointform/core/parallel.h"

#include "common.h"

#include <CLI/CLI.hpp>

#include <cstdio>
#include <exception>
#include <new>

namespace {

// Exit codes, documented in --help.
constexpr int exit_ok = 0;
constexpr int exit_invalid_input = 2; // data or option values that cannot be processed
constexpr int exit_io = 3;            // a file could not be read or written
constexpr int exit_failure = 4;       // any other failure

int run(int argc, char** argv)
{
    CLI::App app{
        "pointform: multiresolution free-form modeling from point-sampled geometry.\n"
        "Exit codes: 0 success, 2 invalid input, 3 file error, 4 other failure; "
        "usage errors as CLI11 reports them (non-zero)."};
    app.set_version_flag("--version", "pointform 0.1.0");
    app.require_subcommand(1);
    app.fallthrough();

    pointform::cli::GlobalOptions global;
    app.add_option("-j,--threads", global.threads, "Threads to use (0 = all cores)")
        ->check(CLI::NonNegativeNumber);
    app.add_flag("-q,--quiet", global.quiet, "No progress and no summary");

    pointform::cli::register_info(app, global);
    pointform::cli::register_normals(app, global);
    pointform::cli::register_sample(app, global);
    pointform::cli::register_mc(app, global);
    pointform::cli::register_render(app, global);
    pointform::cli::register_distance(app, global);
    pointform::cli::register_model(app, global);
    pointform::cli::register_morph(app, global);
    pointform::cli::register_lod(app, global);
    pointform::cli::register_reconstruct(app, global);
    pointform::cli::register_remesh(app, global);

    try
    {
        app.parse(argc, argv);
    }
    catch (const CLI::ParseError& e)
    {
        return app.exit(e);
    }
    catch (const pointform::IoError& e)
    {
        std::fprintf(stderr, "pointform: error: %s\n", e.what());
        return exit_io;
    }
    catch (const pointform::InvalidInput& e)
    {
        std::fprintf(stderr, "pointform: invalid input: %s\n", e.what());
        return exit_invalid_input;
    }
    catch (const std::bad_alloc&)
    {
        std::fprintf(stderr, "pointform: error: out of memory\n");
        return exit_failure;
    }
    catch (const std::exception& e)
    {
        std::fprintf(stderr, "pointform: error: %s\n", e.what());
        return exit_failure;
    }
    return exit_ok;
}

} // namespace

int main(int argc, char** argv)
{
    try
    {
        return run(argc, argv);
    }
    catch (...)
    {
        std::fputs("pointform: error: unexpected failure\n", stderr);
        return exit_failure;
    }
}
