// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/core/memory.h"
#include "pointform/geometry/shapes.h"
#include "pointform/io/io.h"

#include "common.h"
#include "output_transaction.h"

#include <cstdio>
#include <memory>

namespace pointform::cli {
namespace {

struct SampleCommandOptions
{
    std::string shape;
    std::string output;
    SampleOptions sampling;
    bool ascii = false;
};

/// Bytes per sample: its position and normal, the generator's scratch and the write buffer
/// (measured: 72 at -n 4000000).
constexpr double bytes_per_sample = 96.0;

/// About how many bytes sampling `count` points needs.
double estimate_sample_bytes(std::size_t count)
{
    return bytes_per_sample * static_cast<double>(count);
}

void run_sample(const SampleCommandOptions& options, const GlobalOptions& global)
{
    check_memory(estimate_sample_bytes(options.sampling.count),
                 "-n " + std::to_string(options.sampling.count), "use a smaller -n");
    const PointCloud cloud = sample_shape(parse_shape(options.shape), options.sampling);
    write_output(options.output, [&](const std::filesystem::path& path) {
        write_point_cloud(path, cloud, {.ascii = options.ascii});
    });
    if (!global.quiet)
        std::printf("wrote %zu samples of %s with exact normals to %s\n", cloud.size(),
                    options.shape.c_str(), options.output.c_str());
}

} // namespace

void register_sample(CLI::App& app, const GlobalOptions& global)
{
    auto options = std::make_shared<SampleCommandOptions>();
    CLI::App* cmd = app.add_subcommand(
        "sample",
        "Sample an analytic shape with its exact outward normals (test and benchmark "
        "inputs)");
    cmd->add_option("shape", options->shape,
                    "sphere, torus, two-spheres, plate, blobby, part or cone")
        ->required()
        ->check(
            CLI::IsMember({"sphere", "torus", "two-spheres", "plate", "blobby", "part", "cone"}));
    cmd->add_option("-o,--output", options->output, "Output file (.ply or .xyz)")->required();
    cmd->add_option("-n,--count", options->sampling.count, "Samples before holes are cut")
        ->capture_default_str()
        ->check(CLI::PositiveNumber);
    cmd->add_option("--seed", options->sampling.seed, "Random seed")->capture_default_str();
    cmd->add_option("--noise", options->sampling.noise,
                    "Gaussian position noise, fraction of the bounding-box diagonal")
        ->capture_default_str()
        ->check(CLI::NonNegativeNumber);
    cmd->add_option("--holes", options->sampling.holes, "Number of holes cut out")
        ->capture_default_str();
    cmd->add_option("--hole-radius", options->sampling.hole_radius,
                    "Hole radius, fraction of the bounding-box diagonal")
        ->capture_default_str()
        ->check(CLI::NonNegativeNumber);
    cmd->add_option("--strays", options->sampling.strays,
                    "Stray points spread through the bounding box grown by 30%, fraction of the "
                    "count")
        ->capture_default_str()
        ->check(CLI::Range(0.0, 1.0));
    cmd->add_option("--thickness", options->sampling.thickness, "Plate thickness (side 2)")
        ->capture_default_str()
        ->check(CLI::PositiveNumber);
    cmd->add_flag("--ascii", options->ascii, "Write ascii PLY");
    cmd->callback([options, &global] { run_sample(*options, global); });
}

} // namespace pointform::cli
