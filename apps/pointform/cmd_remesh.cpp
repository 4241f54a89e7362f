// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/core/error.h"
#include "pointform/core/memory.h"
#include "pointform/core/parallel.h"
#include "pointform/geometry/mesh_topology.h"
#include "pointform/hermite/radius.h"
#include "pointform/implicit/point_field.h"
#include "pointform/io/io.h"
#include "pointform/polygonize/base_mesh.h"
#include "pointform/spatial/kd_tree.h"

#include "common.h"
#include "semi_regular.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdio>
#include <memory>
#include <random>

namespace pointform::cli {
namespace {

struct RemeshOptions
{
    std::string input;
    std::string output;
    std::size_t samples = 0; ///< area-uniform samples besides the vertices; 0 = vertex count
    std::uint64_t seed = 1;
    std::size_t k = 16;
    double radius_scale = default_field_radius_scale;
    std::string fit = "quadric";
    SemiRegularOptions refine;
};

/// Refuses what the pipeline cannot take: no triangles, a non-manifold or badly oriented mesh,
/// degenerate faces.
void check_input_mesh(const std::string& path, const TriMesh& mesh)
{
    if (mesh.face_count() == 0)
    {
        throw InvalidInput(path + ": the mesh has no triangles (remesh needs a surface mesh)");
    }
    const MeshTopology topo = analyze_topology(mesh);
    if (!topo.is_oriented_manifold() || topo.degenerate_faces > 0)
    {
        throw InvalidInput(
            path + ": not an oriented 2-manifold mesh (" + std::to_string(topo.non_manifold_edges) +
            " edges with more than two triangles, " + std::to_string(topo.non_manifold_vertices) +
            " vertices with several fans, " + std::to_string(topo.misoriented_edges) +
            " misoriented edges, " + std::to_string(topo.degenerate_faces) +
            " degenerate triangles); remesh needs a manifold mesh");
    }
    try // what the base mesh cannot take (a vertex of too high valence), before the surfels
    {
        (void)check_intermediate_mesh(mesh);
    }
    catch (const InvalidInput& e)
    {
        throw InvalidInput(path + ": " + e.what());
    }
}

/// Bytes per surfel of the surfels and their point field (positions, normals, radii, k-d tree,
/// far grid; measured: 193 at --samples 2000000).
constexpr double bytes_per_field_surfel = 256.0;

/// About how many bytes the surfels of `count` samples and their PointField need.
double estimate_surfel_field_bytes(std::size_t count)
{
    return bytes_per_field_surfel * static_cast<double>(count);
}

/// Level 2 from an irregular mesh (§6): every used vertex with its area-weighted vertex normal,
/// then `count` area-uniform samples with the normal of the face they lie on; influence radii
/// from the sampling density (distance to the k-th neighbour, times radius_scale).
PointCloud mesh_surfels(const TriMesh& mesh, const RemeshOptions& options, std::size_t count)
{
    const auto& positions = mesh.vertices.positions;
    std::vector<Vec3d> vertex_normal(positions.size(), Vec3d::Zero());
    std::vector<Vec3d> face_normal(mesh.face_count());
    std::vector<double> cumulative(mesh.face_count());
    double area = 0.0;
    for (std::size_t f = 0; f < mesh.face_count(); ++f)
    {
        const Triangle& t = mesh.triangles[f];
        const Vec3d a = positions[t[0]].cast<double>();
        const Vec3d cross =
            (positions[t[1]].cast<double>() - a).cross(positions[t[2]].cast<double>() - a);
        for (const std::uint32_t v : t)
        {
            vertex_normal[v] += cross; // |cross| = twice the area: area-weighted
        }
        const double norm = cross.norm();
        face_normal[f] = norm > 0.0 ? Vec3d(cross / norm) : Vec3d::Zero();
        area += 0.5 * norm;
        cumulative[f] = area;
    }
    if (!(area > 0.0))
    {
        throw InvalidInput(options.input + ": the mesh has zero area");
    }
    PointCloud out;
    out.origin = mesh.vertices.origin;
    for (std::size_t v = 0; v < positions.size(); ++v)
    {
        const double norm = vertex_normal[v].norm();
        if (norm > 0.0)
        {
            out.positions.push_back(positions[v]);
            out.normals.push_back((vertex_normal[v] / norm).cast<float>());
        }
    }
    std::mt19937_64 random(options.seed);
    std::uniform_real_distribution<double> uniform(0.0, 1.0);
    for (std::size_t i = 0; i < count; ++i)
    {
        const double pick = uniform(random) * area;
        const auto it = std::upper_bound(cumulative.begin(), cumulative.end(), pick);
        const std::size_t f =
            std::min(static_cast<std::size_t>(it - cumulative.begin()), mesh.face_count() - 1);
        const double r1 = std::sqrt(uniform(random));
        const double r2 = uniform(random);
        const Triangle& t = mesh.triangles[f];
        const Vec3d p = (1.0 - r1) * positions[t[0]].cast<double>() +
                        r1 * (1.0 - r2) * positions[t[1]].cast<double>() +
                        r1 * r2 * positions[t[2]].cast<double>();
        if (face_normal[f].squaredNorm() > 0.0)
        {
            out.positions.push_back(p.cast<float>());
            out.normals.push_back(face_normal[f].cast<float>());
        }
    }
    if (out.size() <= options.k)
    {
        throw InvalidInput(options.input + ": too few vertices and samples (" +
                           std::to_string(out.size()) + ") for -k " + std::to_string(options.k));
    }
    const KdTree tree(out.positions);
    const KnnTable knn = knn_batch(tree, out.positions, options.k + 1);
    out.radii = influence_radii(knn, options.radius_scale);
    return out;
}

void run_remesh(const RemeshOptions& options, const GlobalOptions& global)
{
    set_thread_count(global.threads);
    TerminalProgress progress(!global.quiet && !options.refine.json);
    Timings timings;
    const TriMesh mesh = read_mesh(options.input);
    check_input_mesh(options.input, mesh);
    timings.lap("read");
    const std::size_t count = options.samples > 0 ? options.samples : mesh.vertex_count();
    check_memory(estimate_surfel_field_bytes(count + mesh.vertex_count()),
                 "a point field of " + std::to_string(count + mesh.vertex_count()) +
                     " surfels (the vertices and --samples)",
                 "use fewer --samples");
    PointCloud surfels = mesh_surfels(mesh, options, count);
    timings.lap("surfels");
    const PointField field(std::move(surfels), {.fit = parse_plane_fit(options.fit)});
    timings.lap("field");

    // The input is already the intermediate mesh: decimate it.
    // Default: a quarter of the input's faces (one level restores its resolution), within
    // [200, 20000]. Measured on data/meshes/bunny_uniform.off (17.8k faces): faces / 16 refines
    // to level 6 (4.5M faces, 18 s) before the Hausdorff distance stops improving; faces / 4
    // reaches the sampling density at level 3 (256k faces, about a second).
    const std::size_t target =
        options.refine.base_faces
            ? base_face_target(options.refine, mesh)
            : std::min(mesh.face_count(),
                       std::clamp<std::size_t>(mesh.face_count() / 4, 200, 20000));
    if (options.refine.levels)
    {
        check_refinement_memory(target, static_cast<std::size_t>(*options.refine.levels));
    }
    TriMesh intermediate = mesh;
    intermediate.vertices.normals.clear();
    intermediate.vertices.colors.clear();
    intermediate.vertices.radii.clear();
    BaseMeshResult built = build_base_mesh(
        intermediate, field, {.target_faces = target, .progress = progress.callback()});
    timings.lap("base mesh");
    const double base_seconds = timings.stages().back().second;

    const SemiRegularOutput run =
        refine_and_write(built.mesh, field, options.refine, options.output, base_seconds,
                         built.stats.unprojected, timings, progress);
    if (options.refine.json)
    {
        nlohmann::json out = semi_regular_json(run, options.refine, options.input, options.output);
        out["input_faces"] = mesh.face_count();
        out["input_vertices"] = mesh.vertex_count();
        out["area_samples"] = count;
        out["fit"] = options.fit;
        out["base_mesh"] = base_mesh_json(built.stats);
        out["base_mesh"]["source"] = "automatic";
        add_run_report(out, timings);
        std::printf("%s\n", out.dump(2).c_str());
        return;
    }
    if (global.quiet)
    {
        return;
    }
    std::printf("%s -> %s\n", options.input.c_str(), options.output.c_str());
    print_row("input mesh", std::to_string(mesh.face_count()) + " faces, " +
                                std::to_string(mesh.vertex_count()) + " vertices");
    print_row("surfels", std::to_string(run.result.sample_count) +
                             " (the vertices with area-weighted normals, and " +
                             std::to_string(count) + " area-uniform samples with face normals)");
    print_base_mesh(built.stats);
    print_semi_regular(run, options.refine);
    print_timings(timings);
}

} // namespace

void register_remesh(CLI::App& app, const GlobalOptions& global)
{
    auto options = std::make_shared<RemeshOptions>();
    CLI::App* cmd = app.add_subcommand(
        "remesh",
        "Irregular mesh -> semi-regular multiresolution mesh (paper §6, Fig. 13): its vertices "
        "and area-uniform samples become surfels (level 2), the mesh itself is decimated to the "
        "base mesh, which is refined on their field as `pointform reconstruct` does");
    cmd->add_option("input", options->input,
                    "Input mesh: an oriented 2-manifold (.ply, .obj, .off)")
        ->required();
    cmd->add_option("-o,--output", options->output, "Output mesh (.ply, .obj or .off)")->required();
    add_base_faces_option(*cmd, options->refine)
        ->description(
            "Faces of the base mesh, decimated from the input (default: a quarter of "
            "its faces, within [200, 20000])");
    add_refine_options(*cmd, options->refine);
    cmd->add_option("--samples", options->samples,
                    "Area-uniform samples added to the vertices (default: as many as vertices)");
    cmd->add_option("--seed", options->seed, "Seed of the area-uniform samples")
        ->capture_default_str();
    cmd->add_option("-k", options->k, "Neighbours of each surfel for its influence radius")
        ->capture_default_str()
        ->check(CLI::Range(3, 1000));
    cmd->add_option("--radius-scale", options->radius_scale,
                    "Factor on the influence radius (distance to the k-th neighbour)")
        ->capture_default_str()
        ->check(CLI::PositiveNumber);
    cmd->add_option("--fit", options->fit, "Local surfaces of the field (see `pointform mc`)")
        ->capture_default_str()
        ->check(CLI::IsMember({"quadric", "blend", "centroid", "raw"}));
    cmd->callback([options, &global] { run_remesh(*options, global); });
}

} // namespace pointform::cli
