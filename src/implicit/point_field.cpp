// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/implicit/point_field.h"

#include "pointform/core/error.h"
#include "pointform/core/parallel.h"
#include "pointform/core/progress.h"
#include "pointform/hermite/crease_fit.h"
#include "pointform/hermite/normals.h"
#include "pointform/hermite/scatter.h"
#include "pointform/spatial/feature_grid.h"
#include "pointform/spatial/kd_tree.h"
#include "pointform/spatial/point_grid.h"
#include "pointform/spatial/spatial_sort.h"

#include "blend_kernels.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <mutex>
#include <numbers>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace pointform {

namespace {

constexpr std::size_t max_blend_k = 32;

/// Point-grid cell size over the median distance from a sample to its farthest query neighbour:
/// the fastest of 1.5, 2, 2.5 and 3 on a 1M-sample sphere queried within a marching-cubes cell
/// of the surface (bench/implicit). Smaller cells send more queries to the 3 × 3 × 3 block,
/// larger ones scan more points.
constexpr float grid_cell_scale = 2.5F;

/// Beyond every influence radius the field's magnitude is the distance to a sample at most this
/// factor farther than the nearest (PointField).
constexpr float far_distance_factor = 1.01F;

/// Candidates a single-point evaluation that searched the kd-tree keeps for the next ones on
/// its thread (NeighbourMemo): the blended neighbours and this many more, whose distance bounds
/// how far a query may move before another sample could come between. 4 and 16 were tried on
/// the simulated fandisk scans and table_scene_mug; more candidates let farther queries take
/// them but cost every search more.
constexpr std::size_t memo_extra = 8;
constexpr std::size_t memo_capacity = max_blend_k + 1 + memo_extra;

/// A point field's evaluation against an analytic primitive's (Field::cost), roughly.
constexpr double point_field_cost = 50.0;

/// Nodes along the longest side of the far grid (PointField): at most 128³ ≈ 2.1M nodes, 16 MiB,
/// built in about 0.1 s on one core (100k samples). Its spacing h follows the box, not the
/// influence radii: inside values are within 2√3 h of the nearest distance, and the far grid
/// answers from about 2√3 h beyond the largest radius; queries nearer go to the kd-tree, which
/// is fast near the samples, so a spacing below the radii would buy accuracy only, at a cubic
/// cost in memory where the radii are small against the box (a 10 m scan with 1 cm radii).
constexpr std::size_t far_grid_nodes = 128;

/// Whether the field blends the surfaces of several samples (or takes the nearest one's).
bool blends(PlaneFit fit)
{
    return fit == PlaneFit::Blend || fit == PlaneFit::Quadric;
}

void check_surfels(const PointCloud& cloud)
{
    if (cloud.empty())
    {
        throw InvalidInput("point field: the cloud has no samples");
    }
    if (!cloud.has_normals())
    {
        throw InvalidInput("point field: the samples have no normals (orient them first)");
    }
    if (!cloud.has_radii())
    {
        throw InvalidInput("point field: the samples have no influence radii");
    }
    for (std::size_t i = 0; i < cloud.size(); ++i)
    {
        const float norm = cloud.normals[i].norm();
        if (!cloud.positions[i].allFinite() || !std::isfinite(norm) || norm < 0.5F ||
            !(cloud.radii[i] > 0.0F) || !std::isfinite(cloud.radii[i]))
        {
            throw InvalidInput(
                "point field: sample " + std::to_string(i) +
                " has a non-finite position, a zero normal or a non-positive radius");
        }
    }
}

} // namespace

PlaneFit parse_plane_fit(std::string_view text)
{
    if (text == "raw")
    {
        return PlaneFit::Raw;
    }
    if (text == "centroid")
    {
        return PlaneFit::Centroid;
    }
    if (text == "blend")
    {
        return PlaneFit::Blend;
    }
    if (text == "quadric")
    {
        return PlaneFit::Quadric;
    }
    throw InvalidInput("unknown plane fit '" + std::string(text) +
                       "' (expected raw, centroid, blend or quadric)");
}

std::string_view to_string(PlaneFit fit)
{
    switch (fit)
    {
        case PlaneFit::Raw:
            return "raw";
        case PlaneFit::Centroid:
            return "centroid";
        case PlaneFit::Blend:
            return "blend";
        case PlaneFit::Quadric:
            return "quadric";
    }
    return "?";
}

namespace {

using detail::BlendSums;
using detail::clean_cloud;
using detail::crease_plane;
using detail::crease_turn_cosine;
using detail::CreaseNeighbourhood;
using detail::CreasePlane;
using detail::flatness;
using detail::PackedSurfel;

} // namespace

/// A unit vector perpendicular to the unit vector n, the same for the same n.
Vec3f tangent_of(const Vec3f& n)
{
    const Vec3f axis = std::abs(n.x()) < 0.9F ? Vec3f::UnitX() : Vec3f::UnitY();
    return n.cross(axis).normalized();
}

/// How far apart, in standard deviations of their noise, the heights at a sample of its narrow
/// and wide quadrics (PointFieldOptions::quadric_narrow_k) may lie before the narrow one is
/// taken: each height's deviation from the narrow fit's residual (σ̂² = RSS / (k − 6)) and the
/// fit's leverage at the sample, σ̂ √((XᵀX)⁻¹)₀₀, and the two added (the intersection of
/// confidence intervals rule of adaptive-scale regression, Goldenshluger and Nemirovski).
constexpr double narrow_fit_gamma = 2.0;

/// The neighbourhood's test of the wide fit (pool_narrow_fits()): each sample's gap between its
/// two heights, over the standard deviation noise alone gives it (σ √(lev_narrow − lev_wide),
/// nested least squares, σ the neighbourhood's), squared and averaged over the sample's
/// quadric_narrow_k nearest. Noise alone makes it about 1: on the noisy inputs and the
/// simulated scans of bench/peers its median is 0.87-0.98 and 1.3-3.2% of the samples lie
/// above 3; on the shipped bunny scan its median is 5.8 and 80% lie above 3.
constexpr double narrow_pool_bias = 3.0;
/// ... taken only where the neighbourhood's noise (the median of its narrow fits' σ̂) is under
/// this fraction of its reach (the distance to its quadric_narrow_k-th nearest): a narrow fit
/// then costs about its noise, a small part of a spacing, where the wide fit's bias is what
/// was found. σ / reach is 0.0155 at the median over the bunny scan (90% under 0.033), and
/// 0.14-0.26 over the noisy inputs and the simulated scans of bench/peers.
constexpr double narrow_pool_clean = 0.05;
/// ... and not at a sample whose own narrow fit leaves residuals beyond this many times its
/// neighbourhood's variance: its neighbourhood is not a quadric at the narrow scale (a crease,
/// a corner), and the wide fit is kept as the sample-by-sample test chose it.
constexpr double narrow_pool_misfit = 4.0;
/// ... nor at a sample whose two heights differ by less than this fraction of its narrow fit's
/// reach (a thousandth of a spacing or two): the same field either way, and not worth the
/// search (95% of the samples of an exact 1M-sample blobby, 0.29 s of its field's 2.3).
constexpr double narrow_pool_least = 1e-3;

/// What pool_narrow_fits() tests a sample's narrow quadric by (12 bytes a sample).
struct NarrowTest
{
    float gap = 0.0F;     ///< |narrow − wide height| at the sample
    float spread2 = 0.0F; ///< lev_narrow − lev_wide: the gap's variance over σ²
    float sigma2 = -1.0F; ///< the narrow fit's σ̂²; negative where there is no narrow fit
};

/// A sample's narrow quadric, kept where pool_narrow_fits() may take it.
struct NarrowFit
{
    NarrowTest test;
    std::array<float, 6> coef{}; ///< the narrow quadric, as PackedSurfel::a..f
    /// The wide fit was kept, the narrow one is a surface and may pass pool_narrow_fits()
    bool candidate = false;
};

/// A candidate (NarrowFit::candidate) by its sample's slot.
struct NarrowCandidate
{
    std::uint32_t slot = 0;
    std::array<float, 6> coef{};
};

/// The steepest a quadric may rise over the sample's plane (plausible_fit()), as a slope: 1.5
/// (56°). Measured on the 100k inputs of bench/peers, Chamfer in % of the diagonal
/// with 1 / 1.5 / 2 / no bound: clean blobby 0.0069 / 0.0067 / 0.0066 / 0.0066, clean part
/// 0.0112 / 0.0107 / 0.0105 / 0.0103; F@0.5% of the noisy torus 0.9996 / 0.9996 / 0.9993 / 0.9964.
constexpr double max_fit_slope = 1.5;

/// Whether a quadric (coefficients in the wide fit's scaled coordinates; `reach` its farthest
/// neighbour's scaled distance) is a surface at all: its slope at the sample, and its rise over
/// its own neighbourhood (the slope's and the curvature's), at most max_fit_slope.
/// Sixteen noisy samples can fit a quadric that rises at 60-70° (noise of the sampling step on
/// a torus: slopes of 1.8-3.2, curvatures 65 times the tube's), and its heights a few steps away
/// put a sheet of the field inside out: a bubble of surface 0.03 off the torus. A crease's
/// one-sided fit stays within the bound.
bool plausible_fit(const Eigen::Matrix<double, 6, 1>& coef, double reach)
{
    const double slope = std::hypot(coef[1], coef[2]);
    const double curvature =
        std::max({std::abs(coef[3]), std::abs(coef[5]), 0.5 * std::abs(coef[4])});
    return slope <= max_fit_slope &&
           slope * reach + curvature * reach * reach <= max_fit_slope * reach;
}

/// A quadric fitted in coordinates scaled by 1 / `scale` (fit_local_surface()) as
/// PackedSurfel::a..f, in the sample's own (unscaled) frame.
std::array<float, 6> unscaled_quadric(const Eigen::Matrix<double, 6, 1>& coef, double scale)
{
    const double inv_scale = 1.0 / scale;
    return {static_cast<float>(coef[0] * scale),
            static_cast<float>(coef[1]),
            static_cast<float>(coef[2]),
            static_cast<float>(coef[3] * inv_scale),
            static_cast<float>(coef[4] * inv_scale),
            static_cast<float>(coef[5] * inv_scale)};
}

/// Sets `out`'s quadric (PackedSurfel::a..f).
void set_quadric(PackedSurfel& out, const std::array<float, 6>& quadric)
{
    out.a = quadric[0];
    out.b = quadric[1];
    out.c = quadric[2];
    out.d = quadric[3];
    out.e = quadric[4];
    out.f = quadric[5];
}

/// The local surface of sample i (see PackedSurfel) from its neighbours (the sample first,
/// nearest first); `positions` and `normals` are indexed like `neighbors` and i. A quadric fit
/// to the narrowest `narrow_k` of them (0: none) replaces the one fit to all where the two
/// differ by more than noise explains (narrow_fit_gamma) and is a surface (plausible_fit()).
/// `on_rim`: the neighbours lie to one side (a hole's rim): the fit to all must be a surface
/// too, or the centroid plane is kept. Measured on the noisy torus of bench/peers (100k, 8
/// holes): a sample left inside a hole by the noise fitted a quadric whose zero set flared
/// 0.035 off the tube (2.4 times 0.5% of the diagonal); with the rule the torus's F@0.5% went
/// from 0.9992 to 1.0000 and its Hausdorff from 1.45% to 0.51% of the diagonal.
/// `narrow_out` (if given) receives the narrow fit for pool_narrow_fits(). Returns the kept
/// quadric's noise relative to its neighbourhood: the residual's σ̂ (RSS / (count − 6) of the fit
/// to all) over the distance to the farthest neighbour; 0 where no quadric was fitted.
double fit_local_surface(std::span<const Vec3f> positions, std::span<const Vec3f> normals,
                         std::span<const std::uint32_t> neighbors, std::size_t i, PlaneFit fit,
                         std::size_t narrow_k, bool on_rim, PackedSurfel& out,
                         NarrowFit* narrow_out)
{
    const Vec3d s = positions[i].cast<double>();
    const Vec3d n = out.normal.cast<double>();
    const Vec3d t1 = out.tangent.cast<double>();
    const Vec3d t2 = n.cross(t1);
    out.a = out.b = out.c = out.d = out.e = out.f = 0.0F;
    if (fit == PlaneFit::Raw)
    {
        return 0.0;
    }
    double mean_height = 0.0;
    for (const std::uint32_t j : neighbors)
    {
        mean_height += (positions[j].cast<double>() - s).dot(n);
    }
    mean_height /= static_cast<double>(neighbors.size());
    out.a = static_cast<float>(mean_height);
    if (fit != PlaneFit::Quadric)
    {
        return 0.0;
    }
    // The quadric's neighbourhood is wide enough to reach across a thin wall: samples facing
    // more than 60° away belong to another sheet and are left out.
    double scale2 = 0.0;
    std::size_t used = 0;
    for (const std::uint32_t j : neighbors)
    {
        if (normals[j].dot(out.normal) > 0.5F)
        {
            scale2 = std::max(scale2, (positions[j].cast<double>() - s).squaredNorm());
            ++used;
        }
    }
    if (used < 10 || !(scale2 > 0.0))
    {
        return 0.0; // too few to fit six coefficients: keep the centroid plane
    }
    // Least squares in coordinates scaled to the neighbourhood, for a well-conditioned system.
    // The normal equations are accumulated nearest first, and kept at the narrow scale too, with
    // Σ h² for the residuals (RSS = Σ h² − coefᵀ rhs).
    const double inv_scale = 1.0 / std::sqrt(scale2);
    using Mat6 = Eigen::Matrix<double, 6, 6>;
    using Vec6 = Eigen::Matrix<double, 6, 1>;
    // The normal matrix of the monomials (1, u, v, u², uv, v²) holds the 15 moments Σ uᵃ vᵇ,
    // a + b ≤ 4, which are summed instead of its 21 distinct products.
    struct Sums
    {
        std::array<double, 15> moment{}; ///< Σ uᵃ vᵇ: 1, u, v, u², uv, v², u³, u²v, uv², v³,
                                         ///< u⁴, u³v, u²v², uv³, v⁴
        Vec6 rhs = Vec6::Zero(); ///< Σ h (1, u, v, u², uv, v²)
        double heights2 = 0.0;   ///< Σ h²
        std::size_t count = 0;
        double reach = 0.0; ///< the farthest neighbour's distance, scaled (at the narrow scale)

        [[nodiscard]] Mat6 matrix() const
        {
            const auto& m = moment;
            Mat6 out;
            out << m[0], m[1], m[2], m[3], m[4], m[5], //
                m[1], m[3], m[4], m[6], m[7], m[8],    //
                m[2], m[4], m[5], m[7], m[8], m[9],    //
                m[3], m[6], m[7], m[10], m[11], m[12], //
                m[4], m[7], m[8], m[11], m[12], m[13], //
                m[5], m[8], m[9], m[12], m[13], m[14];
            return out;
        }
    };
    Sums sums;
    std::optional<Sums> small;
    for (const std::uint32_t j : neighbors)
    {
        if (!(normals[j].dot(out.normal) > 0.5F))
        {
            continue;
        }
        const Vec3d x = (positions[j].cast<double>() - s) * inv_scale;
        const double u = x.dot(t1);
        const double v = x.dot(t2);
        const double h = x.dot(n);
        const double uu = u * u;
        const double uv = u * v;
        const double vv = v * v;
        auto& m = sums.moment;
        m[0] += 1.0;
        m[1] += u;
        m[2] += v;
        m[3] += uu;
        m[4] += uv;
        m[5] += vv;
        m[6] += uu * u;
        m[7] += uu * v;
        m[8] += u * vv;
        m[9] += vv * v;
        m[10] += uu * uu;
        m[11] += uu * uv;
        m[12] += uu * vv;
        m[13] += uv * vv;
        m[14] += vv * vv;
        sums.rhs += Vec6(1.0, u, v, uu, uv, vv) * h;
        sums.heights2 += h * h;
        ++sums.count;
        if (sums.count == narrow_k)
        {
            small = sums;
            small->reach = x.norm();
        }
    }
    const std::size_t count = sums.count;
    const auto solve = [](const Mat6& m, const Vec6& r) -> std::optional<std::pair<Vec6, double>> {
        const Eigen::LDLT<Mat6> solver(m);
        const auto pivots = solver.vectorD();
        if (solver.info() != Eigen::Success || !(pivots.minCoeff() > 1e-6 * pivots.maxCoeff()))
            return std::nullopt;
        const Vec6 coef = solver.solve(r);
        Vec6 e0 = Vec6::Zero();
        e0[0] = 1.0;
        const double leverage = solver.solve(e0)[0];
        if (!coef.allFinite() || !std::isfinite(leverage))
            return std::nullopt;
        return std::pair{coef, leverage};
    };
    const auto wide = solve(sums.matrix(), sums.rhs);
    if (!wide || (on_rim && !plausible_fit(wide->first, 1.0)))
    {
        // Neighbours on a line, or too few spread, or on a rim a quadric that is no surface over
        // them (plausible_fit()), which the field would extrapolate into the hole: keep the
        // centroid plane. (Inside the surface the wide fit stands: on a clean crease it rises
        // steeply and is still the best fit.)
        return 0.0;
    }
    Vec6 coef = wide->first;
    if (small && small->count < count)
    {
        if (const auto narrow = solve(small->matrix(), small->rhs))
        {
            // The intersection of confidence intervals: the wide fit unless its height at the
            // sample differs from the narrow fit's by more than their noise explains.
            const double rss = std::max(0.0, small->heights2 - narrow->first.dot(small->rhs));
            const double sigma2 = rss / static_cast<double>(small->count - 6);
            const double spread = std::sqrt(sigma2 * std::max(0.0, narrow->second)) +
                                  std::sqrt(sigma2 * std::max(0.0, wide->second));
            const bool plausible = plausible_fit(narrow->first, small->reach);
            const double gap = std::abs(narrow->first[0] - coef[0]);
            const bool taken = gap > narrow_fit_gamma * spread && plausible;
            if (narrow_out != nullptr)
            {
                const double scale = std::sqrt(scale2);
                narrow_out->coef = unscaled_quadric(narrow->first, scale);
                narrow_out->test.gap = static_cast<float>(gap * scale);
                narrow_out->test.spread2 =
                    static_cast<float>(std::max(0.0, narrow->second - wide->second));
                narrow_out->test.sigma2 = static_cast<float>(sigma2 * scale2);
                // pool_narrow_fits() asks σ̂² ≤ misfit · σ² ≤ misfit · clean² · reach² (its
                // reach, that of the nearest narrow_k, is within this fit's), and a gap under
                // narrow_pool_least of the reach changes nothing that matters.
                const double reach2 = small->reach * small->reach;
                narrow_out->candidate =
                    plausible && !taken &&
                    gap * gap > narrow_pool_least * narrow_pool_least * reach2 &&
                    sigma2 <= narrow_pool_misfit * narrow_pool_clean * narrow_pool_clean * reach2;
            }
            if (taken)
                coef = narrow->first;
        }
    }
    set_quadric(out, unscaled_quadric(coef, std::sqrt(scale2)));
    // The wide fit's σ̂ in the scaled coordinates, where the farthest neighbour lies at 1.
    const double rss = std::max(0.0, sums.heights2 - wide->first.dot(sums.rhs));
    return count > 6 ? std::sqrt(rss / static_cast<double>(count - 6)) : 0.0;
}

/// A sample's quadric in a noisy cloud is fitted again at coarser scales while its fit's noise
/// (the residual's σ̂) is above this fraction of the distance to its farthest neighbour. A ball
/// of radius R centred at height z in Gaussian noise σ across a sheet holds samples whose mean
/// height is about 2 z σ² / (R² − σ² − z²): the fit follows its own sample by 2 σ² / R² of its
/// offset, the blend of such fits follows the samples, and the field's zero set frays into the
/// noise. At 0.2 (R = 5 σ) it follows by 8%. The noisy inputs of bench/peers at 100k samples
/// score about 0.1 and keep their fits; at 1M (spacings a third as long, noise the same) 0.3.
/// Where noise merges the two faces of a thin plate into one slab of samples (the 1M noisy plate
/// 0.02 thick: faces 3.4 deviations apart), the slab is what a fit sees, and a ball narrower than
/// the slab fits the samples' own heights: its surface was a sponge (Euler characteristic
/// -12,661).
constexpr double coarse_fit_noise = 0.2;

/// The coarser scales of a refit: the fit's count of neighbours among every 4th sample (in
/// Morton order), every 16th, every 64th: twice, 4 and 8 times the reach.
constexpr std::size_t coarse_fit_stride = 4;
constexpr std::size_t coarse_fit_levels = 3;

/// The k nearest of each query (grid slots and squared distances, nearest first, k per query
/// from query i · k on): the grid's batch search, and the kd-tree for the queries too far from
/// their neighbours for the cells around them.
void knn_of_batch(const PointGrid& grid, const KdTree& tree, std::span<const Vec3f> queries,
                  std::size_t k, std::vector<std::uint32_t>& slots, std::vector<float>& dist2)
{
    slots.resize(queries.size() * k);
    dist2.resize(queries.size() * k);
    std::vector<std::uint32_t> found(queries.size());
    grid.knn_nearby(queries, k, slots, dist2, found);
    for (std::size_t q = 0; q < queries.size(); ++q)
    {
        if (found[q] == k)
            continue;
        const std::span<std::uint32_t> neighbors(slots.data() + q * k, k);
        tree.knn(queries[q], k, neighbors, std::span(dist2.data() + q * k, k));
        for (std::uint32_t& neighbor : neighbors)
            neighbor = grid.slot_of(neighbor);
    }
}

/// Every stride-th sample of a cloud in Morton order (a subsample spread as the cloud is), in
/// the order of a point grid of its own (cells of `cell`) for batch searches.
struct CoarseSamples
{
    std::vector<Vec3f> tree_positions; ///< the kd-tree's points (it refers to them: declared first)
    std::unique_ptr<KdTree> tree;
    std::unique_ptr<PointGrid> grid;
    std::vector<Vec3f> positions;        ///< by grid slot
    std::vector<Vec3f> normals;          ///< by grid slot
    std::vector<std::uint32_t> original; ///< by grid slot: the index in the cloud
};

/// The coarse subsamples of `positions` and `normals` (samples in Morton order), finest first,
/// none with fewer than `k` samples; `cell` is the full cloud's fit grid cell, which each level
/// doubles (its spacing doubles).
std::vector<CoarseSamples> coarse_samples(std::span<const Vec3f> positions,
                                          std::span<const Vec3f> normals, std::size_t k, float cell)
{
    std::vector<CoarseSamples> levels;
    std::size_t stride = 1;
    for (std::size_t level = 0; level < coarse_fit_levels; ++level)
    {
        stride *= coarse_fit_stride;
        cell *= 2.0F;
        if (positions.size() / stride < k)
            break;
        std::vector<Vec3f> subsample;
        std::vector<std::uint32_t> index;
        for (std::size_t i = 0; i < positions.size(); i += stride)
        {
            subsample.push_back(positions[i]);
            index.push_back(static_cast<std::uint32_t>(i));
        }
        CoarseSamples c;
        c.tree_positions = std::move(subsample);
        c.tree = std::make_unique<KdTree>(c.tree_positions);
        c.grid = std::make_unique<PointGrid>(c.tree_positions, cell, *c.tree);
        c.positions.resize(c.grid->slot_count(), Vec3f::Zero());
        c.normals.resize(c.grid->slot_count(), Vec3f::Zero());
        c.original.resize(c.grid->slot_count(), PointGrid::padding_slot);
        for (std::uint32_t slot = 0; slot < c.grid->slot_count(); ++slot)
        {
            const std::uint32_t j = c.grid->original_index(slot);
            if (j == PointGrid::padding_slot)
                continue;
            c.positions[slot] = c.tree_positions[j];
            c.normals[slot] = normals[index[j]];
            c.original[slot] = index[j];
        }
        levels.push_back(std::move(c)); // the vectors' buffers move with them
    }
    return levels;
}

/// Refits, in a noisy cloud, the local surfaces whose fit's noise (fit_local_surface(), in
/// `noise` by sample, samples in Morton order) is above coarse_fit_noise: over the sample's own
/// k nearest among coarser subsamples (`levels`; each doubles the reach), from the level whose
/// reach would bring the noise to the limit were it a single sheet's, and up while it is not.
/// In the sample's own frame. `surfel(i)` is sample i's surface as the field keeps it.
void refit_coarser(std::span<const CoarseSamples> levels, std::span<const Vec3f> positions,
                   std::span<float> noise, std::span<const std::uint8_t> on_rim, std::size_t k,
                   const std::function<PackedSurfel&(std::uint32_t)>& surfel)
{
    // The level each sample starts from (levels.size(): none), by sample.
    std::vector<std::uint8_t> start(positions.size(), static_cast<std::uint8_t>(levels.size()));
    std::vector<std::uint32_t> pending = parallel_collect<std::uint32_t>(
        positions.size(), 4096,
        [&](std::size_t begin, std::size_t end, std::vector<std::uint32_t>& out) {
            for (std::size_t i = begin; i < end; ++i)
            {
                double ratio = static_cast<double>(noise[i]) / coarse_fit_noise;
                if (!(ratio > 1.0))
                    continue;
                std::size_t level = 0;
                for (; ratio > 2.0 && level + 1 < levels.size(); ratio *= 0.5)
                    ++level;
                start[i] = static_cast<std::uint8_t>(level);
                out.push_back(static_cast<std::uint32_t>(i));
            }
        });
    for (std::size_t level = 0; level < levels.size() && !pending.empty(); ++level)
    {
        const CoarseSamples& c = levels[level];
        parallel_blocks(pending.size(), 256, [&](std::size_t begin, std::size_t end) {
            std::vector<Vec3f> queries;
            std::vector<std::uint32_t> asked;
            for (std::size_t p = begin; p < end; ++p)
                if (start[pending[p]] <= level)
                {
                    asked.push_back(pending[p]);
                    queries.push_back(positions[pending[p]]);
                }
            std::vector<std::uint32_t> slots;
            std::vector<float> dist2;
            knn_of_batch(*c.grid, *c.tree, queries, k, slots, dist2);
            std::vector<Vec3f> local_positions;
            std::vector<Vec3f> local_normals;
            std::vector<std::uint32_t> order;
            for (std::size_t q = 0; q < asked.size(); ++q)
            {
                const std::uint32_t i = asked[q];
                PackedSurfel& out = surfel(i);
                local_positions.assign(1, positions[i]);
                local_normals.assign(1, out.normal);
                for (std::size_t j = 0; j < k && local_positions.size() < k; ++j)
                {
                    const std::uint32_t slot = slots[q * k + j];
                    if (c.original[slot] == i)
                        continue;
                    local_positions.push_back(c.positions[slot]);
                    local_normals.push_back(c.normals[slot]);
                }
                order.resize(local_positions.size());
                for (std::size_t o = 0; o < order.size(); ++o)
                    order[o] = static_cast<std::uint32_t>(o);
                PackedSurfel trial = out;
                const double trial_noise =
                    fit_local_surface(local_positions, local_normals, order, 0, PlaneFit::Quadric,
                                      0, on_rim[i] != 0, trial, nullptr);
                // No quadric at this scale: the finer one stays.
                noise[i] = trial_noise > 0.0 ? static_cast<float>(trial_noise) : 0.0F;
                if (trial_noise > 0.0)
                    out = trial;
            }
        });
        std::erase_if(pending, [&](std::uint32_t i) {
            return start[i] <= level && !(static_cast<double>(noise[i]) > coarse_fit_noise);
        });
    }
}

/// The narrow quadrics that the sample-by-sample test of fit_local_surface() left out, taken
/// where the whole neighbourhood shows the wide fits biased (narrow_pool_bias) and its samples
/// nearly exact (narrow_pool_clean): the detail of a clean scan that a quadric over 48
/// neighbours flattens, but whose gap at any one sample is within what that sample's own
/// residuals (ten degrees of freedom) could explain. `tests` is indexed by the slots of `grid`
/// (over the same samples as `tree`); `candidates` are the narrow fits that may be taken, a list
/// per block of slots; `take(candidate)` is called for each one taken (from any thread, once
/// per slot).
/// Measured (field |f| at the samples of the shipped bunny scan, the truth being the mesh they
/// are the vertices of, median in % of the diagonal): 0.0128 -> 0.0084; bench/peers' noisy
/// inputs and its clean analytic shapes the same field to the digits printed.
template <typename Take>
void pool_narrow_fits(const PointGrid& grid, const KdTree& tree, std::span<const Vec3f> positions,
                      std::span<const NarrowTest> tests,
                      std::span<const std::vector<NarrowCandidate>> candidates,
                      std::size_t narrow_k, const Take& take)
{
    parallel_blocks(candidates.size(), 1, [&](std::size_t begin, std::size_t end) {
        std::vector<Vec3f> queries;
        std::vector<std::uint32_t> slots;
        std::vector<float> dist2;
        std::vector<float> variances;
        for (std::size_t b = begin; b < end; ++b)
        {
            const std::vector<NarrowCandidate>& block = candidates[b];
            queries.clear();
            for (const NarrowCandidate& c : block)
                queries.push_back(positions[c.slot]);
            knn_of_batch(grid, tree, queries, narrow_k, slots, dist2);
            for (std::size_t q = 0; q < block.size(); ++q)
            {
                const std::span<const std::uint32_t> neighbors(slots.data() + q * narrow_k,
                                                               narrow_k);
                const std::span<const float> d2(dist2.data() + q * narrow_k, narrow_k);
                variances.clear();
                for (const std::uint32_t j : neighbors)
                    if (tests[j].sigma2 >= 0.0F)
                        variances.push_back(tests[j].sigma2);
                if (variances.empty())
                    continue;
                const auto middle =
                    variances.begin() + static_cast<std::ptrdiff_t>(variances.size() / 2);
                std::nth_element(variances.begin(), middle, variances.end());
                const double sigma2 = static_cast<double>(*middle);
                const double reach2 = static_cast<double>(d2[narrow_k - 1]);
                if (!(sigma2 > 0.0) || sigma2 > narrow_pool_clean * narrow_pool_clean * reach2 ||
                    static_cast<double>(tests[block[q].slot].sigma2) > narrow_pool_misfit * sigma2)
                    continue;
                double bias = 0.0;
                std::size_t count = 0;
                for (const std::uint32_t j : neighbors)
                    if (tests[j].sigma2 >= 0.0F && tests[j].spread2 > 0.0F)
                    {
                        const auto gap = static_cast<double>(tests[j].gap);
                        bias += gap * gap / (sigma2 * static_cast<double>(tests[j].spread2));
                        ++count;
                    }
                if (count > 0 && bias > narrow_pool_bias * static_cast<double>(count))
                    take(block[q]);
            }
        }
    });
}

/// Below this offset of a neighbourhood's centroid (rim_limit()) a sample is inside the sampled
/// surface, and at rim_full and above its rim is placed by the offset; in between the two
/// blend. Relative to the farthest neighbour's distance: a half disc's centroid lies 4/(3π) ≈
/// 0.42 from its centre, and at a 90° crease, where the other face's samples project onto the
/// crease line, about 0.21; 48 neighbours scattered at random round a sample put it about 0.09
/// off, and a regular grid less.
constexpr double rim_start = 0.15;
constexpr double rim_full = 0.25;

/// The centroid of a unit disc cut by the line x = h (the part x > h removed), from its centre.
double cut_disc_centroid(double h)
{
    const double w = std::sqrt(std::max(0.0, 1.0 - h * h));
    const double area = std::numbers::pi - std::acos(h) + h * w;
    return (2.0 / 3.0) * w * w * w / area;
}

/// The inverse of cut_disc_centroid() on [0, 1]: the cut h whose centroid is c.
double cut_of_disc_centroid(double c)
{
    // h in [0, 1] with cut_disc_centroid(h) = c (it falls from 0.42 at 0 to 0 at 1).
    double lo = 0.0;
    double hi = 1.0;
    for (int step = 0; step < 40; ++step)
    {
        const double mid = 0.5 * (lo + hi);
        (cut_disc_centroid(mid) > c ? lo : hi) = mid;
    }
    return lo;
}

/// How far past its crease line a sample leaves the blend's samples that hold (and joins
/// those past their lines), as a fraction of the blend's bandwidth (PointField::Impl::
/// evaluate_with()). Leaving at once made the field jump where a query crossed a line. Measured
/// on the 100k clean blobby, plate and part of bench/peers (Hausdorff / Chamfer in % of the
/// diagonal), at once -> 0.1 -> 0.25: 0.27 / 0.00590 -> 0.24 / 0.00583 -> 0.28 / 0.00588,
/// 0.34 / 0.00391 -> 0.28 / 0.00385 -> 0.30 / 0.00393, 0.46 / 0.00854 -> 0.45 / 0.00836 ->
/// 0.45 / 0.00842; the noisy blobby 1.02 / 0.0694 -> 0.91 / 0.0693, noisy part 1.20 / 0.0836 ->
/// 1.35 / 0.0836, bunny 3.64 / 0.0713 -> 3.66 / 0.0715 (0.05: 3.75 / 0.0755); the 1M clean
/// blobby 0.088 / 0.00058 -> 0.072 / 0.00058.
constexpr double crease_blend_width = 0.1;

/// A sample's normal fitted to its own face, and how far its surface reaches across a crease
/// in the blend (as rim_limit(): the direction toward the crease in the frame (t1, t2) of the
/// new normal, and the distance; zero where no crease was found).
struct CreaseFit
{
    Vec3f normal;
    Eigen::Vector4f crease = Eigen::Vector4f::Zero();
    /// At a concave crease whose other face's plane the neighbours tell (crease_limit()): that
    /// plane as (m, c), m its outward unit normal, the signed distance of p (relative to the
    /// sample) m · p − c; zero elsewhere.
    Eigen::Vector4f other = Eigen::Vector4f::Zero();
    /// Whether the crease is a convex wedge's edge (convex_edge()): its other face's samples
    /// project onto the sample's own side of its tangent plane, so that its neighbourhood looks
    /// like a rim's (rim_limit()), though the surface goes on round the edge.
    bool wedge = false;
};

/// The crease line of a sample whose plane (normal n, through the sample) leaves some
/// neighbours out (residuals beyond the biweight's cut): the neighbours it holds lie to one
/// side, as a disc cut by the crease (their centroid over the plane, relative to the farthest
/// of them, rim_start and more off the sample; cut_disc_centroid() places the cut), and the
/// samples beyond it are the other face's. A crease needs three outliers or more that do not
/// face away (the other side of a thin wall lies under the whole neighbourhood and bounds
/// nothing), and a one-sided neighbourhood (outliers of noise leave it centred); where the
/// outliers span a plane of their own, the line where it meets the sample's bounds the cut
/// too. `cut`: the biweight's cut of the plane. Past the line the sample leaves the blend to
/// the other face's samples, whose own lines end where its face
/// begins: the blend meets the two faces at the crease instead of rounding it, and neither
/// face's surface reaches beyond it. The line itself is the limit: on the 100k clean part of
/// bench/peers, with a margin of 0.25 / 0.1 / 0 of the farthest neighbour's distance beyond
/// it, Hausdorff 1.17 / 0.91 / 0.80 % of the diagonal (0.93 with no limit), Chamfer 0.0102 /
/// 0.0102 / 0.0101 %; the plate 1.15 / 0.88 / 0.89 (0.98). `other_plane`, unless null, gets
/// the other face's plane at a concave crease (CreaseFit::other).
Eigen::Vector4f crease_limit(const CreaseNeighbourhood& hood,
                             std::span<const std::uint32_t> neighbors,
                             std::span<const Vec3f> normals, const Vec3f& normal, double cut,
                             float away, Eigen::Vector4f* other_plane)
{
    const Vec3d n = normal.cast<double>();
    const Vec3d t1 = tangent_of(normal).cast<double>();
    const Vec3d t2 = n.cross(t1);
    // Off the plane by more than `beyond` and not facing away: the other face's.
    const auto other_face = [&](std::size_t j, double beyond) {
        return std::abs(hood.x[j].dot(n)) > beyond && normals[neighbors[j]].dot(normal) > away;
    };
    Eigen::Vector2d sum = Eigen::Vector2d::Zero();
    std::size_t inliers = 0;
    std::size_t outliers = 0;
    double inlier_far2 = 0.0;
    double outlier_height = 0.0;
    Vec3d outlier_normal = Vec3d::Zero();
    for (std::size_t j = 0; j < hood.count; ++j)
    {
        if (std::abs(hood.x[j].dot(n)) <= cut)
        {
            sum += Eigen::Vector2d(hood.x[j].dot(t1), hood.x[j].dot(t2));
            inlier_far2 = std::max(inlier_far2, hood.x[j].squaredNorm());
            ++inliers;
        }
        else if (other_face(j, cut))
        {
            outlier_height += hood.x[j].dot(n);
            outlier_normal += normals[neighbors[j]].cast<double>();
            ++outliers;
        }
    }
    if (outliers < 3 || inliers == 0 || !(inlier_far2 > 0.0))
        return Eigen::Vector4f::Zero();
    const double inlier_far = std::sqrt(inlier_far2);
    const Eigen::Vector2d centroid = sum / (static_cast<double>(inliers) * inlier_far);
    const double offset = centroid.norm();
    if (!(offset >= rim_start))
        return Eigen::Vector4f::Zero();
    const Eigen::Vector2d toward = -centroid / offset;
    double limit = cut_of_disc_centroid(offset) * inlier_far;
    // The other face's plane (the principal plane of the outliers) meets the sample's along
    // the crease: where the two turn by 30° and more, that line bounds the limit too. A sample
    // on the crease line itself holds some of the other face's samples next to the line among
    // its inliers, which pull their centroid back and the cut out: at the edge of the 100k
    // clean part of bench/peers, a line 0.0186 off where it is 0, and a lip 0.018 under the
    // face (Hausdorff 0.71% of the diagonal, 0.47% with the planes' line; Chamfer 0.0101% ->
    // 0.0099%). The plane of only the outliers beyond twice the cut (which noise rarely puts
    // there) was missing where a shallow concave crease puts few samples that far: on the 100k
    // clean blobby a crease line 0.015 out and a jump of the field (Hausdorff 0.34% -> 0.27%
    // with every outlier, the plate 0.40% -> 0.34%, Chamfer of the part 0.0089% -> 0.0085%);
    // the noisy inputs' Chamfer moved by under 1%, the bunny's 0.0707% -> 0.0713%.
    Vec3d mean;
    Eigen::Vector2d direction = toward;
    if (const auto solver = hood.principal_axes(
            [&](std::size_t j) {
                return other_face(j, cut) && normals[neighbors[j]].dot(normal) < crease_turn_cosine
                           ? 1.0
                           : 0.0;
            },
            &mean))
    {
        const Vec3d m = solver->eigenvectors().col(0);
        const Vec3d d = toward.x() * t1 + toward.y() * t2;
        const double turn = std::abs(m.dot(n));
        // The line where the other plane (m · (x − mean) = 0) meets the sample's runs across
        // the direction `along` of m's part in the sample's plane, at t from the sample. Where
        // the inliers' centroid points more than 30° away from that direction, the centroid is
        // off by a gap of the sampling, not cut by the crease, and the planes' line places the
        // limit and its direction; otherwise the centroid's direction stands and the line
        // bounds the limit along it. The plane is fitted to the outliers whose normals turn by
        // 30° or more (the other face's; samples of the sample's own face beyond the cut, by
        // its curvature, tilted it: a plane 77° from the boss's top). On the 1M clean part of
        // bench/peers a gap beside a sample 0.0105 under the boss's rim (at two places of its
        // circumference) turned the centroid's direction 72° from the rim and put the line
        // 0.003 off along it: the wall's surface stopped there, a fin of f ≈ 0 a spacing
        // inside the wall, and a dent of 0.0066 in the mesh, its largest distance from the
        // truth (0.259% of the diagonal against marching cubes' 0.202%).
        const Vec3d inplane = m - m.dot(n) * n;
        const double reach = inplane.norm();
        double t = reach > 0.0 ? m.dot(mean) / reach : 0.0;
        Vec3d along = reach > 0.0 ? Vec3d(inplane / reach) : d;
        if (t < 0.0)
        {
            t = -t;
            along = -along;
        }
        if (solver->eigenvalues()[1] > 4.0 * solver->eigenvalues()[0] && turn < 0.866 &&
            reach > 0.0 && along.dot(d) > 0.0)
        {
            if (along.dot(d) < static_cast<double>(crease_turn_cosine))
            {
                limit = t;
                direction = Eigen::Vector2d(along.dot(t1), along.dot(t2));
            }
            else
            {
                t *= reach / std::abs(m.dot(d));
                limit = std::min(limit, t);
            }
            // At a concave crease the solid is the union of the two faces' half-spaces: the
            // signed distance min(own, other) holds on both sides of the line without placing
            // it (evaluate_with()), where the line's placement, pulled into the sample's own
            // face by the min above, put points of the groove "past" it and inside.
            const double facing = m.dot(outlier_normal);
            if (other_plane != nullptr && outlier_height > 0.0 && t >= 0.0 && t <= inlier_far &&
                facing != 0.0)
            {
                const Vec3d outward = facing > 0.0 ? m : Vec3d(-m);
                *other_plane = {static_cast<float>(outward.x()), static_cast<float>(outward.y()),
                                static_cast<float>(outward.z()),
                                static_cast<float>(outward.dot(mean))};
            }
        }
    }
    // The other face falls away under the sample's plane at a convex crease (outside past the
    // line) and rises over it at a concave one (inside past the line).
    return {static_cast<float>(direction.x()), static_cast<float>(direction.y()),
            static_cast<float>(limit), outlier_height < 0.0 ? 1.0F : -1.0F};
}

/// crease_plane(), and where it refitted the normal, how far the sample's surface reaches
/// across the crease (crease_limit()).
CreaseFit crease_normal(std::span<const Vec3f> positions, std::span<const Vec3f> normals,
                        std::span<const std::uint32_t> neighbors, std::size_t i,
                        const Vec3f& normal, bool clean)
{
    CreaseNeighbourhood hood;
    const CreasePlane plane = crease_plane(hood, positions, normals, neighbors, i, normal, clean);
    if (!plane.refitted)
        return {normal};
    CreaseFit out{plane.normal};
    out.crease = crease_limit(hood, neighbors, normals, out.normal, plane.cut, plane.away,
                              clean ? &out.other : nullptr);
    out.wedge = plane.wedge && out.crease.w() > 0.0F;
    return out;
}

/// Where sample i's neighbours lie around it (all of them, whichever way they face, so that a
/// crease's other face counts): their centroid over its tangent plane, in the frame (t1, t2)
/// and relative to the farthest neighbour's distance `far`.
struct NeighbourhoodOffset
{
    Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
    double far = 0.0;
};

NeighbourhoodOffset neighbourhood_offset(std::span<const Vec3f> positions,
                                         std::span<const std::uint32_t> neighbors, std::size_t i,
                                         const PackedSurfel& surfel)
{
    const Vec3f t1 = surfel.tangent;
    const Vec3f t2 = surfel.normal.cross(t1);
    Eigen::Vector2d sum = Eigen::Vector2d::Zero();
    double far2 = 0.0;
    for (const std::uint32_t j : neighbors)
    {
        const Vec3f x = positions[j] - positions[i];
        sum += Eigen::Vector2d(x.dot(t1), x.dot(t2));
        far2 = std::max(far2, static_cast<double>(x.squaredNorm()));
    }
    NeighbourhoodOffset out;
    if (far2 > 0.0)
    {
        out.far = std::sqrt(far2);
        out.centroid = sum / (static_cast<double>(neighbors.size()) * out.far);
    }
    return out;
}

/// How far across its rim the field of a sample reaches (PointFieldOptions::rim_reach), as the
/// outward unit direction over the tangent plane (t1, t2) and the distance along it; all zero
/// where the sample is inside the surface (no limit). The rim is where the sample's neighbours
/// end: their centroid lies c ℓ from the sample (`offset`; ℓ the farthest neighbour's
/// distance), as a disc of radius ℓ cut at h ℓ puts it (cut_disc_centroid(h) = c). The field
/// reaches r − (1 − reach) min(r, ℓ) past the rim, r the influence radius: automatic radii
/// (about 0.9 ℓ) end `reach` of a radius past it, and radii raised to span a hole (§4.1) still
/// span it.
Eigen::Vector3f rim_limit(const NeighbourhoodOffset& offset, double radius, double reach)
{
    const double c = offset.centroid.norm();
    if (c < rim_start || !(offset.far > 0.0))
        return Eigen::Vector3f::Zero();
    const double limit = cut_of_disc_centroid(c) * offset.far + radius -
                         (1.0 - reach) * std::min(radius, offset.far);
    const double t = std::min(1.0, (c - rim_start) / (rim_full - rim_start));
    const double blended = std::min(radius, (1.0 - t) * radius + t * limit);
    if (!(blended < radius))
        return Eigen::Vector3f::Zero();
    const Eigen::Vector2d outward = -offset.centroid / c;
    return {static_cast<float>(outward.x()), static_cast<float>(outward.y()),
            static_cast<float>(blended)};
}

/// How far `p` (relative to the origin) lies past a sample's limit, a rim's (rim_limit()) or a
/// crease line's (crease_limit()): the part of p − s along the limit's direction (x, y in the
/// frame (t1, t2)) beyond its distance z; zero or less where the sample's surface holds at p,
/// and zero where the limit has no direction (none).
double past_limit(const PackedSurfel& s, const Eigen::Vector3f& limit, const Vec3d& p)
{
    if (limit.x() == 0.0F && limit.y() == 0.0F)
        return 0.0;
    const Vec3d x = p - s.position.cast<double>();
    const Vec3d t1 = s.tangent.cast<double>();
    const Vec3d t2 = s.normal.cast<double>().cross(t1);
    const double outward =
        x.dot(t1) * static_cast<double>(limit.x()) + x.dot(t2) * static_cast<double>(limit.y());
    return outward - static_cast<double>(limit.z());
}

/// sums += scale × more.
void add(BlendSums& sums, const BlendSums& more, double scale)
{
    sums.weight += scale * more.weight;
    sums.value += scale * more.value;
    sums.normal += scale * more.normal;
    sums.weighted_gradient += scale * more.weighted_gradient;
    sums.gradient += scale * more.gradient;
}

/// The signed distance from `p` (relative to the origin) to a sample's face bounded by its
/// crease line (crease_limit()), for a point `past` the line by that much (past_limit()), and
/// its gradient: past a convex crease the face's nearest point is on the line, and p lies
/// outside unless under the face's surface too (then the other face's wall is nearer: outside
/// still); past a concave one p lies inside, under the other face. At an ideal crease of two planes
/// this is the distance to the nearer face, exact on both sides (the other face's samples, past
/// their own lines, give the same). The blend weighs it in where the samples whose surface holds at
/// p carry little of the blend (PointField::Impl::evaluate_with()), as outside a convex corner,
/// where each face is bounded by two lines and a sample's one line leaves some faces' surfaces
/// running past the corner.
double bounded_face_distance(const PackedSurfel& s, const Eigen::Vector4f& crease, double past,
                             const Vec3d& p, Vec3d* gradient)
{
    Vec3d surface_gradient;
    const double height = s.distance(p, &surface_gradient);
    const double along = crease.w() > 0.0F ? std::max(height, 0.0) : std::min(height, 0.0);
    const double length = std::hypot(along, past);
    if (!(length > 0.0))
    {
        *gradient = surface_gradient;
        return height;
    }
    const Vec3d t1 = s.tangent.cast<double>();
    const Vec3d t2 = s.normal.cast<double>().cross(t1);
    const Vec3d toward =
        static_cast<double>(crease.x()) * t1 + static_cast<double>(crease.y()) * t2;
    const double value = crease.w() > 0.0F ? length : -length;
    *gradient = (along * surface_gradient + past * toward) / value;
    return value;
}

/// What answers queries far from the samples (PointField): a feature grid over the padded box
/// and, per sample, whether it represents a site that also holds a sample facing the other way
/// (a wall thinner than the grid spacing, whose side the site cannot tell).
struct FarField
{
    FeatureGrid grid;
    std::vector<std::uint8_t> two_sided; ///< by sample index

    FarField(const PointCloud& surfels, const Aabb& local_box)
        : grid(surfels.positions, local_box, far_grid_nodes), two_sided(surfels.size(), 0)
    {
        for (std::size_t i = 0; i < surfels.size(); ++i)
        {
            const auto [x, y, z] = grid.site_of(surfels.positions[i]);
            const std::uint32_t representative = grid.node(x, y, z).point;
            if (surfels.normals[i].dot(surfels.normals[representative]) < 0.0F)
            {
                two_sided[representative] = 1;
            }
        }
    }
};

/// The far grid's answer at a query point (nullopt outside its box).
using FarCell = std::optional<FeatureGrid::CellQuery>;

/// The samples nearest to the last single-point evaluation of a point field on one thread that
/// the point grid turned down (a search of the kd-tree, the costly kind: far from the samples,
/// or where they are sparse, as over a hole): successive evaluations are mostly close together
/// (the samples of a projection along its line, regula falsi's steps), and a query within the
/// margin that `bound2` leaves around `centre` has its wanted() nearest samples among these,
/// which then need no search.
struct NeighbourMemo
{
    std::uint64_t field = 0; ///< PointField::Impl::id of the field that filled it; 0: empty
    Vec3f centre = Vec3f::Zero();
    /// The squared distance from `centre` of the farthest of `slot`: no other sample is nearer.
    float bound2 = 0.0F;
    /// sqrt(bound2) minus the wanted()-th distance from `centre`: a query that has moved farther
    /// than this is not tried (it rarely passes).
    float gap = 0.0F;
    /// The field's memo_size() nearest samples of `centre`, nearest first.
    std::array<std::uint32_t, memo_capacity> slot{};
};

/// Unique per point field ever built, so that a thread's memo never mixes fields.
std::atomic<std::uint64_t> next_field_id{1};

struct PointField::Impl
{
    PointCloud surfels;
    PointFieldOptions options;
    KdTree tree;
    std::unique_ptr<PointGrid> grid;
    std::vector<PackedSurfel> packed; ///< indexed by grid slot
    /// Per grid slot: how far the sample's field reaches across its rim (rim_limit()): the
    /// outward direction in (t1, t2) and the distance; zero where the sample is inside the
    /// surface. Empty where rim_reach is 1.
    std::vector<Eigen::Vector3f> rim;
    /// Per grid slot: how far the sample's surface reaches across a crease in the blend
    /// (crease_normal()), as `rim` holds it, and +1 for a convex crease, -1 for a concave one;
    /// zero where no crease. Empty but for quadric fits.
    std::vector<Eigen::Vector4f> crease;
    /// Per grid slot, with crease: the other face's plane at a concave crease (CreaseFit::other).
    std::vector<Eigen::Vector4f> other_plane;
    /// Per grid slot: the distance from the sample to its memo_size()-th nearest (itself the
    /// first), from the fit's search; empty when the fit takes fewer. Bounds a search of the
    /// kd-tree from a query near the sample (far_bound()).
    std::vector<float> slot_reach;
    /// The stray samples (ScatterTest::stray()), ascending.
    std::vector<std::uint32_t> strays;
    /// Per grid slot: 1 for a member of a spray (Strays::sprayed), which neither blends nor
    /// defines the field; empty when there are none.
    std::vector<std::uint8_t> stray_slot;
    Aabb box;
    Aabb local_box;  ///< box, relative to the cloud's origin
    Aabb sample_box; ///< the samples' bounding box, relative to the origin
    double median_radius = 0.0;
    bool noisy = false;
    double max_radius = 0.0;
    double area = 0.0;
    /// Farther from every sample than this, the point grid's knn_nearby() finds nothing: it
    /// scans at most the 3 × 3 × 3 cells around the query's cell (a margin covers the float
    /// rounding of queries).
    double nearby_reach = 0.0;
    /// Built on the first query that the point grid cannot answer, so that fields never queried
    /// far from their samples cost nothing more.
    mutable std::once_flag far_once;
    mutable std::unique_ptr<const FarField> far;
    mutable std::atomic<const FarField*> far_built{nullptr};

    std::uint64_t id = next_field_id.fetch_add(1, std::memory_order_relaxed);

    Impl(PointCloud cloud, const PointFieldOptions& opts)
        : surfels(std::move(cloud)), options(opts), tree(surfels.positions)
    {}

    [[nodiscard]] const FarField& far_field() const
    {
        std::call_once(far_once, [this] {
            far = std::make_unique<const FarField>(surfels, local_box);
            far_built.store(far.get(), std::memory_order_release);
        });
        return *far;
    }

    /// How many neighbours a query needs: the blended ones and the next, or the nearest.
    [[nodiscard]] std::size_t wanted() const;
    /// False where `p` (relative to the origin) is certainly too far from the samples for the
    /// point grid to answer (knn_nearby() would find none).
    [[nodiscard]] bool maybe_nearby(const Vec3d& p, const FarField* far_data) const;
    /// The field at `p` (relative to the origin; `query` is it in floats) given what the point
    /// grid's knn_nearby() found there: `found` (0 if it was not asked, or found none)
    /// neighbours in `slot` and `dist2`, which have room for wanted() and may be overwritten.
    /// `nearby`: whether maybe_nearby() holds at `p`. Above `hi`, a far value may be any bound
    /// above it (Field::evaluate_within). With a `memo` (for whose candidates `slot` and
    /// `dist2` have room), a search of the kd-tree takes memo_extra more neighbours and keeps them
    /// there (recall_neighbours()).
    [[nodiscard]] FieldSample evaluate_with(const Vec3d& p, const Vec3f& query,
                                            const FarField* far_data, bool nearby,
                                            std::size_t found, std::uint32_t* slot, float* dist2,
                                            double hi, NeighbourMemo* memo = nullptr) const;

    /// How many neighbours the memo keeps: wanted() and memo_extra more, at most every sample.
    [[nodiscard]] std::size_t memo_size() const;
    /// Keeps the `found` nearest samples of `query` (slot, nearest first) in `memo`, if they
    /// are memo_size() of them.
    void remember_neighbours(NeighbourMemo& memo, const Vec3f& query, std::size_t found,
                             const std::uint32_t* slot, const float* dist2) const;
    /// The wanted() nearest samples of `query`, nearest first, into `slot` and `dist2`, from the
    /// memo, if the memo proves them: no other sample can be nearer than the last of them, no
    /// two of them are at the same distance (so that every search, whatever its tie rule,
    /// finds them in this order, with these distances) and the nearest lies well inside the
    /// largest influence radius (so that evaluate_with() blends them, as a search's would).
    /// False (and the buffers overwritten) otherwise.
    [[nodiscard]] bool recall_neighbours(const NeighbourMemo& memo, const Vec3f& query,
                                         std::uint32_t* slot, float* dist2) const;
    /// A squared distance from `query` that the memo's memo_size() candidates all lie within
    /// (the farthest of them): a bound for the search of memo_size() neighbours that
    /// recall_neighbours() could not spare, close to their true distance when the query has
    /// moved little (the samples of a projection's line). Infinity when the memo is empty.
    [[nodiscard]] float memo_bound(const NeighbourMemo& memo, const Vec3f& query) const;
    /// A squared distance from a query that at least memo_size() samples lie within, given a
    /// sample (grid `slot`) at squared distance `d2` from it: that sample's reach beyond the
    /// distance (the triangle inequality), and the memo's bound if tighter. Infinity when
    /// neither is known.
    [[nodiscard]] float far_bound(std::uint32_t slot, float d2, const NeighbourMemo* memo,
                                  const Vec3f& query) const;

    /// The value at `p` (relative to the origin) where the far grid proves that no influence
    /// ball reaches and every candidate sample's surface puts `p` inside; false (and `out`
    /// untouched) otherwise. `cell` is the far grid's query at `p`.
    bool evaluate_deep_inside(const FarField& far_data, const FarCell& cell, const Vec3d& p,
                              FieldSample& out) const;

    /// The representative of `cell`'s corners nearest to `p` (ties to the smallest index) and
    /// its squared distance, where every representative's surface puts `p` inside (or outside)
    /// and none stands for a two-sided site; nullopt otherwise.
    [[nodiscard]] std::optional<std::pair<std::uint32_t, double>> agreeing_representative(
        const FarField& far_data, const FeatureGrid::CellQuery& cell, const Vec3d& p,
        bool inside) const;

    /// The value at `p` (relative to the origin) where the far grid proves that no influence
    /// ball reaches and every candidate sample's surface puts `p` outside: the distance to a
    /// nearly nearest sample, or a lower bound on it where that is above `hi`; false (and `out`
    /// untouched) otherwise. `cell` is the far grid's query at `p`.
    bool evaluate_far_outside(const FarField& far_data, const FarCell& cell, const Vec3d& p,
                              const Vec3f& query, double hi, FieldSample& out) const;

    /// A sample at most far_distance_factor times as far from `p` as the nearest (its squared
    /// distance to `dist2`), started from the nearest of the representatives of `cell` (the far
    /// grid's query at `p`) where there is one.
    [[nodiscard]] std::uint32_t nearly_nearest(const FarCell& cell, const Vec3f& query,
                                               float& dist2) const;
};

bool PointField::Impl::evaluate_far_outside(const FarField& far_data, const FarCell& cell_at_p,
                                            const Vec3d& p, const Vec3f& query, double hi,
                                            FieldSample& out) const
{
    // The cell at p, or beyond the grid's box at the nearest point of the box.
    const Vec3d q = p.cwiseMax(local_box.min).cwiseMin(local_box.max);
    const FarCell cell = q == p ? cell_at_p : far_data.grid.query(q);
    if (!cell)
    {
        return false;
    }
    const double to_box = (p - p.cwiseMax(sample_box.min).cwiseMin(sample_box.max)).norm();
    const double lower = std::max(to_box, cell->lower_bound - (p - q).norm());
    const double reach = max_radius * static_cast<double>(far_distance_factor);
    if (!(lower > reach))
    {
        return false;
    }
    // As deep inside (evaluate_deep_inside), the other way round.
    const auto agreed = agreeing_representative(far_data, *cell, p, false);
    if (!agreed)
    {
        return false;
    }
    const std::uint32_t best = agreed->first;
    out.defined = false;
    if (lower > hi)
    {
        out.value = lower;
        out.gradient = packed[grid->slot_of(best)].normal.cast<double>();
        return true;
    }
    std::uint32_t nearest = best;
    if (blends(options.fit))
    {
        float d2 = 0.0F;
        nearest = tree.nearest_within_factor(query, far_distance_factor, PointId{best}, &d2).value;
    }
    else
    {
        std::array<std::uint32_t, 1> index{};
        std::array<float, 1> d2{};
        tree.knn(query, 1, index, d2);
        nearest = index[0];
    }
    const PackedSurfel& sample = packed[grid->slot_of(nearest)];
    out.value = (p - sample.position.cast<double>()).norm();
    out.gradient = sample.normal.cast<double>();
    return true;
}

std::uint32_t PointField::Impl::nearly_nearest(const FarCell& cell, const Vec3f& query,
                                               float& dist2) const
{
    if (!cell)
    {
        return tree.nearest_within_factor(query, far_distance_factor, &dist2).value;
    }
    std::uint32_t start = cell->points[0];
    float start_d2 = std::numeric_limits<float>::infinity();
    for (const std::uint32_t index : cell->points)
    {
        const float d2 = (query - surfels.positions[index]).squaredNorm();
        if (d2 < start_d2 || (d2 == start_d2 && index < start))
        {
            start = index;
            start_d2 = d2;
        }
    }
    return tree.nearest_within_factor(query, far_distance_factor, PointId{start}, &dist2).value;
}

bool PointField::Impl::evaluate_deep_inside(const FarField& far_data, const FarCell& cell,
                                            const Vec3d& p, FieldSample& out) const
{
    const double reach = max_radius * static_cast<double>(far_distance_factor);
    if (!cell || !(cell->lower_bound > reach))
    {
        return false;
    }
    // The corners' representatives: all must say inside; the nearest gives the value.
    const auto agreed = agreeing_representative(far_data, *cell, p, true);
    if (!agreed)
    {
        return false;
    }
    out.defined = false;
    out.value = -std::sqrt(agreed->second);
    out.gradient = packed[grid->slot_of(agreed->first)].normal.cast<double>();
    return true;
}

std::optional<std::pair<std::uint32_t, double>> PointField::Impl::agreeing_representative(
    const FarField& far_data, const FeatureGrid::CellQuery& cell, const Vec3d& p, bool inside) const
{
    std::uint32_t best = 0;
    double best_d2 = std::numeric_limits<double>::infinity();
    std::uint32_t checked = std::numeric_limits<std::uint32_t>::max(); // never a sample index
    for (const std::uint32_t index : cell.points)
    {
        if (index == checked)
        {
            continue; // neighbouring corners often share their representative
        }
        checked = index;
        const PackedSurfel& sample = packed[grid->slot_of(index)];
        const double side = sample.distance(p, nullptr);
        if (far_data.two_sided[index] != 0 || !(inside ? side < 0.0 : side > 0.0))
        {
            return std::nullopt;
        }
        const double d2 = (p - sample.position.cast<double>()).squaredNorm();
        if (d2 < best_d2 || (d2 == best_d2 && index < best))
        {
            best = index;
            best_d2 = d2;
        }
    }
    return std::pair{best, best_d2};
}

PointField::PointField(PointCloud surfels, const PointFieldOptions& options)
{
    check_surfels(surfels);
    if (blends(options.fit) && (options.blend_k < 2 || options.blend_k > max_blend_k))
    {
        throw InvalidInput("point field: blend_k must be between 2 and " +
                           std::to_string(max_blend_k));
    }
    if (options.fit != PlaneFit::Raw && options.centroid_k < 2)
    {
        throw InvalidInput("point field: centroid_k must be at least 2");
    }
    if (options.fit == PlaneFit::Quadric && options.quadric_k < 2)
    {
        throw InvalidInput("point field: quadric_k must be at least 2");
    }
    if (options.quadric_narrow_k != 0 &&
        (options.quadric_narrow_k < 10 || options.quadric_narrow_k > options.quadric_k))
    {
        throw InvalidInput("point field: quadric_narrow_k must be 0 or between 10 and quadric_k");
    }
    if (!(options.rim_reach > 0.0 && options.rim_reach <= 1.0))
    {
        throw InvalidInput("point field: rim_reach must be in (0, 1]");
    }
    // The samples in Morton order (spatial_order()), whatever order they came in: the fits, the
    // trees and every pass over them then read memory in order, not a file's (1M samples in a
    // random order took 1.4-2.6 s longer in reconstruct), and the field is the same for any
    // order of the same samples (up to the order of samples at one place).
    {
        const std::vector<std::uint32_t> order = spatial_order(surfels.positions);
        bool in_order = true;
        for (std::size_t j = 0; j < order.size() && in_order; ++j)
            in_order = order[j] == j;
        if (!in_order)
            reorder_points(surfels, order);
    }
    impl_ = std::make_unique<Impl>(std::move(surfels), options);
    Impl& m = *impl_;
    m.options.progress = nullptr; // for the construction only: options() keeps no callback
    const std::size_t n = m.surfels.size();
    for (std::size_t i = 0; i < n; ++i)
    {
        m.surfels.normals[i].normalize();
    }

    const std::size_t fit_k =
        options.fit == PlaneFit::Quadric ? options.quadric_k : options.centroid_k;
    const std::size_t k = std::min(std::max<std::size_t>(fit_k, 2) + 1, n);

    // Grid cells of about twice a query's farthest neighbour, so that queries near the surface
    // find their neighbours in the 8 cells around them (PointGrid); the median is taken over
    // a fixed subsample. The same for the fits' k neighbours, which get a grid of their own.
    const std::size_t query_k = std::min(blends(options.fit) ? options.blend_k + 1 : 9, n);
    const std::size_t reach_k = std::max(query_k, k);
    const std::size_t stride = std::max<std::size_t>(1, n / 20000);
    const std::size_t subsample = (n + stride - 1) / stride;
    std::vector<float> query_reach(subsample);
    std::vector<float> fit_reach(subsample);
    std::vector<double> fit_flatness(subsample);
    // Searched along a Morton curve, as measure_sampling_density() does (the same searches).
    std::vector<Vec3f> probes(subsample);
    for (std::size_t r = 0; r < subsample; ++r)
        probes[r] = m.surfels.positions[r * stride];
    const std::vector<std::uint32_t> probe_order = spatial_order(probes);
    parallel_blocks(subsample, 256, [&](std::size_t begin, std::size_t end) {
        std::vector<std::uint32_t> index(reach_k);
        std::vector<float> d2(reach_k);
        for (std::size_t o = begin; o < end; ++o)
        {
            const std::size_t r = probe_order[o];
            m.tree.knn(probes[r], reach_k, index, d2);
            query_reach[r] = d2[query_k - 1];
            fit_reach[r] = d2[k - 1];
            fit_flatness[r] = flatness(m.surfels.positions, std::span(index).first(k));
        }
    });
    const bool clean = clean_cloud(fit_flatness);
    const auto grid_cell = [](std::vector<float>& reach) {
        auto middle = reach.begin() + static_cast<std::ptrdiff_t>(reach.size() / 2);
        std::nth_element(reach.begin(), middle, reach.end());
        const float cell = grid_cell_scale * std::sqrt(*middle);
        return cell > 0.0F ? cell : 1.0F;
    };
    m.grid = std::make_unique<PointGrid>(m.surfels.positions, grid_cell(query_reach), m.tree);

    // Noisy clouds: each fit's noise, for the refits over coarser subsamples.
    m.noisy = !clean;
    const bool refit = options.fit == PlaneFit::Quadric && !clean && options.noise_scale;
    std::vector<float> fit_noise(refit ? n : 0, 0.0F);
    std::vector<std::uint8_t> fit_on_rim(refit ? n : 0, 0);

    // Each sample's local surface from its k nearest. The samples are taken in the order of
    // the fits' grid (neighbouring samples after each other, which its batch queries answer
    // fastest), and the fits read positions and normals in that order too (a sample's
    // neighbours are then near it in memory), without keeping a table of every sample's
    // neighbours.
    const PointGrid fit_grid(m.surfels.positions, grid_cell(fit_reach), m.tree);
    std::vector<Vec3f> fit_positions(fit_grid.slot_count(), Vec3f::Zero());
    std::vector<Vec3f> fit_normals(fit_grid.slot_count(), Vec3f::Zero());
    for (std::uint32_t slot = 0; slot < fit_grid.slot_count(); ++slot)
    {
        const std::uint32_t i = fit_grid.original_index(slot);
        if (i != PointGrid::padding_slot)
        {
            fit_positions[slot] = m.surfels.positions[i];
            fit_normals[slot] = m.surfels.normals[i];
        }
    }
    constexpr std::size_t block = 4096;
    m.packed.assign(m.grid->slot_count(), PackedSurfel{});
    if (blends(options.fit) && options.rim_reach < 1.0)
        m.rim.assign(m.grid->slot_count(), Eigen::Vector3f::Zero());
    const std::size_t reach_rank = m.memo_size();
    if (k >= reach_rank)
        m.slot_reach.assign(m.grid->slot_count(), 0.0F);
    if (options.fit == PlaneFit::Quadric && options.crease_fit)
    {
        m.crease.assign(m.grid->slot_count(), Eigen::Vector4f::Zero());
        m.other_plane.assign(m.grid->slot_count(), Eigen::Vector4f::Zero());
    }
    std::vector<double> block_area((fit_grid.slot_count() + block - 1) / block, 0.0);
    // For pool_narrow_fits(): a test per fit-grid slot, the candidates block by block.
    std::vector<NarrowTest> narrow_tests;
    std::vector<std::vector<NarrowCandidate>> narrow_candidates;
    if (options.fit == PlaneFit::Quadric && options.quadric_narrow_k != 0)
    {
        narrow_tests.resize(fit_grid.slot_count());
        narrow_candidates.resize(block_area.size());
    }
    ProgressReporter reporter(options.progress, "field");
    parallel_blocks(
        fit_grid.slot_count(), block,
        [&](std::size_t begin, std::size_t end) {
            std::vector<std::uint32_t> samples; // fit-grid slots
            std::vector<Vec3f> queries;
            samples.reserve(end - begin);
            queries.reserve(end - begin);
            for (std::size_t slot = begin; slot < end; ++slot)
            {
                if (fit_grid.original_index(static_cast<std::uint32_t>(slot)) !=
                    PointGrid::padding_slot)
                {
                    samples.push_back(static_cast<std::uint32_t>(slot));
                    queries.push_back(fit_positions[slot]);
                }
            }
            std::vector<std::uint32_t> slots;
            std::vector<float> dist2;
            knn_of_batch(fit_grid, m.tree, queries, k, slots, dist2);
            double area = 0.0;
            for (std::size_t q = 0; q < samples.size(); ++q)
            {
                const std::span<std::uint32_t> neighbors(slots.data() + q * k, k);
                const std::span<const float> d2(dist2.data() + q * k, k);
                // The ball to the last neighbour holds k samples: π d² / k of surface per sample.
                area += std::numbers::pi * static_cast<double>(d2[k - 1]) / static_cast<double>(k);
                const std::uint32_t i = fit_grid.original_index(samples[q]);
                if (!m.slot_reach.empty())
                    m.slot_reach[m.grid->slot_of(i)] = std::sqrt(d2[reach_rank - 1]);
                PackedSurfel packed;
                packed.position = m.surfels.positions[i];
                packed.radius = m.surfels.radii[i];
                CreaseFit crease{m.surfels.normals[i]};
                if (options.fit == PlaneFit::Quadric && options.crease_fit)
                    crease = crease_normal(fit_positions, fit_normals, neighbors, samples[q],
                                           m.surfels.normals[i], clean);
                packed.normal = crease.normal;
                if (!m.crease.empty())
                {
                    m.crease[m.grid->slot_of(i)] = crease.crease;
                    m.other_plane[m.grid->slot_of(i)] = crease.other;
                }
                packed.tangent = tangent_of(packed.normal);
                // Where the neighbours lie (a rim?): for the quadric's fit and the blend's rim
                // limit.
                const NeighbourhoodOffset offset =
                    blends(options.fit)
                        ? neighbourhood_offset(fit_positions, neighbors, samples[q], packed)
                        : NeighbourhoodOffset{};
                NarrowFit narrow;
                const bool on_rim = offset.centroid.norm() >= rim_full;
                const double noise =
                    fit_local_surface(fit_positions, fit_normals, neighbors, samples[q],
                                      options.fit, options.quadric_narrow_k, on_rim, packed,
                                      narrow_tests.empty() ? nullptr : &narrow);
                if (!fit_noise.empty() &&
                    (options.noise_scale_region.cells.empty() ||
                     options.noise_scale_region.contains(m.surfels.origin +
                                                         m.surfels.positions[i].cast<double>())))
                {
                    fit_noise[i] = static_cast<float>(noise);
                    fit_on_rim[i] = on_rim ? 1 : 0;
                }
                if (!narrow_tests.empty())
                {
                    narrow_tests[samples[q]] = narrow.test;
                    if (narrow.candidate)
                        narrow_candidates[begin / block].push_back({samples[q], narrow.coef});
                }
                m.packed[m.grid->slot_of(i)] = packed;
                // A wedge's edge is no rim: past it the field stays defined as far as past any
                // crease (on the clean 100k cone it ended about 0.7 of a radius past the tip, a
                // cell of the intermediate grid, and marching cubes left holes along the rim).
                if (blends(options.fit) && options.rim_reach < 1.0 && !crease.wedge)
                    m.rim[m.grid->slot_of(i)] =
                        rim_limit(offset, static_cast<double>(packed.radius), options.rim_reach);
            }
            block_area[begin / block] = area;
        },
        &reporter);
    reporter.finish();
    if (!narrow_tests.empty())
    {
        pool_narrow_fits(
            fit_grid, m.tree, fit_positions, narrow_tests, narrow_candidates,
            options.quadric_narrow_k, [&](const NarrowCandidate& fit) {
                set_quadric(m.packed[m.grid->slot_of(fit_grid.original_index(fit.slot))], fit.coef);
            });
    }
    if (refit)
    {
        const std::vector<CoarseSamples> coarse =
            coarse_samples(m.surfels.positions, m.surfels.normals, k, fit_grid.cell_size());
        refit_coarser(
            coarse, m.surfels.positions, fit_noise, fit_on_rim, k,
            [&](std::uint32_t i) -> PackedSurfel& { return m.packed[m.grid->slot_of(i)]; });
    }
    m.area = 0.0;
    for (const double area : block_area)
    {
        m.area += area;
    }

    // The stray samples: only those whose reach, as the fit's search measured it, is near the
    // limit or past it are tested (a search of their own each).
    const ScatterTest scatter = scatter_test(m.tree, m.surfels.positions);
    const bool reach_known = !m.slot_reach.empty() && reach_rank == scatter_neighbourhood;
    const std::vector<std::uint32_t> candidates = parallel_collect<std::uint32_t>(
        n, 4096, [&](std::size_t begin, std::size_t end, std::vector<std::uint32_t>& out) {
            for (std::size_t i = begin; i < end; ++i)
            {
                const float r = reach_known
                                    ? m.slot_reach[m.grid->slot_of(static_cast<std::uint32_t>(i))]
                                    : 0.0F;
                if (!reach_known || r * r > 0.999F * scatter.limit2)
                    out.push_back(static_cast<std::uint32_t>(i));
            }
        });
    Strays strays = find_strays(m.tree, m.surfels.positions, scatter, candidates);
    m.strays = std::move(strays.samples);
    // A spray's members blend with nothing; a stray among the samples of a sparse part that are
    // not strays still blends (the part may need it).
    if (!strays.sprayed.empty() && blends(options.fit))
    {
        m.stray_slot.assign(m.grid->slot_count(), 0);
        for (const std::uint32_t i : strays.sprayed)
            m.stray_slot[m.grid->slot_of(i)] = 1;
    }
    float max_radius = 0.0F;
    for (const float r : m.surfels.radii)
    {
        max_radius = std::max(max_radius, r);
    }
    m.max_radius = max_radius;
    m.box = m.surfels.bounds();
    m.box.min -= Vec3d::Constant(max_radius);
    m.box.max += Vec3d::Constant(max_radius);
    m.sample_box = bounding_box(m.surfels.positions);
    m.local_box = m.sample_box;
    m.local_box.min -= Vec3d::Constant(max_radius);
    m.local_box.max += Vec3d::Constant(max_radius);
    m.nearby_reach = 2.0 * std::sqrt(3.0) * static_cast<double>(m.grid->cell_size()) * 1.01;

    std::vector<float> radii = m.surfels.radii;
    auto middle = radii.begin() + static_cast<std::ptrdiff_t>(radii.size() / 2);
    std::nth_element(radii.begin(), middle, radii.end());
    m.median_radius = *middle;
}

PointField::~PointField() = default;

std::size_t PointField::Impl::wanted() const
{
    return blends(options.fit) ? std::min(options.blend_k + 1, surfels.size()) : std::size_t{1};
}

bool PointField::Impl::maybe_nearby(const Vec3d& p, const FarField* far_data) const
{
    // Far from the samples the point grid finds none, and the far grid answers what it can
    // (deep inside). A lower bound on the distance to the samples (from their box and, once it
    // is built, the far grid) tells directly where the point grid would find none, which saves
    // scanning its cells; the answers are the same either way, so they do not depend on when
    // the far grid was built (or on the order of queries).
    double lower = (p - p.cwiseMax(sample_box.min).cwiseMin(sample_box.max)).norm();
    if (far_data != nullptr && !(lower > nearby_reach))
    {
        lower = std::max(lower, far_data->grid.lower_bound(p));
    }
    return !(lower > nearby_reach);
}

FieldSample PointField::Impl::evaluate_with(const Vec3d& p, const Vec3f& query,
                                            const FarField* far_data, bool nearby,
                                            std::size_t found, std::uint32_t* slot, float* dist2,
                                            double hi, NeighbourMemo* memo) const
{
    const Impl& m = *this;
    FieldSample out;
    const std::size_t want = wanted();
    // The far grid's cell at p, looked up once for the far paths below.
    FarCell cell;
    if (found == 0 && m.options.far_grid)
    {
        if (far_data == nullptr)
        {
            far_data = &m.far_field();
        }
        cell = far_data->grid.query(p);
        if (m.evaluate_deep_inside(*far_data, cell, p, out) ||
            m.evaluate_far_outside(*far_data, cell, p, query, hi, out))
        {
            return out;
        }
    }
    else if (found == 0 && far_data != nullptr)
    {
        cell = far_data->grid.query(p);
    }

    if (!blends(m.options.fit))
    {
        if (found == 0)
        {
            std::array<std::uint32_t, 1> index{};
            m.tree.knn(query, 1, index, std::span(dist2, 1));
            slot[0] = m.grid->slot_of(index[0]);
        }
        const PackedSurfel& nearest = m.packed[slot[0]];
        const double distance = (p - nearest.position.cast<double>()).norm();
        const double plane = nearest.distance(p, &out.gradient);
        out.defined = distance <= static_cast<double>(nearest.radius);
        out.value = out.defined ? plane : std::copysign(distance, plane);
        return out;
    }

    // Blend: the blend_k nearest surfaces, weights vanishing at the (blend_k + 1)-th distance.
    if (found == 0)
    {
        // Far from the samples (as a scene evaluates one scan along another's surface): a
        // nearly nearest sample tells whether any influence ball can reach, which mostly ends
        // it. Its distance is within far_distance_factor of the nearest's: deep inside a
        // closed scan the samples are all about equally far, and an exact search visits most.
        // The far grid's representatives around p (once built) give a start whose distance
        // bounds the search from the first node, which skips most of the tree.
        // Near the samples the point grid finds the nearest exactly, in a few of its cells,
        // where it could not find all wanted() neighbours.
        float nearest_d2 = 0.0F;
        std::array<std::uint32_t, 1> nearest_slot{};
        if (!nearby || m.grid->knn_nearby(query, 1, nearest_slot, std::span(&nearest_d2, 1)) == 0)
        {
            nearest_slot[0] = m.grid->slot_of(m.nearly_nearest(cell, query, nearest_d2));
        }
        const PackedSurfel& nearest = m.packed[nearest_slot[0]];
        const double reach = m.max_radius * static_cast<double>(far_distance_factor);
        if (static_cast<double>(nearest_d2) > reach * reach)
        {
            const double nearest_distance = (p - nearest.position.cast<double>()).norm();
            out.defined = false;
            out.value = std::copysign(nearest_distance, nearest.distance(p, nullptr));
            out.gradient = nearest.normal.cast<double>();
            return out;
        }
        // The grid has already turned the query down (found == 0: its cells were scanned for
        // want, or the query lies beyond their reach): straight to the kd-tree.
        const std::size_t ask = memo != nullptr ? m.memo_size() : want;
        found = m.grid->knn_far(query, ask, std::span(slot, ask), std::span(dist2, ask),
                                m.far_bound(nearest_slot[0], nearest_d2, memo, query));
        if (memo != nullptr)
        {
            m.remember_neighbours(*memo, query, found, slot, dist2);
            found = std::min(found, want);
        }
    }
    std::size_t used = found == want && found > 1 ? found - 1 : found;
    // Bandwidth: the distance of the first sample not blended (or a little beyond the last).
    double bandwidth = found > 0 ? std::sqrt(static_cast<double>(dist2[found - 1])) : 0.0;
    if (used == found)
    {
        bandwidth *= 1.5;
    }
    // A spray's members (Strays::sprayed) neither blend nor define the field: it is what the
    // others make of it near them, with the same bandwidth.
    const std::uint32_t nearest_of_all = slot[0];
    if (!m.stray_slot.empty())
    {
        std::size_t kept = 0;
        std::size_t kept_used = 0;
        for (std::size_t j = 0; j < found; ++j)
        {
            if (m.stray_slot[slot[j]] != 0)
                continue;
            kept_used += j < used ? 1 : 0;
            slot[kept] = slot[j];
            dist2[kept] = dist2[j];
            ++kept;
        }
        found = kept;
        used = kept_used;
    }
    const PackedSurfel& nearest = m.packed[found > 0 ? slot[0] : nearest_of_all];
    // Defined inside the union of the blended samples' influence balls, so that a gap next to
    // a sample with a small radius is covered by its neighbours' balls.
    out.defined = false;
    for (std::size_t j = 0; j < found && used > 0 && !out.defined; ++j)
    {
        const PackedSurfel& s = m.packed[slot[j]];
        const auto r = static_cast<double>(s.radius);
        out.defined = static_cast<double>(dist2[j]) <= r * r;
        if (out.defined && !m.rim.empty())
            out.defined = past_limit(s, m.rim[slot[j]], p) <= 0.0;
    }
    if (!out.defined)
    {
        const double nearest_distance = (p - nearest.position.cast<double>()).norm();
        out.value = std::copysign(nearest_distance, nearest.distance(p, nullptr));
        out.gradient = nearest.normal.cast<double>();
        return out;
    }

    if (!(bandwidth > 0.0))
    {
        out.value = nearest.distance(p, &out.gradient);
        return out;
    }
    // One pass: with w_i the weights, d_i the distances to the samples' surfaces and
    // g_i = ∇w_i, f = Σ w_i d_i / Σ w_i and ∇f = (Σ w_i ∇d_i + Σ g_i d_i − f Σ g_i) / Σ w_i.
    const double inv_h = 1.0 / bandwidth;
    BlendSums sums;
    if (m.crease.empty())
    {
        sums = detail::blend_sums(m.packed.data(), slot, dist2, used, p, inv_h);
    }
    else
    {
        // Samples whose crease p lies beyond (crease_limit()) leave the blend to those whose
        // surface holds at p, as far as these carry it: with W_in and W_past the two groups'
        // weights, the samples past their lines count at their distance to their own face
        // bounded by the line (bounded_face_distance()) with weight λ = max(0, 1 − 2 W_in /
        // (W_in + W_past)): not at all where the others carry half the blend, fully where
        // every sample lies past its line (outside a convex corner, inside a concave one).
        // Measured on the 100k clean inputs of bench/peers (Hausdorff and Chamfer in % of the
        // diagonal), against the samples past their lines left out wherever others remain:
        // part 0.71 / 0.00888 -> 0.46 / 0.00886, plate 0.40 / 0.00398 -> 0.40 / 0.00397,
        // blobby 0.34 / 0.00594 -> 0.34 / 0.00592.
        // Each sample's share in the samples that hold: 1 up to its line, falling to 0 over
        // crease_blend_width of the bandwidth past it ((1 - t)², t the fraction of that width
        // it is past), the rest of it among the samples past their lines.
        const double width = crease_blend_width * bandwidth;
        std::array<std::uint32_t, max_blend_k + 1> within_slot{};
        std::array<float, max_blend_k + 1> within_dist2{};
        std::array<std::uint32_t, max_blend_k + 1> past_slot{};
        std::array<float, max_blend_k + 1> past_dist2{};
        std::array<double, max_blend_k + 1> past_by{};
        std::array<double, max_blend_k + 1> share{};
        std::array<std::uint32_t, max_blend_k + 1> union_slot{};
        std::array<float, max_blend_k + 1> union_dist2{};
        // The plane of its other face that each union sample takes (its own, or one it borrows).
        std::array<std::uint32_t, max_blend_k + 1> union_plane{};
        std::size_t within = 0;
        std::size_t past = 0;
        std::size_t unions = 0;
        // A sample's direction toward its crease line, in world axes.
        const auto crease_direction = [&](std::uint32_t sample_slot) {
            const PackedSurfel& sample = m.packed[sample_slot];
            const Eigen::Vector4f& crease = m.crease[sample_slot];
            return Vec3f(crease.x() * sample.tangent +
                         crease.y() * sample.normal.cross(sample.tangent));
        };
        const auto has_plane = [&](std::uint32_t sample_slot) {
            return m.other_plane[sample_slot].head<3>().squaredNorm() > 0.0F;
        };
        for (std::size_t j = 0; j < used; ++j)
        {
            // A concave crease's sample for which no plane of the other face was found borrows
            // the plane of the nearest blended sample of the same face (normals within 30°)
            // at the same crease (directions toward it within 30°). Beside a concave crease the
            // bandwidth may leave one sample to carry the blend (a Wendland weight of 0.133
            // against at most 0.012 for the others, on the 100k clean blobby at seed 31), and
            // with its own face's distance alone it said "outside" inside the other ball: a
            // pocket 0.006 thick in the solid, one vertex of the mesh on it, Hausdorff 0.312% of
            // the diagonal against marching cubes' 0.277 at the same vertex count. Measured
            // (bench/peers, clean, 100k, Hausdorff / Chamfer in % of the diagonal, seeds 1 and
            // 31): blobby 0.254 / 0.0032 -> 0.255 / 0.0032 and 0.312 / 0.0034 -> 0.233 /
            // 0.0034; part 0.557 / 0.0059 -> 0.557 / 0.0058 and 0.586 / 0.0060 -> 0.499 /
            // 0.0060; cone 0.511 / 0.0037 -> 0.574 / 0.0036 (a point of the rim's truth 0.06%
            // farther; the mesh's points over 0.25% off 353 -> 155) and 0.568 / 0.0038 -> 0.535
            // / 0.0039; the plate and two spheres unchanged; the bunny 3.514 / 0.0478 -> 3.507 /
            // 0.0475. Borrowing from any sample of the same face gave the part at seed 1 0.457,
            // but the cone at seed 31 0.615. Noisy clouds find no planes of other faces.
            std::uint32_t plane_of = slot[j];
            if (!has_plane(slot[j]) && m.crease[slot[j]].w() < 0.0F)
            {
                const Vec3f& normal = m.packed[slot[j]].normal;
                const Vec3f toward = crease_direction(slot[j]);
                for (std::size_t u = 0; u < used; ++u)
                    if (has_plane(slot[u]) &&
                        m.packed[slot[u]].normal.dot(normal) >= crease_turn_cosine &&
                        crease_direction(slot[u]).dot(toward) >= crease_turn_cosine)
                    {
                        plane_of = slot[u];
                        break;
                    }
            }
            if (has_plane(plane_of))
            {
                // A concave crease's sample with its other face's plane: the union of the two
                // half-spaces holds on both sides of the line.
                union_slot[unions] = slot[j];
                union_dist2[unions] = dist2[j];
                union_plane[unions] = plane_of;
                ++unions;
                continue;
            }
            const double beyond = past_limit(m.packed[slot[j]], m.crease[slot[j]].head<3>(), p);
            if (!(beyond > 0.0))
            {
                within_slot[within] = slot[j];
                within_dist2[within] = dist2[j];
                ++within;
            }
            else
            {
                past_slot[past] = slot[j];
                past_dist2[past] = dist2[j];
                past_by[past] = beyond;
                const double t = width > 0.0 ? std::min(1.0, beyond / width) : 1.0;
                share[past] = (1.0 - t) * (1.0 - t);
                ++past;
            }
        }
        sums = detail::blend_sums(m.packed.data(), within_slot.data(), within_dist2.data(), within,
                                  p, inv_h);
        if (unions > 0)
        {
            add(sums,
                detail::blend_sums_of(
                    m.packed.data(), union_slot.data(), union_dist2.data(), unions, p, inv_h,
                    [&](std::size_t j, Vec3d* gradient, double* /*factor*/) {
                        const PackedSurfel& sample = m.packed[union_slot[j]];
                        const Eigen::Vector4f& plane = m.other_plane[union_plane[j]];
                        const double own = sample.distance(p, gradient);
                        const Vec3d outward = plane.head<3>().cast<double>();
                        const double other =
                            outward.dot(p - m.packed[union_plane[j]].position.cast<double>()) -
                            static_cast<double>(plane.w());
                        if (other < own)
                        {
                            *gradient = outward;
                            return other;
                        }
                        return own;
                    }),
                1.0);
        }
        if (past > 0)
        {
            const BlendSums holding =
                detail::blend_sums_of(m.packed.data(), past_slot.data(), past_dist2.data(), past, p,
                                      inv_h, [&](std::size_t j, Vec3d* gradient, double* factor) {
                                          *factor = share[j];
                                          return m.packed[past_slot[j]].distance(p, gradient);
                                      });
            const BlendSums beyond = detail::blend_sums_of(
                m.packed.data(), past_slot.data(), past_dist2.data(), past, p, inv_h,
                [&](std::size_t j, Vec3d* gradient, double* factor) {
                    *factor = 1.0 - share[j];
                    return bounded_face_distance(m.packed[past_slot[j]], m.crease[past_slot[j]],
                                                 past_by[j], p, gradient);
                });
            add(sums, holding, 1.0);
            const double total = sums.weight + beyond.weight;
            const double lambda =
                total > 0.0 ? std::clamp(1.0 - 2.0 * sums.weight / total, 0.0, 1.0) : 1.0;
            add(sums, beyond, lambda);
        }
    }
    const double weight_sum = sums.weight;
    if (!(weight_sum > 1e-12))
    {
        out.value = nearest.distance(p, &out.gradient);
        return out;
    }
    out.value = sums.value / weight_sum;
    out.gradient = (sums.normal + sums.weighted_gradient - out.value * sums.gradient) / weight_sum;
    return out;
}

FieldSample PointField::evaluate(const Vec3d& world_point) const
{
    return evaluate_within(world_point, -std::numeric_limits<double>::infinity(),
                           std::numeric_limits<double>::infinity());
}

std::size_t PointField::Impl::memo_size() const
{
    return std::min(wanted() + memo_extra, surfels.size());
}

void PointField::Impl::remember_neighbours(NeighbourMemo& memo, const Vec3f& query,
                                           std::size_t found, const std::uint32_t* slot,
                                           const float* dist2) const
{
    const std::size_t size = memo_size();
    if (found != size || size <= wanted())
    {
        memo.field = 0;
        return;
    }
    memo.field = id;
    memo.centre = query;
    memo.bound2 = dist2[size - 1];
    memo.gap = std::sqrt(dist2[size - 1]) - std::sqrt(dist2[wanted() - 1]);
    std::copy(slot, slot + size, memo.slot.begin());
}

bool PointField::Impl::recall_neighbours(const NeighbourMemo& memo, const Vec3f& query,
                                         std::uint32_t* slot, float* dist2) const
{
    // Only remember_neighbours() sets `field`, with memo_size() candidates, more than wanted().
    if (memo.field != id)
        return false;
    const Vec3f offset = query - memo.centre;
    if (!(offset.squaredNorm() < memo.gap * memo.gap))
        return false;
    const std::size_t want = wanted();
    const std::size_t count = memo_size();
    std::array<float, memo_capacity> d2{};
    grid->squared_distances(query, std::span(memo.slot.data(), count), std::span(d2.data(), count));
    // The candidates in the order (distance, slot) that the point grid keeps (its keys: a
    // non-negative float's bits order as the float does).
    std::array<std::uint64_t, memo_capacity> key{};
    for (std::size_t i = 0; i < count; ++i)
        key[i] = (std::uint64_t{std::bit_cast<std::uint32_t>(d2[i])} << 32U) | memo.slot[i];
    std::sort(key.begin(), key.begin() + static_cast<std::ptrdiff_t>(count));
    const auto distance2 = [&key](std::size_t i) {
        return std::bit_cast<float>(static_cast<std::uint32_t>(key[i] >> 32U));
    };
    // No ties among the first want + 1: their order is the distances' alone.
    for (std::size_t i = 0; i < want; ++i)
        if (!(distance2(i) < distance2(i + 1)))
            return false;
    // Any sample not in the memo is at least sqrt(bound2) from the centre, so at least
    // sqrt(bound2) - |query - centre| from the query: it cannot come before the want-th
    // candidate while that is nearer still. The relative slack covers the float rounding of
    // the distances (a few units in the last place).
    constexpr double slack = 1e-5;
    const double moved = offset.cast<double>().norm();
    const double last = std::sqrt(static_cast<double>(distance2(want - 1)));
    const double bound = std::sqrt(static_cast<double>(memo.bound2));
    if (!((last + moved) * (1.0 + slack) < bound * (1.0 - slack)))
        return false;
    // Near a sample (its distance well inside the largest radius): none of the far paths of
    // evaluate_with(), which a search's answer would take only beyond every radius.
    const double nearest = std::sqrt(static_cast<double>(distance2(0)));
    if (!(nearest < 0.99 * max_radius))
        return false;
    for (std::size_t i = 0; i < want; ++i)
    {
        slot[i] = static_cast<std::uint32_t>(key[i]);
        dist2[i] = distance2(i);
    }
    return true;
}

float PointField::Impl::memo_bound(const NeighbourMemo& memo, const Vec3f& query) const
{
    if (memo.field != id)
        return std::numeric_limits<float>::infinity();
    const std::size_t count = memo_size();
    std::array<float, memo_capacity> d2{};
    grid->squared_distances(query, std::span(memo.slot.data(), count), std::span(d2.data(), count));
    // Measured as the kd-tree measures (the same float sums), so its slack covers the rest.
    return *std::max_element(d2.begin(), d2.begin() + static_cast<std::ptrdiff_t>(count));
}

float PointField::Impl::far_bound(std::uint32_t slot, float d2, const NeighbourMemo* memo,
                                  const Vec3f& query) const
{
    float bound2 =
        memo != nullptr ? memo_bound(*memo, query) : std::numeric_limits<float>::infinity();
    if (!slot_reach.empty())
    {
        // In double, widened by far more than the rounding of either term: the kd-tree's own
        // slack covers the float sums of the distances it compares against it.
        const double by_sample =
            (std::sqrt(static_cast<double>(d2)) + static_cast<double>(slot_reach[slot])) *
            (1.0 + 1e-6);
        bound2 = std::min(bound2, static_cast<float>(by_sample * by_sample));
    }
    return bound2;
}

FieldSample PointField::evaluate_within(const Vec3d& world_point, double /*lo*/, double hi) const
{
    const Impl& m = *impl_;
    const Vec3d p = world_point - m.surfels.origin;
    const Vec3f query = p.cast<float>();
    std::array<std::uint32_t, memo_capacity> slot{};
    std::array<float, memo_capacity> dist2{};
    const std::size_t want = m.wanted();
    const FarField* far = m.far_built.load(std::memory_order_acquire);
    // The wanted() nearest samples from this thread's last search of the kd-tree where they are
    // provably the same (recall_neighbours()); otherwise searched, and a search that the point
    // grid turns down keeps memo_extra more for the next. Either way the same neighbours, in the
    // same order, with the same distances: the value does not depend on which evaluations came
    // before on the thread. Only the kd-tree's searches are kept: they are the costly ones (far
    // from the samples, where they are sparse, as over a hole), and the grid's, near the
    // samples, cost about what taking candidates back does. (A field without blending never
    // searches the kd-tree for more than the nearest, so it keeps nothing and takes nothing.)
    thread_local NeighbourMemo memo;
    if (m.recall_neighbours(memo, query, slot.data(), dist2.data()))
        return m.evaluate_with(p, query, far, true, want, slot.data(), dist2.data(), hi);
    std::size_t found = 0;
    const bool nearby = m.maybe_nearby(p, far);
    if (nearby)
        found = m.grid->knn_nearby(query, want, std::span(slot.data(), want),
                                   std::span(dist2.data(), want));
    return m.evaluate_with(p, query, far, nearby, found, slot.data(), dist2.data(), hi, &memo);
}

double PointField::cost() const
{
    return point_field_cost;
}

void PointField::evaluate(std::span<const Vec3d> points, std::span<FieldSample> out) const
{
    check_same_size("PointField::evaluate", "out", out.size(), points.size());
    evaluate_batch(points, {}, out);
}

void PointField::evaluate_within(std::span<const Vec3d> points, std::span<const double> lo,
                                 std::span<const double> hi, std::span<FieldSample> out) const
{
    check_within_sizes("PointField::evaluate_within", points.size(), lo.size(), hi.size(),
                       out.size());
    evaluate_batch(points, hi, out);
}

void PointField::evaluate_batch(std::span<const Vec3d> points, std::span<const double> hi,
                                std::span<FieldSample> out) const
{
    PF_ASSERT(points.size() == out.size());
    constexpr double inf = std::numeric_limits<double>::infinity();
    const Impl& m = *impl_;
    const std::size_t want = m.wanted();
    // Blocks of consecutive queries, fixed whatever the thread count; the point grid answers
    // each block's queries near the samples together (faster on coherent queries, the same
    // neighbours as one by one), then each is finished as evaluate() finishes it.
    parallel_blocks(points.size(), 1024, [&](std::size_t begin, std::size_t end) {
        const std::size_t n = end - begin;
        const FarField* far = m.far_built.load(std::memory_order_acquire);
        std::vector<Vec3d> local(n);
        std::vector<Vec3f> nearby;
        std::vector<std::uint32_t> which; // the block's queries that the grid is asked
        nearby.reserve(n);
        which.reserve(n);
        for (std::size_t i = 0; i < n; ++i)
        {
            local[i] = points[begin + i] - m.surfels.origin;
            if (m.maybe_nearby(local[i], far))
            {
                nearby.push_back(local[i].cast<float>());
                which.push_back(static_cast<std::uint32_t>(i));
            }
        }
        std::vector<std::uint32_t> slots(nearby.size() * want);
        std::vector<float> dist2(nearby.size() * want);
        std::vector<std::uint32_t> found(nearby.size());
        m.grid->knn_nearby(nearby, want, slots, dist2, found);
        std::array<std::uint32_t, max_blend_k + 1> none_slot{};
        std::array<float, max_blend_k + 1> none_dist2{};
        std::size_t next = 0;
        for (std::size_t i = 0; i < n; ++i)
        {
            const Vec3f query = local[i].cast<float>();
            if (next < which.size() && which[next] == i)
            {
#if defined(__GNUC__) || defined(__clang__)
                // The samples two queries ahead, while this one is blended.
                if (next + 2 < which.size())
                {
                    const std::uint32_t* ahead = slots.data() + (next + 2) * want;
                    for (std::size_t j = 0; j < found[next + 2]; ++j)
                    {
                        __builtin_prefetch(&m.packed[ahead[j]]);
                    }
                }
#endif
                out[begin + i] = m.evaluate_with(
                    local[i], query, far, true, found[next], slots.data() + next * want,
                    dist2.data() + next * want, hi.empty() ? inf : hi[begin + i]);
                ++next;
            }
            else
            {
                out[begin + i] =
                    m.evaluate_with(local[i], query, far, false, 0, none_slot.data(),
                                    none_dist2.data(), hi.empty() ? inf : hi[begin + i]);
            }
        }
    });
}

Aabb PointField::bounds() const
{
    return impl_->box;
}

void PointField::append_seeds(std::vector<Vec3d>& seeds) const
{
    const PointCloud& s = impl_->surfels;
    const std::vector<std::uint32_t>& strays = impl_->strays;
    seeds.reserve(seeds.size() + s.size() - strays.size());
    auto next = strays.begin();
    for (std::size_t i = 0; i < s.size(); ++i)
    {
        if (next != strays.end() && *next == i)
        {
            ++next;
            continue;
        }
        seeds.push_back(s.world(i));
    }
}

std::span<const std::uint32_t> PointField::stray_samples() const
{
    return impl_->strays;
}

const PointCloud& PointField::surfels() const
{
    return impl_->surfels;
}

const KdTree& PointField::tree() const
{
    return impl_->tree;
}

const PointFieldOptions& PointField::options() const
{
    return impl_->options;
}

double PointField::median_radius() const
{
    return impl_->median_radius;
}

std::optional<std::array<std::int32_t, 3>> NoiseScaleRegion::cell_of(const Vec3d& p) const
{
    if (!(size > 0.0))
        return std::nullopt;
    std::array<std::int32_t, 3> cell{};
    for (int a = 0; a < 3; ++a)
    {
        const double c = std::floor(p[a] / size);
        if (!(std::abs(c) < 2e9))
            return std::nullopt;
        cell[a] = static_cast<std::int32_t>(c);
    }
    return cell;
}

bool NoiseScaleRegion::contains(const Vec3d& p) const
{
    if (cells.empty())
        return false;
    const auto cell = cell_of(p);
    return cell && std::binary_search(cells.begin(), cells.end(), *cell);
}

bool PointField::noisy() const
{
    return impl_->noisy;
}

double PointField::estimated_area() const
{
    return impl_->area;
}

} // namespace pointform
