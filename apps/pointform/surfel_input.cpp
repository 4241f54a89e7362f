// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "surfel_input.h"

#include "pointform/core/error.h"
#include "pointform/io/io.h"

#include <cstdio>

namespace pointform::cli {

SurfelsFromSamples load_surfels(const std::string& path, SurfelsFromSamplesOptions options,
                                const ProgressCallback& progress)
{
    const PointCloud cloud = read_point_cloud(path);
    options.progress = progress;
    try
    {
        return surfels_from_samples(cloud, options);
    }
    catch (const InvalidInput& e)
    {
        throw InvalidInput(path + ": " + e.what());
    }
}

void warn_unoriented(const std::string& path, std::size_t unoriented)
{
    if (unoriented > 0)
    {
        std::fprintf(stderr, "pointform: warning: %s: %zu samples without a normal were left out\n",
                     path.c_str(), unoriented);
    }
}

void warn_isolated(const std::string& path, std::size_t isolated, std::size_t copies,
                   std::size_t off_surface)
{
    if (copies > 0)
    {
        std::fprintf(stderr,
                     "pointform: warning: %s: %zu samples at the very place of an earlier sample "
                     "(repeated coordinates) were merged into it\n",
                     path.c_str(), copies);
    }
    if (isolated > 0)
    {
        std::fprintf(stderr,
                     "pointform: warning: %s: %zu samples alone far from the rest (stray points) "
                     "were left out\n",
                     path.c_str(), isolated);
    }
    if (off_surface > 0)
    {
        std::fprintf(stderr,
                     "pointform: warning: %s: %zu samples standing off the surface of their "
                     "nearest (stray returns near it) were left out\n",
                     path.c_str(), off_surface);
    }
}

} // namespace pointform::cli
