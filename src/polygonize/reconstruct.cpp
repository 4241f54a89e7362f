// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/polygonize/reconstruct.h"

#include "pointform/core/error.h"
#include "pointform/core/memory.h"
#include "pointform/polygonize/handles.h"
#include "pointform/polygonize/marching_cubes.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <memory>
#include <optional>
#include <string>

namespace pointform {
namespace {

/// Bytes a refinement needs per face of the level it makes: the hierarchy's positions (double)
/// and parent edges, the faces and edge vertices of the level below, the extracted output mesh,
/// the triangle BVH of the distance measurement and the per-vertex refinement state.
constexpr double bytes_per_refined_face = 256.0;

/// Bytes per surfel of the surfels and their point field (positions, normals, radii, k-d tree,
/// far grid; measured: 193 at 2M surfels).
constexpr double bytes_per_field_surfel = 256.0;

double faces_at_level(std::size_t base_faces, std::size_t level)
{
    return static_cast<double>(base_faces) * std::pow(4.0, static_cast<double>(level));
}

bool fits(std::size_t base_faces, std::size_t level)
{
    const double faces = faces_at_level(base_faces, level);
    return faces <= static_cast<double>(std::numeric_limits<std::uint32_t>::max()) &&
           fits_in_memory(estimate_refinement_bytes(base_faces, level));
}

/// Laps wall-clock time into a report's stage list.
class StageClock
{
public:
    explicit StageClock(std::vector<std::pair<std::string, double>>& stages) : stages_(stages) {}

    /// Records the time since the last lap (or the start) as `stage`. \return those seconds
    double lap(const std::string& stage)
    {
        const auto now = std::chrono::steady_clock::now();
        const double seconds = std::chrono::duration<double>(now - last_).count();
        stages_.emplace_back(stage, seconds);
        last_ = now;
        return seconds;
    }

private:
    std::vector<std::pair<std::string, double>>& stages_;
    std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

RefineOptions refine_options_of(const SemiRegularOptions& options, const ProgressCallback& progress)
{
    RefineOptions refine_options;
    refine_options.predictor = options.predictor;
    refine_options.relax_iterations = options.relax_iterations;
    refine_options.relaxation = options.relaxation;
    refine_options.denoise_rounds = options.denoise_rounds;
    refine_options.fair_unsupported = options.fair_unsupported;
    refine_options.fit_faces = options.fit_faces;
    refine_options.stop_rule = options.stop_rule;
    refine_options.sample_tree = options.sample_tree;
    refine_options.progress = progress;
    return refine_options;
}

void check_semi_regular_options(const SemiRegularOptions& options)
{
    if (options.levels && *options.levels > max_exact_levels)
        throw InvalidInput("--levels must be between 0 and " + std::to_string(max_exact_levels) +
                           " (each level has 4 times the faces of the one below: level 8 has "
                           "65536 times the base mesh's), not " +
                           std::to_string(*options.levels));
    if (options.stop_rule == StopRule::Exact && !options.levels)
        throw InvalidInput("the exact stop rule needs the levels to refine to");
}

/// The level count of a built base mesh (its topology) whose finest level stays within a vertex
/// budget (each 1-to-4 level adds an edge's worth of vertices: V' = V + E, E = V + F − χ), and
/// the base-face target that fills the budget with that many levels (fit_base_faces_to_budget()).
std::size_t target_for_affordable_levels(const MeshTopology& topology, std::size_t budget)
{
    auto v = static_cast<double>(topology.vertices);
    auto f = static_cast<double>(topology.faces);
    const auto chi = static_cast<double>(topology.euler_characteristic);
    std::size_t levels = 0;
    while (levels < max_exact_levels && v + (v + f - chi) <= static_cast<double>(budget))
    {
        v += v + f - chi;
        f *= 4.0;
        ++levels;
    }
    const double faces_wanted = 2.0 * default_budget_fill * static_cast<double>(budget);
    return static_cast<std::size_t>(std::llround(faces_wanted / std::pow(4.0, levels)));
}

/// The automatic base-face target for an intermediate mesh of `faces` faces in `components`
/// pieces: default_base_faces(), fitted to a vertex budget of `samples` under the automatic
/// stop without `levels` (at most `faces`).
std::size_t automatic_base_faces(const SemiRegularOptions& options, std::size_t faces,
                                 std::size_t components, std::size_t share, std::size_t samples,
                                 double coarsening)
{
    const std::size_t target = default_base_faces(faces, components, share, coarsening);
    if (samples == 0 || options.levels || options.stop_rule != StopRule::Automatic)
        return target;
    return std::min(faces, fit_base_faces_to_budget(target, samples));
}

} // namespace

std::size_t base_face_target(const SemiRegularOptions& options, const TriMesh& intermediate,
                             std::size_t share, std::size_t samples, double coarsening)
{
    if (!options.base_faces)
        return automatic_base_faces(options, intermediate.face_count(),
                                    analyze_topology(intermediate).components, share, samples,
                                    coarsening);
    const std::size_t wanted = *options.base_faces;
    if (wanted < 1)
        throw InvalidInput("--base-faces must be at least 1, not " + std::to_string(wanted));
    if (wanted > intermediate.face_count())
        throw InvalidInput("--base-faces " + std::to_string(wanted) +
                           " is larger than the intermediate (marching-cubes) mesh, which has " +
                           std::to_string(intermediate.face_count()) +
                           " faces; the base mesh simplifies it");
    return wanted;
}

double estimate_refinement_bytes(std::size_t base_faces, std::size_t level)
{
    return bytes_per_refined_face * faces_at_level(base_faces, level);
}

void check_refinement_memory(std::size_t base_faces, std::size_t level)
{
    const double faces = faces_at_level(base_faces, level);
    if (faces > static_cast<double>(std::numeric_limits<std::uint32_t>::max()))
    {
        char count[64];
        std::snprintf(count, sizeof count, "%.6g", faces);
        throw InvalidInput("level " + std::to_string(level) + " of a base mesh of " +
                           std::to_string(base_faces) + " faces would have " + count +
                           " faces, more than 32-bit indices allow; use fewer --levels or "
                           "--base-faces");
    }
    char what[160];
    std::snprintf(what, sizeof what,
                  "level %zu of a base mesh of %zu faces (%.4g faces at that level)", level,
                  base_faces, faces);
    check_memory(estimate_refinement_bytes(base_faces, level), what,
                 "use fewer --levels or --base-faces");
}

std::size_t affordable_level(std::size_t base_faces, std::size_t cap)
{
    std::size_t level = 0;
    while (level < cap && fits(base_faces, level + 1))
        ++level;
    return level;
}

SemiRegularReport refine_semi_regular(const TriMesh& base, const Field& field,
                                      const PointCloud* samples, const SemiRegularOptions& options,
                                      const ProgressCallback& progress)
{
    check_semi_regular_options(options);
    if (samples == nullptr && !options.levels)
        throw InvalidInput(
            "refinement: without samples to measure from, the levels to refine to are needed");
    SemiRegularReport r;
    StageClock clock(r.stage_seconds);
    r.hierarchy = MultiresMesh(base);
    static const PointCloud no_samples;
    const PointCloud& measured = samples != nullptr ? *samples : no_samples;
    r.measured = samples != nullptr;
    r.diagonal = samples != nullptr ? samples->bounds().diagonal() : 0.0;
    r.sample_count = measured.size();
    RefineOptions refine_options = refine_options_of(options, progress);
    const std::size_t base_faces = base.face_count();
    if (options.levels)
    {
        check_refinement_memory(base_faces, *options.levels);
        r.exact_levels = true;
        r.level_cap = *options.levels;
        refine_options.stop_rule = StopRule::Exact;
        refine_options.max_level = *options.levels;
        r.refinement = refine(r.hierarchy, field, measured, refine_options);
        r.refinement.stop = RefineStop::LevelCap;
    }
    else
    {
        r.level_cap = affordable_level(base_faces, default_max_level);
        r.cap_from_memory = r.level_cap < default_max_level;
        refine_options.max_level = r.level_cap;
        r.refinement = refine(r.hierarchy, field, measured, refine_options);
    }
    clock.lap("refinement");
    return r;
}

SemiRegularReport semi_regular_mesh(const TriMesh& intermediate, const Field& field,
                                    const PointCloud* samples, const SemiRegularOptions& options,
                                    std::size_t share, const ProgressCallback& progress,
                                    double coarsening)
{
    check_semi_regular_options(options);
    const auto start = std::chrono::steady_clock::now();
    const std::size_t target = base_face_target(
        options, intermediate, share, samples != nullptr ? samples->size() : 0, coarsening);
    if (options.levels)
        check_refinement_memory(target, *options.levels);
    BaseMeshResult built = build_base_mesh(intermediate, field,
                                           {.target_faces = target,
                                            .chord_split_share = options.chord_split_share,
                                            .fill_holes = options.fill_holes,
                                            .progress = progress});
    if (!options.base_faces && !options.levels && options.stop_rule == StopRule::Automatic &&
        samples != nullptr && !samples->empty())
    {
        // A base mesh whose topology (a scan of many handles) kept it well above the fitted
        // target reaches the vertex budget a level early, at a quarter of the vertices the fit
        // planned: built again for the levels it affords, with a target that fills the budget.
        const std::size_t refit =
            std::min(intermediate.face_count(),
                     target_for_affordable_levels(built.stats.topology_after, samples->size()));
        if (2 * refit > 3 * built.mesh.face_count())
            built = build_base_mesh(intermediate, field,
                                    {.target_faces = refit,
                                     .chord_split_share = options.chord_split_share,
                                     .fill_holes = options.fill_holes,
                                     .progress = progress});
    }
    const double base_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    SemiRegularReport r = refine_semi_regular(built.mesh, field, samples, options, progress);
    r.base = built.stats;
    r.base_unprojected = built.stats.unprojected;
    r.base_seconds = base_seconds;
    r.stage_seconds.insert(r.stage_seconds.begin(), {"base mesh", base_seconds});
    return r;
}

VertexResidual field_residual_at_vertices(const TriMesh& mesh, const Field& field)
{
    VertexResidual out;
    std::vector<Vec3d> at(mesh.vertex_count());
    for (std::size_t v = 0; v < at.size(); ++v)
        at[v] = mesh.vertices.world(v);
    std::vector<FieldSample> values(at.size());
    field.evaluate(at, values);
    for (const FieldSample& value : values)
    {
        if (value.defined && std::isfinite(value.value))
        {
            out.max = std::max(out.max, std::abs(value.value));
            out.mean += std::abs(value.value);
            ++out.defined;
        }
    }
    out.mean = out.defined > 0 ? out.mean / static_cast<double>(out.defined) : 0.0;
    return out;
}

double intermediate_face_limit(const PointField& field, double cell,
                               const SemiRegularOptions& options, std::size_t samples)
{
    const double estimated = estimate_marching_cubes_faces(field.estimated_area(), cell);
    const std::size_t target =
        options.base_faces
            ? *options.base_faces
            : automatic_base_faces(options, static_cast<std::size_t>(std::min(estimated, 1e15)), 1,
                                   default_base_share, samples, 1.0);
    return std::min(max_intermediate_faces,
                    intermediate_faces_per_base_face * static_cast<double>(target));
}

/// reconstruct()'s intermediate mesh: marching cubes of `field` over the cells that
/// choose_cell_size() and intermediate_grid() give, its debris removed; its figures into
/// `report`.
TriMesh intermediate_mesh_of(const PointField& field, const Aabb& bounds,
                             const ReconstructOptions& options, ReconstructReport& report,
                             StageClock& clock, const std::string& stage_suffix = {})
{
    const PointCloud& samples = field.surfels();
    IntermediateGrid intermediate{
        .cell = choose_cell_size(field, bounds, options.resolution, options.cell)};
    if (options.resolution <= 0 && !(options.cell > 0.0))
        intermediate =
            intermediate_grid(field, intermediate.cell,
                              intermediate_face_limit(field, intermediate.cell,
                                                      options.semi_regular, samples.size()));
    const double cell = intermediate.cell;
    report.cell = cell;
    report.coarsening = intermediate.coarsening;
    report.stray_samples = field.stray_samples().size();
    const CellGrid grid = grid_over(field.bounds(), cell);
    check_marching_cubes_memory(field, cell);
    // The intermediate mesh's vertex normals are not used (the base mesh is made from its
    // positions): not asked for, which saves a field evaluation a vertex.
    MarchingCubesResult mc =
        marching_cubes(field, grid,
                       {.vertex_normals = false,
                        .min_defined_corners = intermediate.min_defined_corners,
                        .progress = options.progress});
    clock.lap("marching cubes" + stage_suffix);
    if (mc.mesh.face_count() == 0)
        throw Error(
            "marching cubes made no triangles: the field has no defined zero crossing at "
            "this cell size (try a smaller --cell or a larger --radius-scale)");
    report.intermediate_faces = mc.mesh.face_count();
    report.intermediate_vertices = mc.mesh.vertex_count();
    report.degenerate_triangles = mc.stats.degenerate_triangles;
    report.degenerate_kept = mc.stats.degenerate_kept;
    report.undefined_triangles = mc.stats.undefined_triangles;
    report.cell_vertices = mc.stats.cell_vertices;
    report.debris = remove_unsupported_components(
        mc.mesh, samples,
        options.min_component_samples ? *options.min_component_samples
                                      : default_min_component_samples(samples.size()),
        &field.tree());
    clock.lap("debris" + stage_suffix);
    return std::move(mc.mesh);
}

ReconstructReport reconstruct(PointCloud surfels, const ReconstructOptions& options)
{
    check_semi_regular_options(options.semi_regular);
    if (!options.base_mesh.empty() && !options.picked_vertices.empty())
        throw InvalidInput("give a base-mesh file or picked vertices, not both");
    if (!(options.fill_holes >= 0.0 && options.fill_holes < 1.0))
        throw InvalidInput("the largest hole to fill must be in [0, 1) of its component's area");
    if (!(options.max_handle >= 0.0 && options.max_handle <= max_handle_radii))
        throw InvalidInput("the longest handle loop to cut must be in [0, " +
                           std::to_string(static_cast<int>(max_handle_radii)) +
                           "] median influence radii");
    ReconstructReport report;
    StageClock clock(report.stage_seconds);
    const Aabb bounds = surfels.bounds();
    // The field puts the samples in Morton order (field.surfels()), and a base-mesh file names
    // samples by their index as given, so it is read against them in that order.
    std::optional<PointCloud> given;
    if (!options.base_mesh.empty())
        given = surfels;
    auto field = std::make_unique<const PointField>(
        std::move(surfels),
        PointFieldOptions{
            .fit = options.fit, .rim_reach = options.rim_reach, .progress = options.progress});
    clock.lap("field");

    if (!options.base_mesh.empty() || !options.picked_vertices.empty())
    {
        // M0 picked over the samples (§5.1, Fig. 6).
        const PointCloud& samples = field->surfels();
        report.picked = options.base_mesh.empty()
                            ? snap_picked_base_mesh(options.picked_vertices, samples, *field)
                            : read_picked_base_mesh(options.base_mesh, *given, *field);
        given.reset();
        report.picked_angles = angle_quality(report.picked->mesh);
        const double base_seconds = clock.lap("base mesh (picked)");
        SemiRegularOptions semi_regular = options.semi_regular;
        semi_regular.sample_tree = &field->tree();
        report.semi_regular = refine_semi_regular(report.picked->mesh, *field, &samples,
                                                  semi_regular, options.progress);
        report.semi_regular.base_seconds = base_seconds;
    }
    else
    {
        // M0: the simplified marching-cubes mesh (Fig. 5), its debris removed.
        TriMesh intermediate_mesh = intermediate_mesh_of(*field, bounds, options, report, clock);
        // A sponge: the fits follow the noise (PointFieldOptions::noise_scale). The field again,
        // its fits at the scale of the noise, and its mesh.
        if (const std::optional<SpongeRefit> refit = sponge_refit(*field, intermediate_mesh))
        {
            report.sponge_genus = refit->genus;
            report.sponge_cells = refit->options.noise_scale_region.cells.size();
            PointCloud samples = field->surfels();
            field.reset();
            PointFieldOptions field_options = refit->options;
            field_options.progress = options.progress;
            field = std::make_unique<const PointField>(std::move(samples), field_options);
            clock.lap("field (noise scale)");
            intermediate_mesh =
                intermediate_mesh_of(*field, bounds, options, report, clock, " (noise scale)");
        }
        report.handles =
            cut_short_handles(intermediate_mesh, options.max_handle * field->median_radius());
        clock.lap("handles");
        SemiRegularOptions semi_regular = options.semi_regular;
        semi_regular.fill_holes = options.fill_holes;
        semi_regular.sample_tree = &field->tree();
        report.semi_regular =
            semi_regular_mesh(intermediate_mesh, *field, &field->surfels(), semi_regular,
                              default_base_share, options.progress, report.coarsening);
    }
    report.stage_seconds.insert(report.stage_seconds.end(),
                                report.semi_regular.stage_seconds.begin(),
                                report.semi_regular.stage_seconds.end());
    return report;
}

std::size_t default_remesh_base_faces(const TriMesh& mesh)
{
    return std::min(mesh.face_count(), std::clamp<std::size_t>(mesh.face_count() / 4, 200, 20000));
}

void check_remesh_input(const TriMesh& mesh)
{
    if (mesh.face_count() == 0)
        throw InvalidInput("the mesh has no triangles (remesh needs a surface mesh)");
    const MeshTopology topo = analyze_topology(mesh);
    if (!topo.is_oriented_manifold() || topo.degenerate_faces > 0)
        throw InvalidInput(
            "not an oriented 2-manifold mesh (" + std::to_string(topo.non_manifold_edges) +
            " edges with more than two triangles, " + std::to_string(topo.non_manifold_vertices) +
            " vertices with several fans, " + std::to_string(topo.misoriented_edges) +
            " misoriented edges, " + std::to_string(topo.degenerate_faces) +
            " degenerate triangles); remesh needs a manifold mesh");
    // What the base mesh cannot take (a vertex of too high valence), before the surfels.
    (void)check_intermediate_mesh(mesh);
}

RemeshReport remesh(const TriMesh& mesh, const RemeshOptions& options)
{
    check_semi_regular_options(options.semi_regular);
    check_remesh_input(mesh);
    RemeshReport report;
    report.input_faces = mesh.face_count();
    report.input_vertices = mesh.vertex_count();
    StageClock clock(report.stage_seconds);
    const std::size_t count =
        options.surfels.samples > 0 ? options.surfels.samples : mesh.vertex_count();
    check_memory(bytes_per_field_surfel * static_cast<double>(count + mesh.vertex_count()),
                 "a point field of " + std::to_string(count + mesh.vertex_count()) +
                     " surfels (the vertices and --samples)",
                 "use fewer --samples");
    SurfelsFromMesh made = surfels_from_mesh(mesh, options.surfels);
    report.vertex_surfels = made.vertex_surfels;
    report.area_surfels = made.area_surfels;
    clock.lap("surfels");
    const PointField field(std::move(made.surfels), {.fit = options.fit});
    clock.lap("field");

    // The input is already the intermediate mesh: simplify it.
    SemiRegularOptions semi_regular = options.semi_regular;
    if (!semi_regular.base_faces)
        semi_regular.base_faces = default_remesh_base_faces(mesh);
    TriMesh intermediate = mesh;
    intermediate.vertices.normals.clear();
    intermediate.vertices.colors.clear();
    intermediate.vertices.radii.clear();
    report.semi_regular = semi_regular_mesh(intermediate, field, &field.surfels(), semi_regular,
                                            default_base_share, options.progress);
    report.stage_seconds.insert(report.stage_seconds.end(),
                                report.semi_regular.stage_seconds.begin(),
                                report.semi_regular.stage_seconds.end());
    return report;
}

} // namespace pointform
