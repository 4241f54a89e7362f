// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include "pointform/core/progress.h"
#include "pointform/geometry/multires_mesh.h"
#include "pointform/geometry/point_cloud.h"
#include "pointform/implicit/field.h"
#include "pointform/metrics/sampling_density.h"
#include "pointform/spatial/kd_tree.h"

#include <cstddef>
#include <optional>
#include <string_view>
#include <vector>

namespace pointform {

/// \brief Which tangential move the relaxation (§5.2.3) makes with a new vertex.
enum class Relaxation
{
    /// The part of the umbrella move across the parent edge (tangential and perpendicular to
    /// the edge), the default. It evens out the shape of the two faces beside the edge as the
    /// umbrella does, but keeps the ratio in which the vertex splits its parent edge. Old
    /// vertices never move, so the umbrella's move along the edge is not undone by later
    /// levels: next to base vertices whose valence is not 6 it shrinks or grows the same
    /// children every level, and the sizes compound. On a sampled sphere refined to level 3
    /// the full umbrella left triangles 100× smaller than the mean and doubled the largest
    /// distance to the surface; this move keeps the base mesh's size ratios.
    AcrossEdge,
    /// The paper's move: the whole tangential part of the move to the 1-ring's average.
    Umbrella,
};

/// \brief Parses "across" or "umbrella". \throw InvalidInput otherwise
[[nodiscard]] Relaxation parse_relaxation(std::string_view text);
[[nodiscard]] std::string_view to_string(Relaxation relaxation);

/// \brief When refine() stops.
enum class StopRule
{
    /// The default: refine while the next level would still change the mesh by more than the
    /// field's own accuracy, and stay within the vertex budget. It stops at whichever comes
    /// first:
    /// - the next level would have more vertices than RefineOptions::vertex_budget (by default
    ///   the number of samples: a mesh with more vertices than samples holds no more of the
    ///   shape than the samples do);
    /// - the next level's details would be small: the robust mean of |f| at the midpoints of the
    ///   finest level's edges, where the next level puts its new vertices before projecting
    ///   them (RefineLevelStats::next_detail), is at most detail_factor times the field's own
    ///   residual at the samples (RefineReport::field_residual: the noise of a noisy scan), and
    ///   never less than a thousandth of the sampling density (the threshold,
    ///   RefineReport::detail_threshold). A finer level would move the mesh by less than the
    ///   field itself is sure of;
    /// - the next level's details are those of noise: below the field's residual, smaller than
    ///   the previous level's by a factor above noise_decay (0.35), and none well above the
    ///   residual (the 99th percentile of |f| at the midpoints at most tail_factor times it). On
    ///   a smooth surface each level's details are about a quarter of the last (the chord error
    ///   goes with the square of the edge length); where they shrink by half or less, the levels
    ///   follow the roughness that noise leaves in the field (0.35 lies between the two, near
    ///   their geometric mean). Measured on the noisy inputs of bench/peers (100k samples, noise
    ///   0.2% of the diagonal, 8 holes): from level 1 to 2 the details shrank by 0.46-0.53 and
    ///   level 2 was farther from the truth than level 1 on every one (Chamfer, % of the
    ///   diagonal: torus 0.087 vs 0.095, thin plate 0.111 vs 0.117, CAD-like part 0.098 vs
    ///   0.101, blobby 0.100 vs 0.104), with four times the vertices; a factor of 0.5 let three
    ///   of the four go on. A thin plate's flat faces shrink their details by half too, but where
    ///   a coarse level's chords cut the plate's rims the 99th percentile stays 3-5 times the
    ///   residual, and the tail makes this rule go on.
    /// Both are measured before a level is made, so no level is made in vain. Unlike the
    /// paper's rule, no single sample decides: creases, noise, outliers and the rims of holes,
    /// where the largest distance stays above the sampling density at any level, do not drive
    /// the depth.
    Automatic,
    /// The paper's rule (§5.2.4) as the paper states it: stop once the one-sided Hausdorff
    /// distance from the samples is below the sampling density; also stop when a level lowers
    /// it by less than min_improvement (that level is not kept).
    Paper,
    /// Refine exactly to max_level, measuring every level.
    Exact,
};

/// \brief Parses "auto", "paper" or "exact". \throw InvalidInput otherwise
[[nodiscard]] StopRule parse_stop_rule(std::string_view text);
[[nodiscard]] std::string_view to_string(StopRule rule);

/// The most smoothing rounds RefineOptions::denoise_rounds takes.
inline constexpr std::size_t max_denoise_rounds = 1000;

/// \brief Options of refine_once() and refine().
struct RefineOptions
{
    /// Where new vertices start (Predictor, pointform/geometry/multires_mesh.h). A hierarchy
    /// records it when its first level is made; later levels must use the same.
    Predictor predictor = Predictor::Midpoint;
    /// The search for the zero crossing along ±(edge normal) from the prediction reaches at most
    /// this multiple of the parent edge's length (§5.2.2: "bounded by the local edge length").
    double search_scale = 1.0;
    /// Rounds of relaxation (§5.2.3): each moves every projected new vertex by the tangential
    /// part of the move to the average of its 1-ring (umbrella; see `relaxation` for which
    /// part), then projects it again; a move that folds a face or finds no crossing is undone.
    /// 0 = none.
    int relax_iterations = 1;
    Relaxation relaxation = Relaxation::AcrossEdge;
    /// After the relax_iterations rounds (when there are any), this many more of the new
    /// vertices of thin child faces only (an angle under 20°), so that the base mesh's thin
    /// triangles, which 1-to-4 splits copy at every level, are opened where relaxation can open
    /// them, at the cost of a round of a few vertices. 0 = none.
    int thin_relax_iterations = 2;
    /// A child face is folded when the cosine between its normal and its parent face's normal is
    /// at most this (0: the child faces away from its parent, or is degenerate), and so is the
    /// cosine with the field's gradient at the child's centroid (where the field is defined).
    double fold_cosine = 0.0;
    /// refine(): the finest level J to reach at most (the level cap, `--levels J`).
    std::size_t max_level = 6;
    /// refine(): which rule stops the refinement.
    StopRule stop_rule = StopRule::Automatic;
    /// refine(), StopRule::Automatic: the most vertices the finest level may have; 0 = the number
    /// of samples.
    std::size_t vertex_budget = 0;
    /// refine(), StopRule::Automatic: the next level is made only while its expected details
    /// exceed this multiple of the field's residual at the samples; in (0, 1].
    double detail_factor = 0.1;
    /// refine(), StopRule::Automatic: details below the field's residual that shrink by less
    /// than this factor per level are the field's noise; in (0, 1).
    double noise_decay = 0.35;
    /// refine(), StopRule::Automatic: ... unless the largest of them (the 99th percentile of |f|
    /// at the midpoints where f is defined) exceed this multiple of the field's residual: then
    /// some of the surface (a thin part's rim, a crease, a small feature) is still well off the
    /// mesh, by more than noise moves the field, and the next level is made; at least 1. Rims
    /// cut by a coarse level's chords keep it at 3-5; noise and resolved rims alone reach 2-3
    /// (a noisy plate whose level 2 was 10% farther from the truth than level 1:
    /// tests/polygonize/noisy_plate_stop_test.cpp).
    double tail_factor = 4.0;
    /// refine(), StopRule::Automatic: when the refinement stops because the next level's details
    /// would be noise (RefineStop::NoisyDetails), the vertices of the finest level take this many
    /// rounds of Taubin's λ|μ smoothing (λ = 0.5, μ = −0.53: each vertex towards, then away from,
    /// the mean of its neighbours, which removes the field's noise that the zero set still
    /// carries at the mesh's own scale without shrinking the surface; boundary vertices held;
    /// creases kept: where the level's faces meet at more than 30° and more than the noise turns
    /// them (three times atan(field residual / edge length)), a vertex on two such edges
    /// moves along them only and one on one or three or more, a corner, is held; on the noisy
    /// part of bench/peers Chamfer 0.0818 -> 0.0762 and F@0.5% 0.9980 -> 0.9985 against the
    /// smoothing across them; tests/polygonize/noisy_plate_stop_test.cpp).
    /// Levels that end for any other reason (clean scans) are left as projected. Measured on the
    /// noisy inputs with holes of bench/peers (100k samples, noise 0.2% of the diagonal, level
    /// 1), Chamfer to the truth in % of the diagonal with 0 / 5 / 10 rounds before creases were
    /// kept: sphere 0.0712 / 0.0546 / 0.0492, blobby 0.0841 / 0.0702 / 0.0666, part 0.0900 /
    /// 0.0837 / 0.0886 (its creases rounded off past 5), plate 0.0954 / 0.0832 / 0.0819. With
    /// creases kept, 5 / 10 / 20 / 40 rounds (default seed): sphere 0.0535 / 0.0481 / 0.0437 /
    /// 0.0439, blobby 0.0657 / 0.0606 / 0.0566 / 0.0631, part 0.0751 / 0.0728 / 0.0723 /
    /// 0.0756, torus 0.0534 / 0.0478 / 0.0430, plate 0.0717 / 0.0683 / 0.0656; a second seed
    /// alike (10 against 5: 0.90-0.97 of the Chamfer on all five), Hausdorff within the
    /// evaluation's noise, F@0.5% within 0.0001; the 1M noisy sphere and part (level 2) 0.0586
    /// → 0.0543 and 0.0587 → 0.0547 with 10. Not 20: λ + μ < 0 lifts the smooth shape a
    /// little each round, which offsets the chords' sag inside a curved surface at first and
    /// overshoots it on a coarse level (a 20k-sample noisy sphere at 3k vertices: Chamfer
    /// 0.0546 / 0.0473 / 0.0547 with 5 / 10 / 20 rounds; taking the lift back left 0.0591 at
    /// 20, the sag uncovered). 0 = never.
    std::size_t denoise_rounds = 10;
    /// refine(), StopRule::Automatic: fair the finest level where no sample supports it. The
    /// regions of vertices far from every sample (a filled hole, BaseMeshOptions::fill_holes,
    /// and the band around it where the field extrapolates the rim's last, often noisy, fits:
    /// farther than 2 local sample spacings, with an interior vertex or one farther than 5
    /// (a spike), grown through the neighbours farther than 0.75 spacings, as far as 14 of the
    /// cloud's median spacings along the mesh) take, each on its own, the smoothest surface that
    /// continues the mesh around them (thin-plate fairing, the rest held), or a membrane where
    /// the region's rim is flat and the surface leaves its plane steeply (a face the scanner
    /// never saw, whose creases the mesh rounds; see fill_for_rim() in
    /// src/polygonize/thin_plate.h); a thin plate whose rim's normals part into two or three
    /// nearly flat faces of one kind of crease (a hole over an edge, a plate's rim, a seam) is
    /// then moved onto where those faces, fitted to the rim and carried across, meet (see
    /// crease_fill_for_rim() in src/polygonize/crease_fill.h). All are relaxed along their
    /// surface with the two rings of held vertices around them. Measured on the noisy inputs with
    /// holes of bench/peers (100k samples) when it came in (with a core of 2.5 and a band of 3
    /// rings beyond 1.5 spacings): symmetric Hausdorff to the truth, % of the diagonal, without /
    /// with: sphere 0.48 / 0.37, plate 1.22 / 0.75, part 1.35 / 1.17; the shipped bunny scan,
    /// Chamfer to bun_zipper 0.0715 / 0.0651 (0.0490 with today's rule). Done before the
    /// smoothing of denoise_rounds, which smooths the faired vertices across creases.
    bool fair_unsupported = true;
    /// refine(), StopRule::Automatic, a finest level that is not smoothed (denoise_rounds): fit
    /// its flat faces to the field's zero set in the least-squares sense instead of only their
    /// corners. Projected vertices interpolate the surface, so every face of a curved part sags
    /// inside it (by about l² / (8 R) for edges of length l on a radius R) and the whole mesh
    /// lies to one side of the samples; each vertex moves along its normal by the mean step, over
    /// its faces (weighted by area and barycentric share, at the three points of the rule exact
    /// for quadratics), that would take the faces onto the zero set: by the sag, on a uniformly
    /// curved part. Only the finest level's own vertices move (the coarser levels keep theirs on
    /// the field, as they were measured); those on a boundary, on a crease edge (faces meeting at
    /// more than 30°) or in a faired region are held; a move is at most a quarter of the
    /// vertex's mean edge; and no vertex moves when the median move is below a quarter of the
    /// field's residual at the samples (noisy scans: the moves would follow the field's noise
    /// more than the sag). Measured
    /// on the clean 100k inputs of bench/peers (Chamfer to the truth, % of the diagonal, without
    /// / with): see the README's `reconstruct` section. A smoothed (noisy) level is left as
    /// smoothed: fitted to the field of noisy samples, a 100k noisy sphere's Chamfer went from
    /// 0.0457 to 0.0607. false = the paper's interpolating level.
    bool fit_faces = true;
    /// refine(): stop once the one-sided Hausdorff distance from the samples to M^J is below
    /// this, in world units (§5.2.4). 0 = estimate_sampling_density(samples)
    /// (pointform/metrics/sampling_density.h).
    double sampling_density = 0.0;
    /// refine(): a k-d tree over the samples' own positions (built on `samples.positions`, as
    /// PointField::tree() is on its surfels), which the sampling density and the fairing then
    /// use instead of building one; null = build one. A tree over other storage is refused
    /// (InvalidInput).
    const KdTree* sample_tree = nullptr;
    /// refine(), StopRule::Paper: also stop when a level lowers the Hausdorff distance by less than
    /// this fraction of the previous level's: the samples that stay far are where no refinement
    /// reaches (outliers, noise, samples beyond a hole's rim), and each further level would
    /// quadruple the faces for nothing. 0 disables (refine to max_level unless the density is
    /// reached).
    double min_improvement = 0.05;
    /// Optional progress report and cancellation, per stage of each level.
    ProgressCallback progress;
};

/// \brief The finest level's regions that no sample supports, faired
/// (RefineOptions::fair_unsupported).
struct UnsupportedFairing
{
    std::size_t regions = 0;   ///< connected regions faired
    std::size_t membranes = 0; ///< of those, the ones faired as a membrane (the rest thin plates)
    std::size_t creases = 0;   ///< of the thin plates, those moved onto the faces of a crease
    std::size_t vertices = 0;  ///< their vertices
    double max_move = 0.0;     ///< the farthest a vertex moved, world units
};

/// \brief What one refinement M^i → M^(i+1) did.
struct RefineLevelStats
{
    std::size_t level = 0;        ///< the level made, i + 1
    std::size_t faces = 0;        ///< faces of the new level
    std::size_t vertices = 0;     ///< vertices of the new level (all levels' vertices)
    std::size_t new_vertices = 0; ///< vertices the split added
    /// New vertices of a folded child face after projection along AW_FEN (§5.2.2) ...
    std::size_t fold_vertices = 0;
    /// ... of which projection along the vertex-based edge normal VEN removed the fold ...
    std::size_t folds_fixed_by_ven = 0;
    /// ... and of which neither did: VEN found no crossing, or the face stayed folded. These,
    /// and neighbours whose faces fold in turn, went back to the prediction, or to the edge
    /// midpoint if the prediction folds too; they are off the surface and also counted in
    /// `unprojected`.
    std::size_t folds_unresolved = 0;
    /// New vertices that stayed off the surface, at the prediction: no crossing within reach
    /// (the field is undefined there: a hole) or an unresolved fold.
    std::size_t unprojected = 0;
    /// Relaxation moves kept (summed over the rounds).
    std::size_t relaxed = 0;
    /// Relaxation moves undone because they folded a face or found no crossing.
    std::size_t relax_undone = 0;
    /// Child faces still folded at the end (cosine to the parent's normal ≤ fold_cosine);
    /// 0 unless a prediction itself folds.
    std::size_t folded_faces = 0;
    /// One-sided Hausdorff distance max_s d(s, M^(i+1)) from the samples, world units; set
    /// when samples were given.
    std::optional<double> hausdorff;
    /// Mean distance from the samples to M^(i+1); set when samples were given.
    std::optional<double> mean_distance;
    /// The robust distance from the samples to M^(i+1): the mean of the smallest 95% of the
    /// sample-to-mesh distances (the largest 5%, where outliers, hole rims and creases sit, left
    /// out); set when samples were given.
    std::optional<double> robust_distance;
    /// The 90th percentile of the sample-to-mesh distances; set when samples were given.
    std::optional<double> p90_distance;
    /// refine(), StopRule::Automatic: the expected detail of the level after this one, the mean
    /// of the smallest 95% of |f| at the midpoints of this level's edges.
    std::optional<double> next_detail;
    /// Wall-clock seconds of this refinement, the distance measurement included.
    double seconds = 0.0;
};

/// \brief Why refine() stopped.
enum class RefineStop
{
    BelowSamplingDensity, ///< the Hausdorff distance fell below the sampling density (§5.2.4)
    LevelCap,             ///< options.max_level was reached first
    /// Paper: a level lowered the Hausdorff distance by less than min_improvement; that level
    /// was not kept (RefineReport::dropped).
    Stalled,
    VertexBudget, ///< Automatic: the next level would exceed the vertex budget
    SmallDetails, ///< Automatic: the next level's details would be below the detail threshold
    NoisyDetails, ///< Automatic: the next level's details would be those of the field's noise
};

[[nodiscard]] std::string_view to_string(RefineStop stop);

/// \brief The outcome of refine().
struct RefineReport
{
    /// One entry per level made, coarse to fine.
    std::vector<RefineLevelStats> levels;
    /// Hausdorff distance, mean, robust distance and 90th percentile from the samples to the
    /// finest level that refine() started from.
    double initial_hausdorff = 0.0;
    double initial_mean_distance = 0.0;
    double initial_robust_distance = 0.0;
    double initial_p90_distance = 0.0;
    /// The rule that stopped it.
    StopRule stop_rule = StopRule::Automatic;
    /// StopRule::Automatic: the vertex budget used (options or the number of samples).
    std::size_t vertex_budget = 0;
    /// StopRule::Automatic: the field's own distance from the samples, the same robust
    /// statistic over |f(s)| (|∇f| ≈ 1 near the surface): the mean of the smallest 95%. Over
    /// every sample up to 2^19; over every k-th (in the samples' order, at least 2^18 of them)
    /// beyond, where the statistic is as certain and a full pass costs seconds.
    double field_residual = 0.0;
    /// StopRule::Automatic: max(detail_factor · field_residual, 0.001 · sampling_density).
    double detail_threshold = 0.0;
    /// StopRule::Automatic: the next level's expected detail at the level refine() started from.
    double initial_next_detail = 0.0;
    /// The first level (0 = the one refine() started from) whose Hausdorff distance from the
    /// samples is below the sampling density, the paper's stop (§5.2.4); unset if none of the
    /// levels made (the dropped one included) reached it. Under StopRule::Automatic a level
    /// is measured as it is output: the finest after its smoothing (denoise_rounds).
    std::optional<std::size_t> paper_level;
    /// Rounds of smoothing given to the finest level (RefineOptions::denoise_rounds), 0 if none;
    /// the finest level's distances (levels.back(), or initial_* for the base) are measured
    /// after them.
    std::size_t denoise_rounds = 0;
    /// The farthest the smoothing moved a vertex, world units.
    double denoise_max_move = 0.0;
    /// Vertices of the finest level moved by the least-squares fit of its faces
    /// (RefineOptions::fit_faces), 0 if none; the finest level is measured after.
    std::size_t face_fit_vertices = 0;
    /// The farthest that fit moved a vertex, world units.
    double face_fit_max_move = 0.0;
    /// The median of the moves that fit asked for, world units: none is made when it is below a
    /// quarter of field_residual (the moves would follow the field's noise more than the faces'
    /// sag); 0 if the fit did not run.
    double face_fit_median_move = 0.0;
    /// When face_fit_median_move is the median of the moves of a sample of the level's free
    /// vertices only (evenly spread; far enough below the bar that the whole fit was not
    /// measured, and no fit is made), the number of moves in that sample; 0 when it is the
    /// whole level's.
    std::size_t face_fit_probes = 0;
    /// Vertices of the finest level that stood off their neighbours' surface alone (a spike or
    /// dent on a narrow step of the field, such as the blend between two local fits at a
    /// concave crease) and were put back on the field from their neighbours' centroid, after
    /// the fairing and the smoothing (automatic stop only); the finest level is measured after.
    std::size_t spikes = 0;
    /// The regions of the finest level that no sample supports, faired
    /// (RefineOptions::fair_unsupported); the finest level is measured after.
    UnsupportedFairing unsupported;
    /// A level that was made and measured but not kept (Stalled).
    std::optional<RefineLevelStats> dropped;
    /// The threshold used: options.sampling_density, or the estimate.
    double sampling_density = 0.0;
    RefineStop stop = RefineStop::LevelCap;
};

/// \brief One refinement M^J → M^(J+1) of the finest level (§5.2).
///
/// 1. Split: every face 1-to-4 (MultiresMesh::split); the new vertex of edge e starts at the
///    prediction (options.predictor).
/// 2. Project: along ±AW_FEN(e), the area-weighted normal of e's one or two faces, to the
///    nearest zero crossing where AW_FEN·∇f > 0 (project_to_zero), the search bounded by
///    search_scale × |e|.
/// 3. Folds: a child face whose normal is against its parent face's normal (cosine ≤
///    fold_cosine) and against the field's gradient at its centroid as well (or degenerate, or
///    the field undefined there) marks its new vertices; a parent that straddles a crease has
///    children turned by up to the crease's angle from it, which agree with the field. The
///    marked vertices are projected again from the prediction along VEN(e), the normalised sum
///    of the area-weighted vertex normals of e's ends (§5.2.2). A vertex still in a folded face
///    goes to the nearest point of f = 0 (Newton steps), else back to the prediction (then to
///    the midpoint).
/// 4. Relax (§5.2.3): relax_iterations rounds of the tangential umbrella move of every projected
///    new vertex towards the average of its 1-ring in M^(J+1) (on the boundary: of its two
///    boundary neighbours; tangent plane: the vertex's area-weighted normal; by default only
///    the part across the parent edge, see Relaxation), each followed by re-projection along
///    that normal; moves that fold a face or lose the surface are undone. Then
///    thin_relax_iterations rounds of the same move for the new vertices of child faces with an
///    angle under 20° only.
/// Old vertices never move. Where no crossing is found (the field undefined: a hole), the new
/// vertex keeps its prediction and is counted in `unprojected`. Every per-vertex step runs in
/// parallel into its own slot (Jacobi style), so the result does not depend on the thread
/// count.
/// \param samples  optional; when given, the stats carry the one-sided Hausdorff distance from
///                 them to M^(J+1)
/// \throw InvalidInput if the hierarchy is empty, an option is out of range (search_scale not
///        positive and finite, fold_cosine outside [-1, 1), relax_iterations or
///        thin_relax_iterations < 0,
///        sampling_density negative or not finite, min_improvement outside [0, 1),
///        detail_factor outside (0, 1], noise_decay outside (0, 1)) or the new
///        level would overflow 32-bit indices
/// \throw Cancelled if the progress callback asks to stop (the new level is then removed)
RefineLevelStats refine_once(MultiresMesh& mesh, const Field& field,
                             const RefineOptions& options = {},
                             const PointCloud* samples = nullptr);

/// \brief Refines the finest level until options.stop_rule says stop (StopRule), at most to
/// options.max_level. Checks the rule on the starting level first, so a hierarchy that already
/// fits is left as it is. A level that stalls is measured, removed again and reported in
/// RefineReport::dropped. With StopRule::Exact, `samples` may be empty: then it refines to
/// max_level measuring nothing (no distances, no sampling density, as refine_once() without
/// samples), e.g. on a modeled surface.
/// \throw InvalidInput as refine_once(), or if `samples` is empty and the rule is not Exact
/// \throw Cancelled if the progress callback asks to stop
RefineReport refine(MultiresMesh& mesh, const Field& field, const PointCloud& samples,
                    const RefineOptions& options = {});

} // namespace pointform
