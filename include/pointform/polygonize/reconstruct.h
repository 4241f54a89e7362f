// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// The pipeline from surfels or a mesh to a semi-regular multiresolution mesh (§5, §6), each
// step one function with an options struct and a returned report: what `pointform
// reconstruct`, `pointform remesh` and `pointform model --semi-regular` run.

#pragma once

#include "pointform/core/progress.h"
#include "pointform/geometry/mesh_topology.h"
#include "pointform/geometry/multires_mesh.h"
#include "pointform/geometry/point_cloud.h"
#include "pointform/geometry/tri_mesh.h"
#include "pointform/hermite/surfels.h"
#include "pointform/implicit/field.h"
#include "pointform/implicit/point_field.h"
#include "pointform/metrics/quality.h"
#include "pointform/polygonize/base_mesh.h"
#include "pointform/polygonize/components.h"
#include "pointform/polygonize/handles.h"
#include "pointform/polygonize/refine.h"

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace pointform {

/// The level cap of refine_semi_regular() without SemiRegularOptions::levels.
inline constexpr std::size_t default_max_level = 6;
/// The most levels SemiRegularOptions::levels may ask for (level 8 has 65536 times the base
/// mesh's faces).
inline constexpr std::size_t max_exact_levels = 8;

/// \brief Options of the semi-regular mesh (§5): its base mesh and its refinement.
struct SemiRegularOptions
{
    /// Faces of the automatic base mesh, at least 1 and at most the intermediate mesh's; unset =
    /// base_face_target()'s default.
    std::optional<std::size_t> base_faces;
    /// Refine exactly to level J (0 = the base mesh only), at most max_exact_levels; unset =
    /// until `stop_rule` says so, at most to default_max_level (lower where that would not fit
    /// in memory).
    std::optional<std::size_t> levels;
    /// The rule without `levels`: Automatic or Paper (StopRule); Exact is what `levels` asks.
    StopRule stop_rule = RefineOptions{}.stop_rule;
    Predictor predictor = RefineOptions{}.predictor;
    /// Rounds of relaxation per level (§5.2.3), 0 = none.
    int relax_iterations = RefineOptions{}.relax_iterations;
    Relaxation relaxation = RefineOptions{}.relaxation;
    /// Smoothing rounds of a finest level that stopped on noise (RefineOptions::denoise_rounds).
    std::size_t denoise_rounds = RefineOptions{}.denoise_rounds;
    /// Fair the regions no sample supports (RefineOptions::fair_unsupported).
    bool fair_unsupported = RefineOptions{}.fair_unsupported;
    /// Fit the finest level's faces to the field's zero set (RefineOptions::fit_faces).
    bool fit_faces = RefineOptions{}.fit_faces;
    /// Holes of the automatic base mesh filled (BaseMeshOptions::fill_holes); 0 = none.
    double fill_holes = 0.0;
    /// Long chords of the automatic base mesh split (BaseMeshOptions::chord_split_share).
    double chord_split_share = BaseMeshOptions{}.chord_split_share;
    /// A k-d tree over the samples' own positions for the refinement
    /// (RefineOptions::sample_tree); null = it builds one.
    const KdTree* sample_tree = nullptr;
};

/// \brief A semi-regular mesh and how it was made.
struct SemiRegularReport
{
    /// Level 0 is the base mesh M0; the finest level is the result.
    MultiresMesh hierarchy;
    /// The refinement (refine()): report.initial_* describe M0, one entry per level made,
    /// report.dropped a level that stalled (measured, not kept), report.stop why it stopped
    /// (LevelCap with `levels`).
    RefineReport refinement;
    /// The automatic base mesh's statistics (unset when the caller gave the base mesh).
    std::optional<BaseMeshStats> base;
    /// Vertices of M0 off the surface, and seconds spent making M0.
    std::size_t base_unprojected = 0;
    double base_seconds = 0.0;
    /// Refined exactly to SemiRegularOptions::levels.
    bool exact_levels = false;
    /// The level cap used (`levels` itself when exact).
    std::size_t level_cap = 0;
    /// The cap was lowered below default_max_level to fit in memory.
    bool cap_from_memory = false;
    /// Distances were measured from samples (the refinement's figures are set).
    bool measured = false;
    /// The samples' count and bounding-box diagonal (0 without samples).
    std::size_t sample_count = 0;
    double diagonal = 0.0;
    /// Wall-clock seconds by stage, in order: "base mesh" (when built here), "refinement".
    std::vector<std::pair<std::string, double>> stage_seconds;
};

/// The automatic base mesh's marching cubes has about this many faces per face of the base
/// mesh it is simplified to, at most (reconstruct(), intermediate_face_limit()): its grid is
/// coarsened (intermediate_grid()) where the field's own would make more. The base mesh needs
/// the intermediate mesh's shape and topology at its own scale only; refinement projects every
/// finer vertex onto the field. Against the field's own grid up to max_intermediate_faces (16
/// faces a base face at the default share), on simulated scans of three shapes at seeds not
/// tuned on (fandisk and spot at 11-15, the teapot at 4-8; bench/peers/virtual_scan.py): mean
/// F@0.5% 0.9709 -> 0.9734, Chamfer 0.0935 -> 0.0909% of the diagonal, triangles under 20°
/// 0.67% -> 0.32% (at most 4.00% -> 1.84%), 18% less time.
inline constexpr double intermediate_faces_per_base_face = 8.0;

/// \brief The most faces the automatic base mesh's intermediate mesh should have:
/// intermediate_faces_per_base_face times the base-face target expected from the field's
/// estimated area at `cell` (the target base_face_target() would give an intermediate mesh
/// of that many faces, fitted to a vertex budget of `samples` under the automatic stop), at
/// most max_intermediate_faces.
[[nodiscard]] double intermediate_face_limit(const PointField& field, double cell,
                                             const SemiRegularOptions& options,
                                             std::size_t samples);

/// \brief The automatic base mesh's face target for `intermediate`: options.base_faces
/// (checked: at least 1 and at most the intermediate mesh's faces), or else
/// default_base_faces(intermediate, share), which without `levels` and with the Automatic stop
/// is fitted to a vertex budget of `samples` (fit_base_faces_to_budget()) when `samples` > 0.
/// \throw InvalidInput for a base_faces out of range
[[nodiscard]] std::size_t base_face_target(const SemiRegularOptions& options,
                                           const TriMesh& intermediate,
                                           std::size_t share = default_base_share,
                                           std::size_t samples = 0, double coarsening = 1.0);

/// \brief About how many bytes refining `base_faces` faces to `level` takes (256 per face of
/// that level: positions, parent edges, the level below, the output, the distance BVH).
[[nodiscard]] double estimate_refinement_bytes(std::size_t base_faces, std::size_t level);

/// \brief Refuses, before anything is allocated, a level whose F0·4^J faces would not fit in
/// memory (check_memory()) or in 32-bit indices.
/// \throw InvalidInput saying how much it would need
void check_refinement_memory(std::size_t base_faces, std::size_t level);

/// \brief The deepest level ≤ `cap` whose faces fit in memory (at least 0).
[[nodiscard]] std::size_t affordable_level(std::size_t base_faces, std::size_t cap);

/// \brief Refines `base` on `field` to a semi-regular mesh (§5.2): exactly to options.levels,
/// or until options.stop_rule says so (refine()), at most to default_max_level or the deepest
/// level that fits in memory. A level that stalls under StopRule::Paper is measured and dropped
/// (RefineReport::dropped).
/// \param samples  the samples distances are measured from (usually the field's surfels); may be
///                 null only with options.levels (then nothing is measured)
/// \throw InvalidInput for options out of range, no samples without levels, or a level that
///        would not fit in memory; Cancelled if `progress` asks to stop
[[nodiscard]] SemiRegularReport refine_semi_regular(const TriMesh& base, const Field& field,
                                                    const PointCloud* samples,
                                                    const SemiRegularOptions& options,
                                                    const ProgressCallback& progress = {});

/// \brief An intermediate mesh of `field` (e.g. marching cubes) to a semi-regular mesh: the
/// base mesh simplified from it (build_base_mesh(), base_face_target() with `share` and the
/// samples' count; an intermediate mesh made on a grid `coarsening` times the field's counts
/// as coarsening² times its faces, see intermediate_grid()), then refine_semi_regular().
/// \throw InvalidInput as base_face_target(), check_intermediate_mesh(), build_base_mesh() and
///        refine_semi_regular()
[[nodiscard]] SemiRegularReport semi_regular_mesh(const TriMesh& intermediate, const Field& field,
                                                  const PointCloud* samples,
                                                  const SemiRegularOptions& options,
                                                  std::size_t share = default_base_share,
                                                  const ProgressCallback& progress = {},
                                                  double coarsening = 1.0);

/// \brief |f| at a mesh's vertices, where the field is defined: how near its zero set they lie.
struct VertexResidual
{
    double max = 0.0;
    double mean = 0.0;
    std::size_t defined = 0; ///< vertices where the field is defined and finite
};
[[nodiscard]] VertexResidual field_residual_at_vertices(const TriMesh& mesh, const Field& field);

/// \brief ReconstructOptions::max_handle by default: a loop of 6 median influence radii is a
/// tube of radius 0.95 of one. On 100k noisy 45° cones (0.2% noise) the handles' loops were
/// 0.7-7.7 radii long, most under 4; real handles measured 11-14 (a teapot scan's), and over 40
/// (a 100k torus and the part). At 4 (until the fifty-third session) twelve such cones kept 16
/// handles in all, at 6 they keep 5, with the same mean Chamfer to the cone (0.0892% of the
/// diagonal); the clean samples of data/meshes/teapot.obj 5 -> 4, the two shipped bunny range
/// scans merged 7 -> 4.
inline constexpr double default_max_handle = 6.0;
/// \brief The largest ReconstructOptions::max_handle: a longer loop is no topological noise (and
/// the search from every vertex grows with the square of the length).
inline constexpr double max_handle_radii = 64.0;

/// \brief Options of reconstruct(): surfels → field → marching cubes → base mesh → refinement.
struct ReconstructOptions
{
    /// The local surfaces of the field.
    PlaneFit fit = PointFieldOptions{}.fit;
    /// How far past a rim of the samples the field reaches (PointFieldOptions::rim_reach), in
    /// (0, 1]; 1 = a whole influence radius, the paper's field.
    double rim_reach = PointFieldOptions{}.rim_reach;
    /// Marching cubes: cells along the longest side of the samples' bounding box (≥ 2), or
    /// else the cell size (> 0), or else (both 0) intermediate_grid() of default_cell_size():
    /// the field's cell, coarsened where that would make more faces than the base mesh needs.
    int resolution = 0;
    double cell = 0.0;
    /// Marching-cubes components that fewer samples are nearest to are removed before the base
    /// mesh; unset = default_min_component_samples(), 0 keeps every component.
    std::optional<std::size_t> min_component_samples;
    /// A picked base mesh (§5.1, Fig. 6; read_picked_base_mesh()) instead of the automatic one;
    /// empty = automatic (then marching cubes and the debris removal run).
    std::filesystem::path base_mesh;
    /// A picked base mesh given as points that snap to the nearest samples
    /// (snap_picked_base_mesh(); what `pointform view` sends), instead of a file; at most one of
    /// `base_mesh` and `picked_vertices`.
    PickedVertices picked_vertices;
    /// The automatic base mesh's holes that are filled: boundary loops enclosing at most this
    /// fraction of their component's area (BaseMeshOptions::fill_holes), in [0, 1); 0 keeps
    /// every hole. Replaces semi_regular.fill_holes.
    double fill_holes = 0.05;
    /// The intermediate mesh's handles whose loop is at most this many median influence radii
    /// of the samples long are cut and capped (cut_short_handles(), topological noise); 0 keeps
    /// every handle. A tube that short is narrower than the fits that make it: the field's
    /// tunnels where sheets meet past their samples (a sharp rim under noise, a scan's step).
    double max_handle = default_max_handle;
    SemiRegularOptions semi_regular;
    ProgressCallback progress;
};

/// \brief What reconstruct() made and every figure of how.
struct ReconstructReport
{
    /// The semi-regular mesh; semi_regular.hierarchy holds every level.
    SemiRegularReport semi_regular;
    /// The automatic base mesh's intermediate mesh: marching cubes at `cell`, its faces and
    /// vertices, its near-zero-area triangles (MarchingCubesStats) and the debris removed.
    double cell = 0.0;
    /// `cell` over the field's cell (intermediate_grid()); 1 on the field's own grid.
    double coarsening = 1.0;
    std::size_t intermediate_faces = 0;
    std::size_t intermediate_vertices = 0;
    /// Triangles dropped past the field's defined region on a coarsened grid, and vertices inside
    /// cells (MarchingCubesStats).
    std::size_t undefined_triangles = 0;
    std::size_t cell_vertices = 0;
    std::size_t degenerate_triangles = 0;
    std::size_t degenerate_kept = 0;
    ComponentFilterReport debris;
    /// The samples that PointField::stray_samples() found stray: not seeds of the marching
    /// cubes, so that the sheets only they hold up are not made.
    std::size_t stray_samples = 0;
    /// The short handles cut from the intermediate mesh (ReconstructOptions::max_handle).
    HandleCutReport handles;
    /// The handles of the first intermediate mesh where it was a sponge, whereupon the field was
    /// made again with PointFieldOptions::noise_scale (and the figures above are its mesh's);
    /// 0 where it was not.
    std::size_t sponge_genus = 0;
    /// The cells of spongy_cells() (its handles and the cells round them) that the field's fits
    /// were made again in; 0: everywhere, or no sponge.
    std::size_t sponge_cells = 0;
    /// The picked base mesh, when ReconstructOptions::base_mesh or picked_vertices was given, and
    /// its angles.
    std::optional<PickedBaseMesh> picked;
    AngleQuality picked_angles;
    /// Wall-clock seconds by stage, in order: "field", then "marching cubes", "debris", "handles",
    /// "base mesh" (automatic) or "base mesh (picked)", then "refinement".
    std::vector<std::pair<std::string, double>> stage_seconds;
};

/// \brief Surfels to a semi-regular multiresolution mesh (§5): their PointField, marching
/// cubes, debris removal and the automatic base mesh (or the picked one), then
/// refine_semi_regular() measured from the surfels.
/// \param surfels  oriented surfels with radii (surfels_from_samples())
/// \throw InvalidInput for bad surfels or options (both a base-mesh file and picked vertices),
///        or work that would not fit in memory;
///        IoError for an unreadable picked base mesh; Error when marching cubes makes no
///        triangle; Cancelled if the progress callback asks to stop
[[nodiscard]] ReconstructReport reconstruct(PointCloud surfels,
                                            const ReconstructOptions& options = {});

/// \brief Options of remesh(): a mesh → surfels → field → base mesh → refinement (§6).
struct RemeshOptions
{
    /// The mesh's surfels (surfels_from_mesh()).
    SurfelsFromMeshOptions surfels;
    PlaneFit fit = PointFieldOptions{}.fit;
    /// base_faces unset = a quarter of the input's faces within [200, 20000]
    /// (default_remesh_base_faces()).
    SemiRegularOptions semi_regular;
    ProgressCallback progress;
};

/// \brief What remesh() made and every figure of how.
struct RemeshReport
{
    SemiRegularReport semi_regular;
    /// The input mesh's faces and vertices.
    std::size_t input_faces = 0;
    std::size_t input_vertices = 0;
    /// Surfels at the vertices and area-uniform ones (SurfelsFromMesh).
    std::size_t vertex_surfels = 0;
    std::size_t area_surfels = 0;
    /// Wall-clock seconds by stage, in order: "surfels", "field", "base mesh", "refinement".
    std::vector<std::pair<std::string, double>> stage_seconds;
};

/// \brief The base-face target of remesh() without base_faces: a quarter of the input's faces
/// (one level restores its resolution), within [200, 20000] and at most its faces. Measured on
/// data/meshes/bunny_uniform.off (17.8k faces): faces / 16 refines to level 6 (4.5M faces,
/// 18 s) before the Hausdorff distance stops improving; faces / 4 reaches the sampling density
/// at level 3 (256k faces, about a second).
[[nodiscard]] std::size_t default_remesh_base_faces(const TriMesh& mesh);

/// \brief Refuses what remesh() cannot take: no triangles, a mesh that is not an oriented
/// 2-manifold or has degenerate triangles, or a vertex of too high valence for the base mesh.
/// \throw InvalidInput saying which
void check_remesh_input(const TriMesh& mesh);

/// \brief An irregular mesh to a semi-regular multiresolution mesh (§6, Fig. 13): its vertices
/// and area-uniform samples become surfels (surfels_from_mesh()), the mesh itself is simplified
/// to the base mesh, which refine_semi_regular() refines on their field, measured from them.
/// \throw InvalidInput as check_remesh_input(), for options out of range, or for work that
///        would not fit in memory; Cancelled if the progress callback asks to stop
[[nodiscard]] RemeshReport remesh(const TriMesh& mesh, const RemeshOptions& options = {});

} // namespace pointform
