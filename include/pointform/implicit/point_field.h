// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include "pointform/core/progress.h"
#include "pointform/geometry/point_cloud.h"
#include "pointform/implicit/field.h"
#include "pointform/spatial/kd_tree.h"

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

namespace pointform {

/// \brief Which tangent plane(s) define the point field near a sample.
enum class PlaneFit
{
    /// The paper's field (§4): the plane through the nearest sample s_k with its normal n_k,
    /// f(p) = (p − s_k)·n_k. Scanner noise goes straight into the surface.
    Raw,
    /// Hoppe's original construction: the plane through the centroid of the nearest sample's
    /// neighbourhood (its `centroid_k` nearest samples and itself), with normal n_k.
    Centroid,
    /// A smooth blend of the centroid planes of the `blend_k` nearest samples, weighted by a
    /// compactly supported Wendland kernel of the distance relative to the (blend_k + 1)-th
    /// nearest sample's distance, so the field is continuous.
    Blend,
    /// The same blend over local quadrics instead of planes: each sample's surface is the
    /// least-squares height function a + bu + cv + du² + euv + fv² of its neighbourhood over
    /// its tangent plane, which follows curvature that planes (centred or not) cut through.
    /// The most accurate both on exact samples and on noisy ones (bench/implicit,
    /// tests/implicit), hence the default.
    Quadric,
};

/// \brief Parses "raw", "centroid", "blend" or "quadric". \throw InvalidInput otherwise
[[nodiscard]] PlaneFit parse_plane_fit(std::string_view text);
[[nodiscard]] std::string_view to_string(PlaneFit fit);

/// \brief Cells of a uniform grid anchored at the world origin (cell c spans size·c to
/// size·(c + 1)): where PointFieldOptions::noise_scale applies.
struct NoiseScaleRegion
{
    double size = 0.0;
    std::vector<std::array<std::int32_t, 3>> cells; ///< ascending
    /// \brief The cell of world point `p`; nullopt where the size is not positive or the cell's
    /// index is beyond 32 bits.
    [[nodiscard]] std::optional<std::array<std::int32_t, 3>> cell_of(const Vec3d& p) const;
    /// \brief Whether world point `p` lies in one of the cells (false when there are none).
    [[nodiscard]] bool contains(const Vec3d& p) const;
};

struct PointFieldOptions
{
    PlaneFit fit = PlaneFit::Quadric;
    /// Neighbours (besides the sample) whose centroid anchors a sample's plane (Centroid, Blend).
    std::size_t centroid_k = 16;
    /// Planes blended at a query point (Blend, Quadric), ≥ 2.
    std::size_t blend_k = 8;
    /// Neighbours (besides the sample) that a sample's quadric is fitted to (Quadric): wider
    /// than the centroid's, since six coefficients need more samples to average noise away (on
    /// spheres and tori with 0.1–0.2% noise, 48 beats 16 and 32 and the centroid blend).
    std::size_t quadric_k = 48;
    /// Quadric: the neighbours (the sample included) of a second, narrower fit, taken instead of
    /// the wide one where their heights at the sample differ by more than twice the noise of
    /// the two fits explains (the noise estimated from the narrow fit's residual): where the
    /// samples are exact and the surface turns faster than a quadric over 48 neighbours
    /// follows (creases, small features), and not where noise alone makes them differ. 0 = the
    /// wide fit everywhere. Measured on the 100k inputs of bench/peers, Chamfer to the truth in
    /// % of the diagonal: clean blobby 0.0072 → 0.0066, clean CAD-like part 0.0123 → 0.0104,
    /// clean thin plate 0.0065 → 0.0052, noisy inputs within 2% either way; the shipped bunny
    /// 0.068 → 0.070 (the surface its field spans over the scan's holes bulges more).
    /// The narrow fit is also taken where the sample's own test cannot tell but its
    /// neighbourhood's can: where the gaps of its quadric_narrow_k nearest together lie well
    /// beyond their noise, and that noise is a small part of a spacing (a clean real scan,
    /// whose detail a wide quadric flattens by about its noise at every sample): the shipped
    /// bunny's field at its samples 0.0128% → 0.0084% of the diagonal (median); noisy inputs
    /// unchanged.
    std::size_t quadric_narrow_k = 16;
    /// Quadric: fit each sample's surface to its own face of a crease. Where some of its
    /// neighbours' normals turn from its own by more than 30° and some of them lie well off its
    /// plane (beyond 3 robust standard deviations of their residuals), its normal is refitted
    /// to the others (iteratively reweighted, from up to four starts: a principal component
    /// normal tilts toward the other face, up to 54° at a box's corners), and where those lie
    /// to one side of it the blend leaves the space past their edge (the crease line) to the
    /// other face's samples, so that the faces meet at the crease instead of being rounded off
    /// or running past it. Measured on the 100k inputs of bench/peers, `reconstruct` at its
    /// defaults (Hausdorff / Chamfer in % of the diagonal, without → with; the Hausdorff
    /// distance of these evaluations varies by about 0.03 from run to run): clean plate
    /// 0.98 / 0.0057 → 0.93 / 0.0050, clean blobby 0.25 / 0.0067 → 0.25 / 0.0064, clean part
    /// 0.93 / 0.0107 → 0.47 / 0.0099; the clean sphere and torus the same mesh; the noisy
    /// sphere, blobby, part and plate 0.2-0.8% lower in Chamfer.
    bool crease_fit = true;
    /// Across a rim of the samples (a hole's edge, a partial scan's border: a sample whose
    /// neighbours, whichever way they face, have their centroid well off it over its tangent
    /// plane), the field is defined only this fraction of an automatic influence radius beyond
    /// the sample, so that the surfaces fitted to one side are not extrapolated into the hole,
    /// where noise makes them flare (bench/peers, noisy inputs with holes: patches and rims off
    /// the truth by up to 3 times 0.5% of the diagonal). A radius raised above the automatic one
    /// (a larger radius scale, a region of §4.1) keeps what it adds: it still spans the holes it
    /// was raised to span. Crease samples are not rims (the other face's neighbours balance
    /// the centroid). In (0, 1]; 1 = the whole radius, as elsewhere (the paper's field).
    double rim_reach = 0.25;
    /// Quadric, in a noisy cloud (PointField::noisy()): the fit scale from the local noise.
    /// Where a sample's fit leaves residuals above a fifth of the distance to its farthest
    /// neighbour, it is fitted again over its quadric_k nearest among every 4th sample (in
    /// Morton order), then every 16th and 64th (twice, 4 and 8 times the reach), until they are
    /// not. A fit whose ball is not wide against the noise follows its own sample (by about
    /// 2 σ² / R² of its offset), and where the noise band is as thick as the ball (dense noisy
    /// samples; the two faces of a thin plate merged by noise into one slab) the blend of such
    /// fits is about zero through the whole band and its zero set a sponge. Off by default:
    /// at concave creases the wider fits round the surface more (the noisy 1M blobby of
    /// bench/peers: the field at the truth 0.0020 -> 0.0040 off near its creases, 0.0016 ->
    /// 0.0015 elsewhere); reconstruct() turns it on where the field's surface comes out a sponge.
    bool noise_scale = false;
    /// Where noise_scale applies, by the samples' positions; empty cells = everywhere.
    NoiseScaleRegion noise_scale_region;
    /// Answer deep-inside queries from the far grid (see PointField): constant time, within
    /// 2√3 h of the distance. False: the nearly nearest kd-tree search, as outside (within 1%),
    /// slower deep inside a closed scan; for callers that take inside values as distances
    /// (morphs, UndefinedPolicy::Ignore).
    bool far_grid = true;
    /// Optional: told how the samples' fits advance (stage "field"); returning false stops the
    /// build, which then throws Cancelled. Called during construction only (options() returns
    /// the options without it).
    ProgressCallback progress;
};

/// \brief The signed field of oriented surfels (§4).
///
/// s_k = the sample nearest to p. Where ‖p − s_k‖ ≤ r_k the field is defined: f(p) is the signed
/// distance to the local surface chosen by PlaneFit, ∇f its gradient. Beyond r_k the field is
/// the paper's f = ∞: `defined` is false, the value is ±‖p − s_k‖ with the sign of the nearest
/// sample's surface, so inside and outside stay told apart (see FieldSample). Blend and Quadric
/// widen "defined" to the union of the influence balls of the blended samples: with irregular
/// sampling the nearest sample's ball alone leaves pinholes between clusters. Across a rim of
/// the samples each ball is cut short (PointFieldOptions::rim_reach).
///
/// Farther from every sample than the largest influence radius, s_k may be a sample a little
/// farther than the nearest, at distance D: there every sample is about as far as the nearest
/// (think of the middle of a closed scan) and an exact search would visit most of them.
/// - Outside (value > 0): D ≤ |value| ≤ 1.01 D (a nearly nearest kd-tree search), close enough
///   for offsets and blends, which trust outside values as distances.
/// - Deep inside (value < 0): D ≤ |value| ≤ D + 2√3 h, with h = (the longest side of bounds())
///   / 127, answered in constant time by a far grid: a FeatureGrid of 128 nodes along that side
///   over bounds(), built on the first query that needs it (about 8 bytes a node, at most 16 MiB;
///   never for a field queried only near its samples). With the 8 nodes around p it proves that
///   no influence ball reaches p (every sample is farther than the largest radius × 1.01), and
///   s_k is the nearest to p of those nodes' representative samples (see FeatureGrid), ties to
///   the smallest index. Its magnitude is never below D, so an undefined inside value stays
///   beyond every influence radius, as Booleans need; operators that take undefined values as
///   distances inside too (UndefinedPolicy::Ignore, as morphs do) see the 2√3 h, unless they
///   turn the far grid off (PointFieldOptions::far_grid; `pointform morph` does). The far grid
///   answers only where all those representatives' surfaces put p inside and none shares its node
///   with a sample facing the other way (a wall thinner than h, whose side the node cannot tell);
///   elsewhere the kd-tree search decides, as outside.
/// - Far outside the same way (no influence ball reaches, every representative's surface puts p
///   outside, none two-sided; beyond the grid's box, the representatives at the nearest point of
///   the box): the value is positive, its magnitude from the kd-tree search started at the
///   nearest representative; evaluate_within() answers with the grid's lower bound on the
///   distance wherever that is above the range asked, without searching.
/// The answers do not depend on the order of queries or on threads.
///
/// Queries are answered by a PointGrid over the samples (a kd-tree far from them), and run
/// fastest in spatially coherent order (as marching cubes and refinement ask).
class PointField final : public Field
{
public:
    /// \param surfels positions with unit normals and radii (as compute_surfels makes them), in
    ///        any order (the field keeps them in Morton order)
    /// \throw InvalidInput if the cloud is empty, or normals or radii are missing, non-finite or
    ///        not positive
    explicit PointField(PointCloud surfels, const PointFieldOptions& options = {});
    ~PointField() override;

    [[nodiscard]] FieldSample evaluate(const Vec3d& p) const override;
    /// \brief The same values as evaluate() per point (bit for bit, whatever the thread
    /// count), faster: the point grid answers each block of consecutive queries together, which
    /// pays where they are coherent (as marching cubes and refinement ask).
    void evaluate(std::span<const Vec3d> points, std::span<FieldSample> out) const override;
    /// \brief evaluate(), except far outside (see above) where a lower bound on the distance
    /// to the samples is above `hi`: then the value is that bound.
    [[nodiscard]] FieldSample evaluate_within(const Vec3d& p, double lo, double hi) const override;
    /// \brief evaluate_within() per point, as fast as the batch evaluate().
    void evaluate_within(std::span<const Vec3d> points, std::span<const double> lo,
                         std::span<const double> hi, std::span<FieldSample> out) const override;
    [[nodiscard]] double cost() const override;
    [[nodiscard]] Aabb bounds() const override;
    /// \brief The samples' positions, but for the strays (stray_samples()): a surface that only
    /// strays hold up is no part of the scan (marching cubes, which follows the surface from
    /// these seeds, does not look for it), and a surface that other samples hold up too is
    /// found from theirs.
    void append_seeds(std::vector<Vec3d>& seeds) const override;

    /// \brief The samples (indices into surfels(), ascending) that ScatterTest::stray() finds
    /// stray: returns sprayed through the space around a scan, or standing off a surface, whose
    /// influence radii (many times the others') give the field sheets far from any surface.
    [[nodiscard]] std::span<const std::uint32_t> stray_samples() const;

    /// \brief The samples, with unit normals, in Morton order (spatial_order()), not
    /// necessarily the order given: the field is the same whatever order its samples come in.
    [[nodiscard]] const PointCloud& surfels() const;
    /// \brief The k-d tree over surfels()' positions (RefineOptions::sample_tree takes it).
    [[nodiscard]] const KdTree& tree() const;
    [[nodiscard]] const PointFieldOptions& options() const;
    /// \brief Median influence radius over the samples.
    [[nodiscard]] double median_radius() const;
    /// \brief Whether the field's noise test found the samples noisy (the median flatness of
    /// their fit neighbourhoods above that of clean samples): crease fits then look for their
    /// other face's samples only among outliers, and PointFieldOptions::noise_scale applies.
    [[nodiscard]] bool noisy() const;
    /// \brief The area of the sampled surface, estimated from the sampling density (each sample
    /// stands for π d² / k, d its distance to the k-th of its `centroid_k` neighbours).
    [[nodiscard]] double estimated_area() const;

private:
    /// The batch evaluate(), each point within (-∞, hi[i]], or exact where `hi` is empty.
    void evaluate_batch(std::span<const Vec3d> points, std::span<const double> hi,
                        std::span<FieldSample> out) const;

    struct Impl;
    std::unique_ptr<Impl> impl_;
};

} // namespace pointform
