// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include "pointform/core/progress.h"
#include "pointform/core/types.h"
#include "pointform/spatial/neighborhoods.h"

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace pointform {

/// \brief How orientation passes from a sample a to its neighbour b, and what the Riemannian graph
/// charges for that edge (the less certain the step, the higher the cost).
enum class OrientationRule
{
    /// Hoppe et al., as in the paper (§4 step 2): b agrees with a when n_a·n_b > 0; cost
    /// 1 − |n_a·n_b|. Fails where two sheets face each other closer than the neighbourhood
    /// size (thin walls) and is blind at creases, where n_a ⟂ n_b.
    Hoppe,
    /// The normal at a, reflected in the bisector plane of the edge e = b − a:
    /// m = n_a − 2 (n_a·ê) ê, is the normal a circle through a and b would have at b. b agrees
    /// with a when n_b·m > 0; cost 1 − |n_b·m|. For neighbours in one tangent plane m = n_a, so
    /// this is Hoppe's rule there; across a thin wall (e along the normals) and around a crease
    /// it predicts the turned normal correctly, where Hoppe's rule flips a whole side. The cost
    /// is symmetric in a and b. Measured: on a clean plate half a sampling step thick it orients
    /// 99.6% of the faces where Hoppe's rule gets 50%, but position noise of a fifth of the
    /// sampling step tilts short edges towards the normal and breaks it (about 60% on a noisy
    /// sphere), so it is for clean, thin-walled data only.
    Reflection,
};

/// \brief Options for orient_normals_mst.
struct OrientationOptions
{
    /// Neighbours of each point in the Riemannian graph (the symmetrised kNN graph); 0 = every
    /// column of the table passed in. Fewer neighbours make a sparser, faster graph.
    std::size_t k = 0;
    /// Propagation rule and edge cost; see OrientationRule.
    OrientationRule rule = OrientationRule::Hoppe;
    /// Tree edges costing more than this (normals more than about acos(1 − patch_cost) apart)
    /// are not trusted to pass orientation on: they cut the spanning trees into patches, which
    /// are then oriented against each other by the summed agreement of every graph edge between
    /// them. 0.3 trusts steps up to about 45°; 2 trusts every edge (plain propagation).
    double patch_cost = 0.3;
    /// Noisy clouds (Hoppe rule only): orientation follows guide normals, PCA normals of each
    /// sample's neighbourhood grown by up to this many rings of the neighbour table (each ring
    /// one pass over all k columns), at the ring where the neighbourhood is flattest; the oriented
    /// guides are then the output normals (where the input normal is usable): the neighbourhood
    /// scale follows the noise. On a 100k-sample sphere with noise of 0.2% of its diagonal the
    /// mean angle to the true normals went from 12.9° (each PCA normal given its guide's sign,
    /// 10 of them inside out) to 1.8° (none), and its marching-cubes mesh from 9 components
    /// and 9 boundary loops to one closed sphere. Noise of twice the sampling step leaves PCA
    /// normals 40° off and their signs to chance, while the guide's averages it out: on 1M noisy
    /// samples with holes, 88.3% → 98.2% oriented on a torus, 94.1% → 98.5% on a sphere (2
    /// rings: 97.7% and 98.0%). A cloud whose neighbourhoods are mostly flat (median surface
    /// variation about that of noise of 1/17 of the neighbourhood radius; clean scans are flatter)
    /// is oriented by its own normals, so thin walls and sharp features of clean data keep their
    /// fine scale. 0 = never guide.
    std::size_t guide_rings = 4;
    /// Guided clouds whose neighbourhoods are still thick with noise after guide_rings rings
    /// (median flatness above about that of noise of a seventh of the grown neighbourhood's
    /// radius) grow them further, up to this many rings in all: the denser the samples are for
    /// their noise, the more rings averaging it out takes. A 1M-sample cone with noise of twice the
    /// sampling step took 14 and went from 41% of its normals inside out (its base) to 1.2%; the
    /// bench's noisy spheres, tori and plates at 1M from 516-1,855 wrong normals and 6.4-7.7° mean
    /// error to 0-222 and 2.1-3.9°, for about 0.05 s per ring per million samples. Noisy clouds of
    /// 100k samples (noise of 0.6 sampling steps) stop at 4. Values below guide_rings count as
    /// guide_rings.
    std::size_t guide_most_rings = 16;
    /// Sweeps in which every sample takes the sign of its neighbourhood's weighted mean normal,
    /// after propagation (each sweep reads all k columns of the table), when not guided (guided
    /// signs come from the smooth guide instead, where the sweeps measured no gain). 0 = none.
    /// Measured on a 1M-sample sphere with noise of twice the sampling step, unguided: 93.0%
    /// oriented with 0 sweeps, 93.9% with 1, 94.1% with 2.
    std::size_t smoothing_sweeps = 2;
    /// Clean clouds (not guided; Hoppe's rule) of at least 2048 samples: orient patches instead
    /// of single samples. Block by block (4096 samples in index order, so spatially sorted
    /// samples, as compute_surfels() has them, make compact blocks), the reliable graph edges
    /// that stay on the sheet join their ends' signs in disjoint sets; the patches are then
    /// oriented against each other by the summed agreement of the edges between them (a maximum
    /// spanning forest, as the whole graph's patches are). Samples next to a crease or across a
    /// thin part (some neighbour's normal more than a reliable step away, or oriented otherwise
    /// by the reflection rule than by Hoppe's, or two neighbours' normals more than a reliable
    /// step apart), and the samples next to those, join no patch; the edges there vote by the
    /// reflection rule, and pairs of samples across them by the tilt rule (each on the same
    /// side of the other's tangent plane): Hoppe's rule turns one face of a crease sharper than
    /// 90° (a cone's rim) or of a knife edge inside out. On the 10M-sample blobby the
    /// orientation took 1.0 s instead of 3.9 s (a subsample of the graph, the previous scheme)
    /// at 2 threads with the same signs; on the clean test shapes and the bunny scans the signs
    /// are the whole graph's but for a few samples at a thin plate's corners. Noisy clouds
    /// (guided) and the reflection rule always use the whole graph. false = the whole graph, as
    /// in the paper.
    bool patches = true;
    /// Optional progress report.
    ProgressCallback progress;
};

/// \brief A minimum spanning forest of the Riemannian graph: one tree a connected component,
/// rooted at the component's seed.
struct RiemannianForest
{
    static constexpr std::uint32_t none = 0xFFFFFFFFU;

    /// N: tree parent of each sample; a root is its own parent; `none` for a sample of a
    /// component that has no usable normal (it is in no tree).
    std::vector<std::uint32_t> parent;
    /// Samples in breadth-first order from the roots; every parent comes before its child.
    std::vector<std::uint32_t> order;
    /// N: connected component of each sample, numbered by smallest sample index.
    std::vector<std::uint32_t> component;
    /// One root a component (`none` for a component with no usable normal).
    std::vector<std::uint32_t> roots;
    /// Sum of the edge costs of all trees.
    double total_cost = 0.0;
};

/// \brief Builds the Riemannian graph (the kNN graph made symmetric, with `options.k` columns of
/// `neighbors`) and its minimum spanning forest by Borůvka's algorithm in parallel, over the
/// table itself (no edge list: 4 bytes an edge for its cost), ties broken by edge order, so the
/// forest is the one Kruskal's algorithm makes and does not depend on the thread count; one
/// tree a component, each rooted at the component's highest sample with a usable normal. Edge
/// costs (`options.rule`) depend only on the lines the normals span, not on their signs.
/// \param positions  N points
/// \param normals    N normals (unit, or zero where undefined; zero ones are reached last)
/// \param neighbors  an N by k neighbour table of the points
[[nodiscard]] RiemannianForest riemannian_spanning_forest(std::span<const Vec3f> positions,
                                                          std::span<const Vec3f> normals,
                                                          const KnnTable& neighbors,
                                                          const OrientationOptions& options = {});

/// \brief Consistently oriented normals and what the orientation did.
struct OrientedNormals
{
    /// N unit normals, consistently oriented; zero where a sample could not be oriented.
    std::vector<Vec3f> normals;
    /// Connected components of the Riemannian graph (each oriented from its own seed).
    std::size_t components = 0;
    /// Normals whose sign differs from the input's.
    std::size_t flipped = 0;
    /// Samples with no usable normal of their own that took one from a graph neighbour.
    std::size_t inherited = 0;
    /// Samples that could not be oriented (a component with no usable normal), ascending.
    std::vector<std::uint32_t> unoriented;
    /// Noisy clouds: thin parts whose two faces the noise joins, oriented by their two bands of
    /// samples (each face away from the other) where orientation left them undecided, and the
    /// normals that turned there.
    std::size_t thin_parts = 0;
    std::size_t thin_part_turned = 0;
};

/// \brief Orients normals consistently by propagation along a minimum spanning tree of the
/// Riemannian graph (§4 step 2, after Hoppe et al. 1992).
///
/// Every connected component is handled on its own: its seed is its highest point (largest z),
/// whose normal is turned to +z, and orientation spreads from it along the minimum spanning
/// tree, each sample taking the sign that agrees with its tree parent under `options.rule` —
/// but only across tree edges cheaper than `options.patch_cost`. The dearer edges cut the trees
/// into patches, which are flipped against each other by the summed agreement of every graph
/// edge between them. Then `options.smoothing_sweeps` times, every sample takes the sign of its
/// neighbours' weighted mean normal. On noisy clouds (Hoppe rule) all this runs on coarser-scale
/// guide normals (`options.guide_rings`), which are then the output normals (after a vote of
/// each sample's neighbours on its sheet: a guide that fewer than 6 of them support within 30°,
/// a stray of the noise, takes the principal axis of theirs, and every normal turns to the side
/// they point to); there an edge whose
/// end lies off the other end's sheet (its height along that end's guide more than 3 robust
/// deviations of the local noise from the median of that end's neighbours) neither passes
/// orientation nor votes, so the two faces of a noisy thin plate, whose outliers meet in the gap
/// with parallel guides, are not oriented alike (faces at least about 8 noise deviations apart:
/// closer ones share outliers that no test of positions tells apart), and a patch left without
/// votes takes the sign of its neighbours. Guided clouds are then checked by the generalized
/// winding number of the oriented samples: samples whose guide is thick at every scale (1.5
/// times the median flatness, with their neighbours) part the cloud into regions, and a region
/// is turned over where that brings the winding number on the samples clearly closer to ½, and
/// leaves them a closed surface by it (at a noisy crease sharper than a right angle every guide
/// near it is the wedge's axis, and a chain of them turns one face inside out); where one turns,
/// the samples outside those regions then take the tangent plane of the region sample they lie
/// nearest to. Finally, so that
/// closed surfaces come out with outward normals whatever their shape, the component's normals are
/// flipped if the area-weighted flux Σ a_i n_i·(p_i − c) (3 × the enclosed volume for a closed
/// surface, by the divergence theorem) is clearly negative; for open, flat components the flux says
/// little and the seed's +z stands. Samples with a zero normal (degenerate neighbourhoods) take
/// their tree parent's normal and are counted in `inherited`.
///
/// \param positions  N points
/// \param normals    N unoriented normals (unit, or zero where undefined)
/// \param neighbors  an N by k neighbour table of the points (self entries are skipped); its
///                   squared distances weight the flux (area ≈ squared k-th neighbour distance)
/// \throw InvalidInput if the sizes disagree
[[nodiscard]] OrientedNormals orient_normals_mst(std::span<const Vec3f> positions,
                                                 std::span<const Vec3f> normals,
                                                 const KnnTable& neighbors,
                                                 const OrientationOptions& options = {});

/// \brief Turns every normal towards a viewpoint: n·(viewpoint − p) ≥ 0 (scanner position).
/// \param viewpoint  in the same frame as positions (subtract the cloud's origin first)
[[nodiscard]] OrientedNormals orient_normals_towards(std::span<const Vec3f> positions,
                                                     std::span<const Vec3f> normals,
                                                     const Vec3d& viewpoint);

/// \brief Turns every normal to agree with a direction: n·direction ≥ 0.
/// \throw InvalidInput if direction is zero or not finite
[[nodiscard]] OrientedNormals orient_normals_along(std::span<const Vec3f> normals,
                                                   const Vec3d& direction);

/// \brief Reverses every normal.
[[nodiscard]] OrientedNormals flip_normals(std::span<const Vec3f> normals);

} // namespace pointform
