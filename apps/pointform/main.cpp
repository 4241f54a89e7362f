// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/core/error.h"
#include "pointform/core/parallel.h"

#include "common.h"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cstdio>
#include <exception>
#include <new>
#include <string>
#include <thread>

namespace {

// Exit codes, documented in --help.
constexpr int exit_ok = 0;
constexpr int exit_invalid_input = 2; // data or option values that cannot be processed
constexpr int exit_io = 3;            // a file could not be read or written
constexpr int exit_failure = 4;       // any other failure

/// The largest -j accepted: four threads per core, and at least 8 (determinism tests
/// oversubscribe small machines on purpose).
int max_thread_option()
{
    const unsigned cores = std::thread::hardware_concurrency();
    return std::max(8, 4 * static_cast<int>(std::min(cores, 1024U)));
}

int run(int argc, char** argv)
{
    CLI::App app{
        "pointform: multiresolution free-form modeling from point-sampled geometry.\n"
        "Exit codes: 0 success, 2 invalid input or usage (bad option values, unknown options, "
        "missing arguments), 3 file error, 4 other failure."};
    app.set_version_flag("--version", "pointform 0.1.0");
    app.require_subcommand(1);
    app.fallthrough();

    pointform::cli::GlobalOptions global;
    // More threads than this only costs memory and time: a typo, not a wish.
    const int max_threads = max_thread_option();
    app.add_option("-j,--threads", global.threads,
                   "Threads to use (0 = all cores; at most " + std::to_string(max_threads) + ")")
        ->check(CLI::Validator(
            [max_threads](const std::string& text) -> std::string {
                long long n = -1;
                try
                {
                    std::size_t used = 0;
                    n = std::stoll(text, &used);
                    if (used != text.size())
                        n = -1;
                }
                catch (const std::exception&)
                {
                    n = -1;
                }
                if (n < 0 || n > max_threads)
                    return "-j " + text + ": expected 0 (all cores) to " +
                           std::to_string(max_threads) + " (4 per core on this machine)";
                return {};
            },
            "0.." + std::to_string(max_threads)));
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
    pointform::cli::register_export(app, global);
    pointform::cli::register_texture(app, global);
    pointform::cli::register_deform(app, global);
    pointform::cli::register_reconstruct(app, global);
    pointform::cli::register_remesh(app, global);
    pointform::cli::register_view(app, global);

    try
    {
        app.parse(argc, argv);
    }
    catch (const CLI::ParseError& e)
    {
        // --help and --version exit 0; every usage error (a bad option value, an unknown
        // option, a missing argument) is invalid input.
        return app.exit(e) == exit_ok ? exit_ok : exit_invalid_input;
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
