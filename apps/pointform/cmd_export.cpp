// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/core/error.h"
#include "pointform/io/hierarchy.h"
#include "pointform/multires/export.h"

#include "common.h"
#include "output_transaction.h"
#include "textured_output.h"

#include <nlohmann/json.hpp>

#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace pointform::cli {
namespace {

struct ExportOptions
{
    std::string input;
    std::string output;
    std::string levels = "all";
    bool json = false;
};

void run_export(const ExportOptions& options, const GlobalOptions& global)
{
    Timings timings;
    const bool gltf = is_gltf_output(options.output); // before any work: a bad name is exit 2
    const MultiresMesh mesh = read_hierarchy(options.input);
    timings.lap("read");
    std::vector<std::size_t> levels;
    try
    {
        levels = parse_level_list(options.levels, mesh.level_count());
    }
    catch (const InvalidInput& e)
    {
        throw InvalidInput(options.input + ": " + e.what());
    }
    // An OBJ holds one level: the finest of those asked for.
    if (!gltf)
        levels = {levels.back()};
    const TexturedMesh chain = level_chain(mesh, levels);
    timings.lap("levels");

    OutputTransaction transaction;
    const std::vector<std::filesystem::path> files =
        stage_textured_mesh(transaction, options.output, chain, chain.lods.size() - 1);
    transaction.commit();
    timings.lap("write");
    std::vector<std::uintmax_t> sizes;
    for (const auto& file : files)
        sizes.push_back(std::filesystem::file_size(file));

    if (options.json)
    {
        nlohmann::json out;
        out["input"] = options.input;
        out["output"] = options.output;
        out["format"] = gltf ? "glb" : "obj";
        nlohmann::json written = nlohmann::json::array();
        for (std::size_t k = 0; k < levels.size(); ++k)
            written.push_back({{"level", levels[k]},
                               {"vertices", chain.lod_vertex_counts[k]},
                               {"faces", chain.lods[k].size()}});
        out["levels"] = written;
        nlohmann::json file_list = nlohmann::json::array();
        for (std::size_t k = 0; k < files.size(); ++k)
            file_list.push_back({{"path", files[k].string()}, {"bytes", sizes[k]}});
        out["files"] = file_list;
        out["bytes"] = sizes.front();
        add_run_report(out, timings);
        std::printf("%s\n", out.dump(2).c_str());
        return;
    }
    if (global.quiet)
        return;
    std::printf(
        "%s: %zu of %zu level%s -> %s (%s)\n", options.input.c_str(), levels.size(),
        mesh.level_count(), mesh.level_count() == 1 ? "" : "s", options.output.c_str(),
        gltf ? (levels.size() > 1 ? "glTF binary, levels of detail in MSFT_lod" : "glTF binary")
             : "OBJ, one level");
    std::printf("  %5s %12s %12s\n", "level", "vertices", "faces");
    for (std::size_t k = 0; k < levels.size(); ++k)
        std::printf("  %5zu %12zu %12zu\n", levels[k], chain.lod_vertex_counts[k],
                    chain.lods[k].size());
    for (std::size_t k = 0; k < files.size(); ++k)
        print_row(files[k].string(), std::to_string(sizes[k]) + " bytes");
    print_timings(timings);
}

} // namespace

void register_export(CLI::App& app, const GlobalOptions& global)
{
    auto options = std::make_shared<ExportOptions>();
    CLI::App* cmd = app.add_subcommand(
        "export",
        "Exports levels of a hierarchy file: glTF binary (.glb) with every chosen level as a level "
        "of detail (MSFT_lod; loaders without it show the finest), or OBJ (.obj) with the finest "
        "chosen level");
    cmd->add_option("input", options->input, "Hierarchy file (.pfh)")->required();
    cmd->add_option("-o,--output", options->output, "Output file (.glb or .obj)")->required();
    cmd->add_option("--levels", options->levels,
                    "'all' (default) or level numbers in increasing order, e.g. 0,2,4");
    cmd->add_flag("--json", options->json, "Print the report as JSON");
    cmd->callback([options, &global] { run_export(*options, global); });
}

} // namespace pointform::cli
