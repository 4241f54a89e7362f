// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/core/error.h"
#include "pointform/geometry/mesh_topology.h"
#include "pointform/io/hierarchy.h"
#include "pointform/io/io.h"
#include "pointform/multires/level_of_detail.h"

#include "common.h"
#include "output_transaction.h"

#include <nlohmann/json.hpp>

#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <utility>

namespace pointform::cli {
namespace {

struct LodOptions
{
    std::string input;
    std::string output;
    long long level = 0;
    bool level_given = false;
    bool ascii = false;
    bool json = false;
};

/// The level asked for, or the finest; any other value is an error that lists the levels.
std::size_t choose_level(const LodOptions& options, const MultiresMesh& mesh)
{
    if (!options.level_given)
        return mesh.finest_level();
    if (options.level < 0)
        throw InvalidInput(options.input + ": level " + std::to_string(options.level) +
                           " does not exist: the hierarchy has " +
                           std::to_string(mesh.level_count()) + " levels (0 to " +
                           std::to_string(mesh.finest_level()) + ")");
    try
    {
        check_level(mesh, static_cast<std::size_t>(options.level));
    }
    catch (const InvalidInput& e)
    {
        throw InvalidInput(options.input + ": " + e.what());
    }
    return static_cast<std::size_t>(options.level);
}

void run_lod(const LodOptions& options, const GlobalOptions& global)
{
    Timings timings;
    const MultiresMesh mesh = read_hierarchy(options.input);
    timings.lap("read");
    const std::size_t level = choose_level(options, mesh);

    std::optional<TriMesh> extracted;
    MeshTopology topo;
    if (!options.output.empty())
    {
        LevelOfDetail lod = extract_level(mesh, level);
        extracted = std::move(lod.mesh);
        topo = lod.topology;
        timings.lap("extract");
        write_output(options.output, [&](const std::filesystem::path& path) {
            write_mesh(path, *extracted, {.ascii = options.ascii});
        });
        timings.lap("write");
    }

    // The version the file was written in (read_hierarchy() has read it, so it is one it knows).
    const std::uint32_t version =
        hierarchy_file_version(options.input).value_or(hierarchy_format_version);
    if (options.json)
    {
        nlohmann::json out;
        out["input"] = options.input;
        out["format_version"] = version;
        out["origin"] = {mesh.origin().x(), mesh.origin().y(), mesh.origin().z()};
        nlohmann::json levels = nlohmann::json::array();
        for (std::size_t l = 0; l < mesh.level_count(); ++l)
            levels.push_back(
                {{"level", l}, {"vertices", mesh.vertex_count(l)}, {"faces", mesh.face_count(l)}});
        out["levels"] = levels;
        out["level"] = level;
        if (extracted)
        {
            out["output"] = options.output;
            out["vertices"] = extracted->vertex_count();
            out["faces"] = extracted->face_count();
            out["components"] = topo.components;
            out["boundary_loops"] = topo.boundary_loops;
            out["euler_characteristic"] = topo.euler_characteristic;
            out["manifold"] = topo.is_oriented_manifold();
        }
        add_run_report(out, timings);
        std::printf("%s\n", out.dump(2).c_str());
        return;
    }
    if (global.quiet)
        return;
    std::printf("%s: semi-regular hierarchy, format version %u, %zu level%s\n",
                options.input.c_str(), version, mesh.level_count(),
                mesh.level_count() == 1 ? "" : "s");
    std::printf("  %5s %12s %12s\n", "level", "vertices", "faces");
    for (std::size_t l = 0; l < mesh.level_count(); ++l)
        std::printf("  %5zu %12zu %12zu%s\n", l, mesh.vertex_count(l), mesh.face_count(l),
                    extracted && l == level ? "  <- written" : "");
    if (!extracted)
        return;
    std::printf("level %zu -> %s\n", level, options.output.c_str());
    print_row("vertices", std::to_string(extracted->vertex_count()));
    print_row("faces", std::to_string(extracted->face_count()));
    print_row("components", std::to_string(topo.components));
    print_row("boundary loops", std::to_string(topo.boundary_loops));
    print_row("Euler characteristic", std::to_string(topo.euler_characteristic));
    print_timings(timings);
}

} // namespace

void register_lod(CLI::App& app, const GlobalOptions& global)
{
    auto options = std::make_shared<LodOptions>();
    CLI::App* cmd = app.add_subcommand(
        "lod",
        "Level of detail: prints the levels of a hierarchy file (written by reconstruct "
        "--save-hierarchy) and, with -o, writes one level as a mesh");
    cmd->add_option("input", options->input, "Hierarchy file (.pfh)")->required();
    auto* level = cmd->add_option("-l,--level", options->level,
                                  "Level to extract, 0 (base mesh) to J (default: the finest)");
    cmd->add_option("-o,--output", options->output,
                    "Output mesh (.ply, .obj or .off); without it only the levels are listed");
    cmd->add_flag("--ascii", options->ascii, "Write ascii PLY instead of binary");
    cmd->add_flag("--json", options->json, "Print the report as JSON");
    cmd->callback([options, level, &global] {
        options->level_given = level->count() > 0;
        run_lod(*options, global);
    });
}

} // namespace pointform::cli
