// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/hermite/orientation.h"

#include "pointform/core/disjoint_sets.h"
#include "pointform/core/error.h"
#include "pointform/core/memory.h"
#include "pointform/core/parallel.h"

#include "orientation_detail.h"
#include "orientation_lanes.h"
#include "two_sheets.h"

#include <Eigen/Core>

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cmath>
#include <limits>
#include <memory>
#include <numbers>
#include <numeric>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>

namespace pointform {
namespace {

using detail::add_moment;
using detail::Guide;
using detail::Moments;
using detail::ring_sums;
using detail::winding_group_sum;
using detail::winding_lanes;
using detail::WindingSources;

/// The flux test overrides the seed's +z only when |flux| exceeds this fraction of
/// Σ a_i |p_i − c|. A closed convex surface scores 1, closed non-convex shapes (bunny, torus)
/// well above 0.3, while open sheets such as terrain or a flat scan score near 0 and keep the
/// seed's upward orientation.
constexpr double flux_decision_threshold = 0.1;
/// A sample's area in the flux (its squared k-th neighbour distance) is at most this many times
/// the median area: a stray far from the surface has an area hundreds of times a surface
/// sample's and a normal that says nothing, and a few hundred of them outweighed the surface (a
/// torus with 1% strays through its box came out inside out, the strays' flux 200 times the
/// surface's). Uneven sampling within this ratio keeps its areas.
constexpr double flux_area_cap = 8.0;
/// The median area is taken over every flux_area_stride-th sample.
constexpr std::size_t flux_area_stride = 64;

/// Columns of the neighbour table that make the Riemannian graph (OrientationOptions::k).
std::size_t graph_columns(const OrientationOptions& options, const KnnTable& neighbors)
{
    return options.k == 0 ? neighbors.k : std::min(options.k, neighbors.k);
}

/// Whether `value` is among the first `columns` entries of the table's row: a scan without an
/// early exit, which the compiler vectorises (the graph rows are short).
bool row_contains(const KnnTable& table, std::size_t row, std::size_t columns, std::uint32_t value)
{
    const std::uint32_t* nbrs = table.indices.data() + row * table.k;
    std::uint32_t hits = 0;
    for (std::size_t c = 0; c < columns; ++c)
        hits += nbrs[c] == value ? 1U : 0U;
    return hits != 0;
}

using detail::usable;

/// The signed agreement of normal nb at pb with the orientation rule predicts from na at pa
/// (agreement() takes them from one array).
/// Inlined: the patch pass of orient_by_patches() calls it on every edge of a clean cloud.
[[gnu::always_inline]] inline float agreement_of(const Vec3f& pa, const Vec3f& na, const Vec3f& pb,
                                                 const Vec3f& nb, OrientationRule rule)
{
    const float hoppe = na.dot(nb);
    if (rule == OrientationRule::Hoppe)
        return hoppe;
    const Vec3f e = pb - pa;
    const float len2 = e.squaredNorm();
    if (len2 == 0.0F)
        return hoppe;
    const Vec3f predicted = na - (2.0F * na.dot(e) / len2) * e;
    return nb.dot(predicted);
}

/// Signed agreement of n_b with the orientation that rule predicts from n_a: its sign says whether
/// b agrees with a, its magnitude how certain that is.
float agreement(std::span<const Vec3f> positions, std::span<const Vec3f> normals,
                OrientationRule rule, std::uint32_t a, std::uint32_t b)
{
    return agreement_of(positions[a], normals[a], positions[b], normals[b], rule);
}

float edge_cost(std::span<const Vec3f> positions, std::span<const Vec3f> normals,
                OrientationRule rule, std::uint32_t a, std::uint32_t b)
{
    if (!usable(normals[a]) || !usable(normals[b]))
        return 2.0F; // worst: reach samples without a normal last
    // Clamped: |n_a·n_b| may round above 1, and a negative cost would sort last as raw bits.
    return std::max(0.0F, 1.0F - std::abs(agreement(positions, normals, rule, a, b)));
}

/// Median flatness (see flatness()) of the samples' own neighbourhoods above which a cloud counts
/// as noisy and is oriented by guide normals. A disc of radius ρ with position noise σ scores about
/// 6 σ² / ρ², so 0.02 is noise of about ρ / 17, where PCA normals are still within a few degrees.
/// Curvature alone scores about (ρ / R)² / 4 for curvature radius R: 4e-4 to 3e-3 on the test
/// shapes, 0.007 to 0.01 on the bunny scans; the noisy benchmark clouds score 0.1 to 0.9. A clean
/// plate thinner than the guide's reach scores 0, so it is never guided across its walls.
constexpr float noisy_flatness = 0.02F;

/// The noise test (guide_normals()) takes every noise_test_stride-th sample of clouds of at least
/// noise_test_sampled samples (so at least 8,192 of them; a million give 125,000), and of larger
/// clouds a stride that tests about noise_test_most: its median then moves far less than the
/// margin between clean and noisy clouds, at an eighth of the cost or less (the test was a tenth
/// of the orientation of a clean cloud; at a stride of 8 still 0.13 s of 1.2 at 10M samples).
constexpr std::size_t noise_test_stride = 8;
constexpr std::size_t noise_test_sampled = 65536;
constexpr std::size_t noise_test_most = std::size_t{1} << 17U;

/// The stride of the noise test's samples in a cloud of n.
std::size_t noise_test_stride_for(std::size_t n)
{
    return n >= noise_test_sampled ? std::max(noise_test_stride, n / noise_test_most) : 1;
}

/// The guide's neighbourhoods grow past OrientationOptions::guide_rings while the median flatness
/// of the last ring's neighbourhoods (over the noise test's samples) is above this: about noise of
/// a seventh of the grown neighbourhood's radius (see noisy_flatness). Each ring adds about one
/// step of the neighbour table to the radius in quadrature (a ring is a walk of one step), so the
/// flatness of noise falls as about 1 / rings: the bench's noisy clouds at 100k samples (noise of
/// 0.6 sampling steps) score 0.06-0.08 at ring 4 and keep 4 rings, while at 1M (2 steps) they
/// score 0.21-0.23 there and need 12-14. A crease band (crease_band()) forms only once the faces
/// are flatter than a crease: the base of a 1M-sample noisy cone stayed inside out up to 8 rings
/// (median 0.167) and was right from 9 (0.156); with 4 rings, 41% of its normals were wrong.
constexpr float guide_target_flatness = 0.12F;

/// A point lies off a sample's sheet when its height along the sample's guide is more than this
/// many robust standard deviations of the noise from the median height of the sample's
/// neighbours (mark_sheets()): under Gaussian noise 3 keeps 99.7% of a sheet's own samples,
/// while a sample of the opposite face of a thin plate, which noise can bring into a
/// neighbourhood, lies about the gap away. Faces less than about 8 deviations apart share outliers
/// that no test of positions can tell apart.
constexpr float off_sheet_deviations = 3.0F;

/// The smallest robust deviation of the heights in a row, relative to the distance to the
/// farthest neighbour: on a clean, flat part of a noisy cloud the deviations are about zero, and
/// rounding would decide.
constexpr float min_height_limit = 0.05F;

/// A covariance as a matrix, divided by its trace (so that its adjugate and determinant stay in
/// float range whatever the units); zero when the trace is not positive.
Eigen::Matrix3f normalized_matrix(const std::array<float, 6>& c)
{
    const float trace = c[0] + c[3] + c[5];
    Eigen::Matrix3f m;
    m << c[0], c[1], c[2], c[1], c[3], c[4], c[2], c[4], c[5];
    return trace > 0.0F ? Eigen::Matrix3f(m / trace) : Eigen::Matrix3f::Zero();
}

/// Adjugate of a symmetric matrix (its eigenvalues: λ1λ2, λ0λ2, λ0λ1).
Eigen::Matrix3f adjugate(const Eigen::Matrix3f& m)
{
    const float a = m(1, 1) * m(2, 2) - m(1, 2) * m(1, 2);
    const float b = m(0, 2) * m(1, 2) - m(0, 1) * m(2, 2);
    const float c = m(0, 1) * m(1, 2) - m(0, 2) * m(1, 1);
    const float d = m(0, 0) * m(2, 2) - m(0, 2) * m(0, 2);
    const float e = m(0, 1) * m(0, 2) - m(0, 0) * m(1, 2);
    const float f = m(0, 0) * m(1, 1) - m(0, 1) * m(0, 1);
    Eigen::Matrix3f adj;
    adj << a, b, c, b, d, e, c, e, f;
    return adj;
}

/// How far points are from a plane, from the invariants of their covariance C (eigenvalues
/// λ0 ≤ λ1 ≤ λ2): 3 det C / (I2 tr C), I2 = tr adj C the sum of C's principal 2×2 minors, that
/// is 3 / ((1/λ0 + 1/λ1 + 1/λ2)(λ0 + λ1 + λ2)): 0 on a plane, 1 for an isotropic blob, about
/// 3 λ0 / (λ1 + λ2) (Pauly's surface variation, times 3) when thin; no eigen-solve needed.
/// From the covariance's normalized_matrix() `m` (tr = 1) and its adjugate.
float flatness(const Eigen::Matrix3f& m, const Eigen::Matrix3f& adj)
{
    const float minors = adj.trace();
    const float det = m.row(0).dot(adj.col(0));
    if (!(minors > 0.0F))
        return 2.0F; // no plane: worse than any
    return std::max(0.0F, 3.0F * det / minors);
}

float flatness(const std::array<float, 6>& covariance)
{
    const Eigen::Matrix3f m = normalized_matrix(covariance);
    return flatness(m, adjugate(m));
}

/// The eigenvector of the least eigenvalue of a covariance (unit; arbitrary sign; zero if there
/// is none): the dominant eigenvector of its adjugate, started from the adjugate's longest column
/// (exact when λ0 = 0) and refined by power iteration, each step shrinking the error by λ0 / λ1.
/// Cheaper than an eigen-solve, and the guide needs only a direction. From the adjugate of the
/// covariance's normalized_matrix().
Vec3f least_axis(const Eigen::Matrix3f& adj)
{
    Eigen::Index longest = 0;
    adj.colwise().squaredNorm().maxCoeff(&longest);
    // Two steps, scaled once: adj's eigenvalues lie in [0, 1/4] (m's in [0, 1]), and the start
    // divided by its largest entry keeps the steps far from float's range limits. The guide
    // takes an axis at every ring that a sample's neighbourhood gets flatter, so this is a hot
    // path: one square root and two divisions instead of three and three.
    Vec3f v = adj.col(longest);
    const float scale = v.cwiseAbs().maxCoeff();
    if (!(scale > 0.0F) || !std::isfinite(scale))
        return Vec3f::Zero();
    v = adj * (adj * (v / scale));
    const float length = v.norm();
    if (!(length > 0.0F) || !std::isfinite(length))
        return Vec3f::Zero();
    return v / length;
}

/// The value at position count / 2 of `values` in ascending order, as std::nth_element leaves it
/// there (which it may do to `values`). Short rows, as neighbour rows are, take each value's rank
/// counted without branches, several times faster than nth_element's partitioning on 17 values.
float middle_value(std::span<float> values)
{
    constexpr std::size_t short_row = 32;
    const std::size_t count = values.size();
    const std::size_t middle = count / 2;
    if (count <= short_row)
        for (std::size_t i = 0; i < count; ++i)
        {
            // 32-bit counts: the compare masks add up in vector lanes without widening.
            const float v = values[i];
            std::uint32_t less = 0;
            std::uint32_t not_greater = 0;
            for (std::size_t j = 0; j < count; ++j)
            {
                less += values[j] < v ? 1U : 0U;
                not_greater += values[j] <= v ? 1U : 0U;
            }
            if (less <= middle && middle < not_greater)
                return v;
        }
    // Long rows, and rows with a NaN (no value has a consistent rank).
    const auto at = values.begin() + static_cast<std::ptrdiff_t>(middle);
    std::nth_element(values.begin(), at, values.end());
    return *at;
}

/// The band of each sample's sheet along its guide normal, which its neighbours must lie in (far
/// steadier than its own normal under noise): centred on the median height of its neighbours,
/// off_sheet_deviations robust deviations wide each way. The deviation is the median, over the
/// sample's neighbours, of each one's own robust deviation (1.4826 times the median absolute
/// deviation of the heights in its row): where noise brings the opposite face of a thin plate into
/// a row, that row's own deviation is inflated by the other face, its neighbours' mostly are not.
/// Samples without a guide get an unbounded band.
void mark_sheets(std::span<const Vec3f> positions, const KnnTable& neighbors, Guide& guide)
{
    const std::size_t n = positions.size();
    guide.centre.assign(n, 0.0F);
    guide.reach.assign(n, std::numeric_limits<float>::infinity());
    std::vector<float> deviation(n, 0.0F);
    parallel_blocks(n, 4096, [&](std::size_t begin, std::size_t end) {
        std::vector<float> height(neighbors.k);
        std::vector<float> scratch(neighbors.k);
        const auto median = [&](std::size_t count) {
            return middle_value(std::span<float>(scratch).first(count));
        };
        for (std::size_t i = begin; i < end; ++i)
        {
            const Vec3f& axis = guide.normals[i];
            if (!usable(axis))
                continue;
            const auto row = neighbors.neighbors(i);
            const std::size_t count = row.size();
            float extent2 = 0.0F;
            for (std::size_t c = 0; c < count; ++c)
            {
                const Vec3f d = positions[row[c]] - positions[i];
                height[c] = d.dot(axis);
                scratch[c] = height[c];
                extent2 = std::max(extent2, d.squaredNorm());
            }
            const float middle = median(count);
            for (std::size_t c = 0; c < count; ++c)
                scratch[c] = std::abs(height[c] - middle);
            guide.centre[i] = middle;
            deviation[i] = std::max(1.4826F * median(count), min_height_limit * std::sqrt(extent2));
        }
    });
    parallel_blocks(n, 4096, [&](std::size_t begin, std::size_t end) {
        std::vector<float> scratch(neighbors.k);
        for (std::size_t i = begin; i < end; ++i)
        {
            if (!usable(guide.normals[i]))
                continue;
            const auto row = neighbors.neighbors(i);
            for (std::size_t c = 0; c < row.size(); ++c)
                scratch[c] = deviation[row[c]];
            guide.reach[i] =
                off_sheet_deviations * middle_value(std::span<float>(scratch).first(row.size()));
        }
    });
}

/// The median of flatness() over every stride-th neighbourhood of `moments` (stride as the noise
/// test's), the same for any thread count.
float median_flatness(std::span<const Moments> moments)
{
    const std::size_t n = moments.size();
    const std::size_t stride = noise_test_stride_for(n);
    std::vector<float> values((n + stride - 1) / stride);
    parallel_blocks(values.size(), 4096, [&](std::size_t begin, std::size_t end) {
        for (std::size_t t = begin; t < end; ++t)
            values[t] = flatness(moments[t * stride].covariance);
    });
    return values.empty() ? 0.0F : middle_value(values);
}

/// The ring pass asks for the moments of the neighbours of the sample this many ahead: the
/// loads of a row's moments were a third of the pass (1M noisy blobby's orientation 1.56 ->
/// 1.49 s, median of five; 8 ahead was no faster).
constexpr std::size_t ring_prefetch = 4;

/// The normals that orientation follows: for each sample, the PCA normal of its neighbourhood
/// grown ring by ring through the neighbour table (at least `rings` rings, and more, up to
/// `most_rings`, while the median flatness is above guide_target_flatness) at the scale where the
/// points are flattest (least flatness()). Noise makes a small neighbourhood thick, and growing it
/// averages the noise out, whereas curvature and nearby sheets make a larger one thicker: so the
/// scale follows the noise where there is noise and stays at the normal's own neighbourhood on
/// clean, curved or thin-walled parts. The moments of the union (with multiplicity) of the
/// neighbourhoods of i's neighbours follow from theirs: mean of the centroids, and mean
/// covariance plus the covariance of the centroids; so each ring costs one pass over the table.
/// Empty when the cloud is clean (noisy_flatness). The normals go into `scratch` when it has a
/// slot for every sample. Needs no fine normals: finish_guide() brings them in.
Guide guide_normals(std::span<const Vec3f> positions, const KnnTable& neighbors, std::size_t rings,
                    std::size_t most_rings, std::span<Vec3f> scratch)
{
    const std::size_t n = positions.size();
    // Sums of d and d dᵀ about `shift`, turned into a centroid and covariance.
    const auto finish = [](const std::array<float, 3>& shift, std::array<float, 3> sum,
                           std::array<float, 6> outer, float count) {
        const float inv = 1.0F / count;
        for (auto& s : sum)
            s *= inv;
        for (auto& o : outer)
            o *= inv;
        return Moments{
            {shift[0] + sum[0], shift[1] + sum[1], shift[2] + sum[2]},
            {outer[0] - sum[0] * sum[0], outer[1] - sum[0] * sum[1], outer[2] - sum[0] * sum[2],
             outer[3] - sum[1] * sum[1], outer[4] - sum[1] * sum[2], outer[5] - sum[2] * sum[2]}};
    };
    // The moments of sample i's own neighbourhood.
    const auto own_moments = [&](std::size_t i) {
        const Vec3f& p = positions[i];
        std::array<float, 3> sum{};
        std::array<float, 6> outer{};
        const auto row = neighbors.neighbors(i);
        for (const std::uint32_t j : row)
        {
            const Vec3f d = positions[j] - p;
            add_moment(sum, outer, d.x(), d.y(), d.z());
        }
        return finish({p.x(), p.y(), p.z()}, sum, outer, static_cast<float>(row.size()));
    };
    // Clean enough when the median flatness (the value at half the count in order) is below
    // noisy_flatness, that is when more than half the samples are flatter: counted, not sorted,
    // and nothing kept for a clean cloud, whose samples' own normals are the best guide. Counted
    // on every stride-th sample (in Morton order, an even spread over the surface).
    {
        const std::size_t stride = noise_test_stride_for(n);
        const std::size_t tested = (n + stride - 1) / stride;
        constexpr std::size_t block = 4096;
        std::vector<std::size_t> flatter((tested + block - 1) / block, 0);
        parallel_blocks(tested, block, [&](std::size_t begin, std::size_t end) {
            std::size_t count = 0;
            for (std::size_t t = begin; t < end; ++t)
                count += flatness(own_moments(t * stride).covariance) < noisy_flatness ? 1U : 0U;
            flatter[begin / block] = count;
        });
        if (std::accumulate(flatter.begin(), flatter.end(), std::size_t{0}) > tested / 2)
            return {};
    }
    // The flattest scale's flatness and least axis so far (the axis taken from the moments, not
    // their covariance kept: half the memory). The axis is taken once the next ring is no
    // flatter, from the moments still at hand (or after the last ring): a sign bit on the
    // flatness marks it owed. Most noisy samples get flatter ring after ring, and the axis was
    // most of a ring's arithmetic when it was taken at each.
    FilledLaterVector<Moments> current(n); // filled below, each page by the thread that fills it
    Guide result;
    if (scratch.size() >= n)
        result.normals = scratch.first(n);
    else
    {
        result.storage.resize(n);
        result.normals = result.storage;
    }
    const std::span<Vec3f> best_axis = result.normals;
    std::vector<float> best_flatness(n);
    const auto settle = [&](std::size_t i, const Moments& flattest) {
        best_axis[i] = least_axis(adjugate(normalized_matrix(flattest.covariance)));
        best_flatness[i] = -best_flatness[i];
    };
    // `latest` is sample i's newest ring, `before` the ring before it (none at the start).
    const auto take_if_flatter = [&](std::size_t i, const Moments& latest, const Moments* before) {
        const Eigen::Matrix3f m = normalized_matrix(latest.covariance);
        const float f = flatness(m, adjugate(m));
        float& best = best_flatness[i];
        const bool owed = std::signbit(best);
        if (f < std::abs(best))
            best = -f;
        else if (owed && before != nullptr)
            settle(i, *before);
    };
    parallel_blocks(n, 4096, [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i)
        {
            current[i] = own_moments(i);
            best_flatness[i] = std::numeric_limits<float>::infinity();
            take_if_flatter(i, current[i], nullptr);
        }
    });
    most_rings = std::max(rings, most_rings);
    FilledLaterVector<Moments> next(most_rings > 0 ? n : 0);
    for (std::size_t ring = 0; ring < most_rings; ++ring)
    {
        parallel_blocks(n, 4096, [&](std::size_t begin, std::size_t end) {
            for (std::size_t i = begin; i < end; ++i)
            {
                const auto& c = current[i].centroid;
                std::array<float, 3> sum{};
                std::array<float, 6> outer{};
                const auto row = neighbors.neighbors(i);
#if defined(__GNUC__) || defined(__clang__)
                if (i + ring_prefetch < end)
                    for (const std::uint32_t j : neighbors.neighbors(i + ring_prefetch))
                        __builtin_prefetch(&current[j]);
#endif
                ring_sums(current.data(), row, c, sum, outer);
                next[i] = finish(c, sum, outer, static_cast<float>(row.size()));
                take_if_flatter(i, next[i], &current[i]);
            }
        });
        current.swap(next);
        if (ring + 1 >= rings && median_flatness(current) <= guide_target_flatness)
            break;
    }
    parallel_blocks(n, 4096, [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i)
            if (std::signbit(best_flatness[i]))
                settle(i, current[i]);
    });
    // Each sample's offset over its widest neighbourhood, which reaches across the gap of a
    // thin part where its flattest one may keep to one face (two_sheet_sides()).
    result.offset.resize(n);
    parallel_blocks(n, 4096, [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i)
        {
            const Moments& widest = current[i];
            const auto& c = widest.covariance;
            const float spread = std::sqrt(c[0] + c[3] + c[5]);
            const Vec3f centroid(widest.centroid[0], widest.centroid[1], widest.centroid[2]);
            const float height = (positions[i] - centroid).dot(best_axis[i]);
            result.offset[i] = spread > 0.0F && std::isfinite(height) ? height / spread : 0.0F;
        }
    });
    FilledLaterVector<Moments>().swap(current);
    FilledLaterVector<Moments>().swap(next);
    result.flatness.swap(best_flatness);
    return result;
}

/// The guide's normals where they are no use: zero where the sample's own normal is, the own
/// normal where no scale gave a plane. Then the band of each sample's sheet (mark_sheets()).
void finish_guide(std::span<const Vec3f> positions, std::span<const Vec3f> normals,
                  const KnnTable& neighbors, Guide& result)
{
    if (result.normals.empty())
        return;
    if (result.normals.size() != positions.size() || result.flatness.size() != positions.size())
        throw std::logic_error("orientation: a guide of another cloud");
    parallel_blocks(positions.size(), 4096, [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i)
        {
            Vec3f& axis = result.normals[i];
            if (!usable(normals[i]))
                axis = Vec3f::Zero();
            else if (!(result.flatness[i] < 1.0F && usable(axis)))
                axis = normals[i];
        }
    });
    mark_sheets(positions, neighbors, result);
    result.side = detail::two_sheet_sides(positions, neighbors, result.normals, result.offset);
    std::vector<float>().swap(result.offset);
    detail::ball_sides(positions, result.normals, result.side);
}

std::size_t count_flipped(std::span<const Vec3f> before, std::span<const Vec3f> after)
{
    std::atomic<std::size_t> flipped{0};
    parallel_blocks(before.size(), 65536, [&](std::size_t begin, std::size_t end) {
        std::size_t local = 0;
        for (std::size_t i = begin; i < end; ++i)
            local += before[i].dot(after[i]) < 0.0F ? 1U : 0U;
        flipped.fetch_add(local, std::memory_order_relaxed);
    });
    return flipped.load();
}

} // namespace

namespace {

/// riemannian_spanning_forest(), with the edges that jump between sheets (Guide::jumps()) at the
/// worst cost. The sizes and the table are checked by the caller.
RiemannianForest spanning_forest(std::span<const Vec3f> positions, std::span<const Vec3f> normals,
                                 const Guide& guide, const KnnTable& neighbors,
                                 const OrientationOptions& options)
{
    const std::size_t n = positions.size();
    if (n >= RiemannianForest::none)
        throw InvalidInput("orientation: too many points for 32-bit indices");
    RiemannianForest forest;
    if (n == 0)
        return forest;
    ProgressReporter progress(options.progress, "orientation");
    const std::size_t columns = graph_columns(options, neighbors);

    // 1. The Riemannian graph's edges, each once, in the neighbour table's layout: {i, j} is
    //    edge (i, c) when j is column c of row i, unless row j lists i too and j < i. No edge
    //    list is built.
    constexpr std::size_t block = 8192;
    if (static_cast<double>(n) * static_cast<double>(columns) >= 0x1p33)
        throw InvalidInput("orientation: too many points times graph neighbours (" +
                           std::to_string(n) + " x " + std::to_string(columns) + ")");
    //    Which entries are edges still leaving their component is one bit each (`live`, a row's
    //    bits in row_bytes bytes); a live edge's cost is worked out again whenever a round looks
    //    at it (the same pure function, so the same bits), which takes 2 bytes a sample for the
    //    default 10 columns where stored costs took 40 (and the guided path's peak memory with
    //    them). Written in full by the first round (in parallel, so the pages are touched where
    //    they are used), hence not zeroed first.
    const std::size_t row_bytes = (columns + 7) / 8;
    auto live = std::make_unique_for_overwrite<std::uint8_t[]>(n * row_bytes);
    const auto cost_of = [&](std::uint32_t a, std::uint32_t b) {
        return std::bit_cast<std::uint32_t>(
            guide.jumps(positions, neighbors, a, b)
                ? 2.0F
                : edge_cost(positions, normals, options.rule, a, b));
    };

    // 2. Borůvka: each round, every component takes its cheapest edge to another component,
    //    found in parallel by atomic minima of 64-bit keys (cost, then edge index: the order of
    //    a stable sort of the edges by cost), so the forest is the one Kruskal's algorithm makes
    //    with that order, whatever the thread count. Components at least halve every round.
    //    Costs are in [0, 2], so their bits fit in 31 and the edge index gets the other 33.
    constexpr std::uint64_t no_key = ~std::uint64_t{0};
    const auto key_of = [](std::uint32_t bits, std::size_t edge) {
        return (std::uint64_t{bits} << 33) | edge;
    };
    const auto edge_of = [](std::uint64_t key) {
        return static_cast<std::size_t>(key & ((std::uint64_t{1} << 33) - 1));
    };
    std::vector<std::uint32_t> label(n); // the component of each sample: a representative
    std::vector<std::uint32_t> up(n);    // by label: the next label towards its round's root
    std::iota(label.begin(), label.end(), 0U);
    std::vector<std::uint32_t> alive(n); // the labels of this round's components
    std::iota(alive.begin(), alive.end(), 0U);
    std::vector<std::uint64_t> cheapest(n, no_key); // by label
    std::vector<std::uint8_t> internal(n, 0);       // every edge of the row is inside one component
    std::vector<std::uint64_t> tree_keys;
    tree_keys.reserve(n);
    //    The costs are stored as the first round's search goes: every sample its own component,
    //    every edge leaves one.
    parallel_blocks(n, block, [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i)
        {
            const auto a = static_cast<std::uint32_t>(i);
            const auto row = neighbors.neighbors(i).first(columns);
            std::uint8_t* bits = live.get() + i * row_bytes;
            std::fill(bits, bits + row_bytes, std::uint8_t{0});
            std::uint64_t own = no_key;
            for (std::size_t c = 0; c < columns; ++c)
            {
                const std::uint32_t b = row[c];
                if (b == a || (b < a && row_contains(neighbors, b, columns, a)))
                    continue;
                bits[c / 8] |= static_cast<std::uint8_t>(1U << (c % 8));
                const std::uint64_t key = key_of(cost_of(a, b), i * columns + c);
                own = std::min(own, key);
                detail::lower_atomically(cheapest[b], key);
            }
            if (own != no_key)
                detail::lower_atomically(cheapest[a], own);
            else
                internal[i] = 1;
        }
    });
    progress.update(0.3, 1.0);
    for (bool merged = true, first = true; merged; first = false)
    {
        parallel_blocks(first ? 0 : n, block, [&](std::size_t begin, std::size_t end) {
            for (std::size_t i = begin; i < end; ++i)
            {
                if (internal[i] != 0)
                    continue;
                const std::uint32_t la = label[i];
                const auto a = static_cast<std::uint32_t>(i);
                const auto row = neighbors.neighbors(i).first(columns);
                std::uint8_t* bits = live.get() + i * row_bytes;
                std::uint64_t own = no_key; // the row's cheapest edge out of la
                bool leaves = false;
                for (std::size_t c = 0; c < columns; ++c)
                {
                    const auto bit = static_cast<std::uint8_t>(1U << (c % 8));
                    if ((bits[c / 8] & bit) == 0)
                        continue;
                    const std::uint32_t lb = label[row[c]];
                    if (lb == la)
                    {
                        bits[c / 8] &= static_cast<std::uint8_t>(~bit); // inside from now on
                        continue;
                    }
                    leaves = true;
                    const std::uint64_t key = key_of(cost_of(a, row[c]), i * columns + c);
                    own = std::min(own, key);
                    detail::lower_atomically(cheapest[lb], key);
                }
                if (leaves)
                    detail::lower_atomically(cheapest[la], own);
                else
                    internal[i] = 1; // components only grow: it stays so
            }
        });
        //    Each component's cheapest edge links it to the component across. Two components
        //    whose cheapest edges are one edge link each other (with distinct keys that is the
        //    only cycle), and the smaller label becomes their root and keeps the edge; pointer
        //    jumping then takes every label to its root. The tree edges are kept in the order of
        //    `alive`, and every step is a function of this round's labels: no thread order shows.
        const std::size_t count = alive.size();
        parallel_blocks(count, block, [&](std::size_t begin, std::size_t end) {
            for (std::size_t q = begin; q < end; ++q)
            {
                const std::uint32_t l = alive[q];
                up[l] = l;
                if (cheapest[l] == no_key)
                    continue;
                const std::size_t edge = edge_of(cheapest[l]);
                const std::uint32_t la = label[edge / columns];
                const std::uint32_t lb = label[neighbors.neighbors(edge / columns)[edge % columns]];
                up[l] = la == l ? lb : la;
            }
        });
        //    Then what each does: 0 nothing (no edge out), 1 keeps its edge, 2 keeps it and is a
        //    root, 3 drops it (the other of a mutual pair holds the same edge).
        std::vector<std::uint8_t> kind(count);
        parallel_blocks(count, block, [&](std::size_t begin, std::size_t end) {
            for (std::size_t q = begin; q < end; ++q)
            {
                const std::uint32_t l = alive[q];
                const std::uint32_t other = up[l];
                kind[q] = other == l ? 0 : up[other] != l ? 1 : l < other ? 2 : 3;
            }
        });
        merged = false;
        for (std::size_t q = 0; q < count; ++q)
        {
            merged |= kind[q] != 0;
            if (kind[q] == 1 || kind[q] == 2)
                tree_keys.push_back(cheapest[alive[q]]);
        }
        parallel_blocks(count, block, [&](std::size_t begin, std::size_t end) {
            for (std::size_t q = begin; q < end; ++q)
            {
                cheapest[alive[q]] = no_key;
                if (kind[q] == 2)
                    up[alive[q]] = alive[q];
            }
        });
        for (bool moved = true; moved;)
        {
            std::atomic<bool> any{false};
            parallel_blocks(count, block, [&](std::size_t begin, std::size_t end) {
                bool local = false;
                for (std::size_t q = begin; q < end; ++q)
                {
                    const std::uint32_t l = alive[q];
                    std::atomic_ref<std::uint32_t> mine(up[l]);
                    const std::uint32_t parent = mine.load(std::memory_order_relaxed);
                    const std::uint32_t grand =
                        std::atomic_ref<std::uint32_t>(up[parent]).load(std::memory_order_relaxed);
                    if (grand != parent)
                    {
                        mine.store(grand, std::memory_order_relaxed);
                        local = true;
                    }
                }
                if (local)
                    any.store(true, std::memory_order_relaxed);
            });
            moved = any.load();
        }
        // Relabel: every component's root, then every sample.
        std::vector<std::uint32_t> next;
        for (const std::uint32_t l : alive)
            if (up[l] == l)
                next.push_back(l);
        parallel_blocks(n, block, [&](std::size_t begin, std::size_t end) {
            for (std::size_t i = begin; i < end; ++i)
                label[i] = up[label[i]];
        });
        alive.swap(next);
    }
    live.reset();
    std::vector<std::uint32_t>().swap(up);
    std::vector<std::uint32_t>().swap(alive);
    std::vector<std::uint64_t>().swap(cheapest);
    std::vector<std::uint8_t>().swap(internal);
    progress.update(0.6, 1.0);

    //    The forest's adjacency, each sample's tree edges in Kruskal's order (by key), so that
    //    the trees are walked as Kruskal's algorithm would: counted and scattered in parallel,
    //    then each sample's few edges sorted. The costs are summed in the order the rounds found
    //    the edges, which does not depend on the thread count.
    const auto ends_of = [&](std::uint64_t key) {
        const std::size_t edge = edge_of(key);
        const auto a = static_cast<std::uint32_t>(edge / columns);
        return std::pair{a, neighbors.neighbors(a)[edge % columns]};
    };
    for (const std::uint64_t key : tree_keys)
        forest.total_cost +=
            static_cast<double>(std::bit_cast<float>(static_cast<std::uint32_t>(key >> 33)));
    //    The edges' ends are looked up again from their keys where needed, and `degree` serves
    //    as the scatter's cursors too (then shifted back): the forest's peak memory is its
    //    adjacency being built, 8 bytes a sample fewer so.
    std::vector<std::uint32_t> degree(n + 1, 0);
    parallel_blocks(tree_keys.size(), block, [&](std::size_t begin, std::size_t end) {
        for (std::size_t e = begin; e < end; ++e)
        {
            const auto [a, b] = ends_of(tree_keys[e]);
            std::atomic_ref<std::uint32_t>(degree[a + 1]).fetch_add(1, std::memory_order_relaxed);
            std::atomic_ref<std::uint32_t>(degree[b + 1]).fetch_add(1, std::memory_order_relaxed);
        }
    });
    for (std::size_t i = 0; i < n; ++i)
        degree[i + 1] += degree[i];
    std::vector<std::uint32_t> adjacent(degree[n]);
    {
        auto adjacent_keys = std::make_unique_for_overwrite<std::uint64_t[]>(degree[n]);
        //    Each sample's cursor starts at its first slot and ends at the next sample's.
        parallel_blocks(tree_keys.size(), block, [&](std::size_t begin, std::size_t end) {
            for (std::size_t e = begin; e < end; ++e)
            {
                const auto [a, b] = ends_of(tree_keys[e]);
                for (const std::uint32_t v : {a, b})
                    adjacent_keys[std::atomic_ref<std::uint32_t>(degree[v]).fetch_add(
                        1, std::memory_order_relaxed)] = tree_keys[e];
            }
        });
        std::move_backward(degree.begin(), degree.end() - 2, degree.end() - 1);
        degree[0] = 0;
        std::vector<std::uint64_t>().swap(tree_keys);
        parallel_blocks(n, block, [&](std::size_t begin, std::size_t end) {
            for (std::size_t v = begin; v < end; ++v)
            {
                std::uint64_t* first = adjacent_keys.get() + degree[v];
                std::uint64_t* last = adjacent_keys.get() + degree[v + 1];
                std::sort(first, last);
                for (std::uint64_t* k = first; k != last; ++k)
                {
                    const auto [a, b] = ends_of(*k);
                    adjacent[static_cast<std::size_t>(k - adjacent_keys.get())] = a == v ? b : a;
                }
            }
        });
    }

    // 3. Components numbered by smallest sample; root = highest sample with a usable normal.
    forest.parent.assign(n, RiemannianForest::none);
    forest.component.assign(n, RiemannianForest::none);
    std::vector<std::uint32_t> label_of_set(n, RiemannianForest::none);
    for (std::size_t i = 0; i < n; ++i)
    {
        std::uint32_t& number = label_of_set[label[i]];
        if (number == RiemannianForest::none)
        {
            number = static_cast<std::uint32_t>(forest.roots.size());
            forest.roots.push_back(RiemannianForest::none);
        }
        forest.component[i] = number;
        if (!usable(normals[i]))
            continue;
        std::uint32_t& root = forest.roots[number];
        if (root == RiemannianForest::none || positions[i].z() > positions[root].z())
            root = static_cast<std::uint32_t>(i);
    }
    std::vector<std::uint32_t>().swap(label);
    std::vector<std::uint32_t>().swap(label_of_set);

    // 4. Each tree walked breadth-first from its root: parents and a parent-first order.
    forest.order.reserve(n);
    for (const std::uint32_t root : forest.roots)
    {
        if (root == RiemannianForest::none)
            continue;
        forest.parent[root] = root;
        std::size_t head = forest.order.size();
        forest.order.push_back(root);
        while (head < forest.order.size())
        {
            const std::uint32_t v = forest.order[head++];
            for (std::uint32_t e = degree[v]; e < degree[v + 1]; ++e)
            {
                const std::uint32_t w = adjacent[e];
                if (forest.parent[w] == RiemannianForest::none)
                {
                    forest.parent[w] = v;
                    forest.order.push_back(w);
                }
            }
        }
    }
    progress.finish();
    return forest;
}

/// Throws unless there are as many normals and neighbour rows as positions.
void check_sizes(std::span<const Vec3f> positions, std::span<const Vec3f> normals,
                 const KnnTable& neighbors)
{
    if (normals.size() != positions.size() || neighbors.rows() != positions.size())
        throw InvalidInput("orientation: " + std::to_string(positions.size()) + " points, " +
                           std::to_string(normals.size()) + " normals and " +
                           std::to_string(neighbors.rows()) + " neighbour rows must agree");
}

} // namespace

RiemannianForest riemannian_spanning_forest(std::span<const Vec3f> positions,
                                            std::span<const Vec3f> normals,
                                            const KnnTable& neighbors,
                                            const OrientationOptions& options)
{
    check_sizes(positions, normals, neighbors);
    check_knn_table(neighbors, positions.size(), positions.size(), "orientation");
    return spanning_forest(positions, normals, Guide{}, neighbors, options);
}

namespace {

/// Samples a block of reduce_by_component().
constexpr std::size_t reduce_block = 65536;

/// Per component (`component_of(i)`: sample i's, RiemannianForest::none to leave it out), the
/// samples 0 to n - 1 folded in index order: `add(acc, i)` folds sample i into its component's
/// accumulator, `merge(total, part)` a block's part into the total. Blocks run in parallel and are
/// merged in block order, so the result does not depend on the thread count.
template <typename ComponentOf, typename Acc, typename Add, typename Merge>
std::vector<Acc> reduce_by_component(std::size_t n, const ComponentOf& component_of,
                                     std::size_t count, const Acc& zero, const Add& add,
                                     const Merge& merge)
{
    const std::size_t blocks = (n + reduce_block - 1) / reduce_block;
    // Each block's runs of one component: few where components are spatially coherent.
    std::vector<std::vector<std::pair<std::uint32_t, Acc>>> parts(blocks);
    parallel_blocks(blocks, 1, [&](std::size_t first, std::size_t last) {
        for (std::size_t b = first; b < last; ++b)
        {
            auto& out = parts[b];
            for (std::size_t i = b * reduce_block; i < std::min(n, (b + 1) * reduce_block); ++i)
            {
                const std::uint32_t c = component_of(i);
                if (c == RiemannianForest::none)
                    continue;
                if (out.empty() || out.back().first != c)
                    out.emplace_back(c, zero);
                add(out.back().second, i);
            }
        }
    });
    std::vector<Acc> total(count, zero);
    for (const auto& part : parts)
        for (const auto& [c, acc] : part)
            merge(total[c], acc);
    return total;
}

/// Each component's highest sample (the first of them on a tie).
template <typename ComponentOf>
std::vector<std::uint32_t> highest_samples(std::span<const Vec3f> positions,
                                           const ComponentOf& component_of, std::size_t count)
{
    const auto higher = [&](std::uint32_t& best, std::uint32_t i) {
        if (i != RiemannianForest::none &&
            (best == RiemannianForest::none || positions[i].z() > positions[best].z()))
            best = i;
    };
    return reduce_by_component(
        positions.size(), component_of, count, RiemannianForest::none,
        [&](std::uint32_t& best, std::size_t i) { higher(best, static_cast<std::uint32_t>(i)); },
        higher);
}

/// The last two steps of orient_normals_mst() for every component (`component_of(i)`: sample
/// i's, RiemannianForest::none to leave it out): turn it so that its root (`roots`, one a
/// component, or none) faces +z, then flip it if its area-weighted flux is clearly negative.
/// A component holding a faced thin part (`faced`, nonzero where a sample's region was faced:
/// its normals face away from its midplane, outwards) keeps its normals unless its flux is
/// clearly negative: a thin solid encloses too little volume for its flux to be clear, and the
/// root's +z turned a noisy plate 0.02 thick at 1M samples, faced outwards, inside out (91.8% of
/// its normals facing away).
template <typename ComponentOf>
void face_components(std::span<const Vec3f> positions, const KnnTable& neighbors,
                     const ComponentOf& component_of, std::span<const std::uint32_t> roots,
                     std::span<Vec3f> normals, std::span<const std::uint8_t> faced = {})
{
    const std::size_t n = positions.size();
    const std::size_t component_count = roots.size();
    std::vector<std::uint8_t> root_down(component_count, 0);
    for (std::size_t c = 0; c < component_count; ++c)
        root_down[c] = roots[c] != RiemannianForest::none && normals[roots[c]].z() < 0.0F;
    //    Σ a_i n_i·(p_i − c), a_i ≈ squared k-th neighbour distance, with the normals as they
    //    are (the root's turn negates it).
    const std::vector<Eigen::Vector4d> sums = reduce_by_component(
        n, component_of, component_count, Eigen::Vector4d::Zero().eval(),
        [&](Eigen::Vector4d& acc, std::size_t i) {
            acc.head<3>() += positions[i].cast<double>();
            acc[3] += 1.0;
        },
        [](Eigen::Vector4d& total, const Eigen::Vector4d& part) { total += part; });
    std::vector<float> sampled;
    sampled.reserve(n / flux_area_stride + 1);
    for (std::size_t i = 0; i < n; i += flux_area_stride)
        sampled.push_back(neighbors.farthest2(i));
    double largest_area = std::numeric_limits<double>::infinity();
    if (const float median = sampled.empty() ? 0.0F : middle_value(sampled);
        std::isfinite(median) && median > 0.0F)
        largest_area = flux_area_cap * static_cast<double>(median);
    const std::vector<Eigen::Vector2d> fluxes = reduce_by_component(
        n, component_of, component_count, Eigen::Vector2d::Zero().eval(),
        [&](Eigen::Vector2d& acc, std::size_t i) {
            const Eigen::Vector4d& sum = sums[component_of(i)];
            const double area = std::min<double>(neighbors.farthest2(i), largest_area);
            const Vec3d d = positions[i].cast<double>() - sum.head<3>() / sum[3];
            acc[0] += area * normals[i].cast<double>().dot(d);
            acc[1] += area * d.norm();
        },
        [](Eigen::Vector2d& total, const Eigen::Vector2d& part) { total += part; });
    std::vector<std::uint8_t> settled(component_count, 0);
    for (std::size_t i = 0; i < faced.size(); ++i)
        if (const std::uint32_t c = component_of(i); faced[i] != 0 && c != RiemannianForest::none)
            settled[c] = 1;
    std::vector<std::uint8_t> flip(component_count, 0);
    for (std::size_t c = 0; c < component_count; ++c)
    {
        const double bound = flux_decision_threshold * fluxes[c][1];
        if (settled[c] != 0)
        {
            flip[c] = fluxes[c][0] < -bound ? 1 : 0;
            continue;
        }
        const double flux = root_down[c] != 0 ? -fluxes[c][0] : fluxes[c][0];
        const bool inward = flux < -bound;
        flip[c] = static_cast<std::uint8_t>((root_down[c] != 0) != inward);
    }
    parallel_blocks(n, reduce_block, [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i)
        {
            const std::uint32_t c = component_of(i);
            if (c != RiemannianForest::none && flip[c] != 0)
                normals[i] = -normals[i];
        }
    });
}

/// A neighbour supports a sample's normal within 30° of it (cos² 30° = 0.75).
constexpr float supporting_cos2 = 0.75F;
/// Fewer supporting neighbours than this (of the row's 16), and a guided sample's normal is a
/// stray of the noise, replaced by its neighbours' vote (vote_normals()). Measured on the noisy
/// 100k part and plate of bench/peers (seed 7; normals more than 30° off the truth): 2 -> 3.73% and
/// 3.14%, 4 -> 3.72% and 3.11%, 6 -> 3.78% and 3.14%, every sample -> 4.65% and 3.76% (the
/// creases' minority side outvoted); none -> 3.77% and 3.29%. On the 1M plate below, 6 leaves
/// 3.2% off by 30° and 0.20% inside out where 4 leaves 3.6% and 0.25%.
constexpr std::size_t min_support = 6;

/// Oriented guide normals checked by a vote of their neighbours on the same sheet
/// (Guide::jumps_in_rows()), each weighted by its guide's confidence: a sample that too few
/// neighbours support (min_support) takes the principal axis of their normals (a sign-free vote, so
/// the side with more weight wins, rather than an average across a crease), and every sample turns
/// to the side the weighted normals point to, so a lone sample oriented against its neighbours
/// follows them. On a noisy plate whose faces are 9 noise deviations apart (1M samples, noise
/// twice the sampling step, bench/peers' noisy+holes plate at 1M) the guides of samples whose
/// every scale is thick with noise lie sideways, and a field through them puts tunnels across
/// the plate: normals more than 30° off the truth 7.8% -> 3.2%, inside out 0.76% -> 0.20%, and
/// `reconstruct` gives 11 handles instead of 37 (Euler characteristic -22 instead of -72; with
/// the true normals marching cubes gives 16, the rest are the holes through both faces).
void vote_normals(std::span<const Vec3f> positions, const KnnTable& neighbors, const Guide& guide,
                  std::vector<Vec3f>& normals)
{
    const std::size_t n = normals.size();
    std::vector<Vec3f> voted(n);
    parallel_blocks(n, 4096, [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i)
        {
            voted[i] = normals[i];
            if (!usable(normals[i]))
                continue;
            const auto a = static_cast<std::uint32_t>(i);
            Eigen::Matrix3f tensor = Eigen::Matrix3f::Zero();
            Vec3f sum = Vec3f::Zero();
            Vec3f start = Vec3f::Zero();
            float heaviest = -1.0F;
            std::size_t support = 0;
            for (const std::uint32_t j : neighbors.neighbors(i))
            {
                if (!usable(normals[j]) ||
                    (j != a && guide.jumps_in_rows(positions, neighbors, a, j)))
                    continue;
                const float along = normals[j].dot(normals[i]);
                support += j != a && along * along > supporting_cos2 ? 1U : 0U;
                const float weight = guide.confidence(j);
                tensor.noalias() += weight * normals[j] * normals[j].transpose();
                sum += weight * normals[j];
                if (weight > heaviest)
                {
                    heaviest = weight;
                    start = normals[j];
                }
            }
            // Supported by enough neighbours: the sample's own axis stands (a crease's side, a
            // thin part), only its side follows the vote.
            if (support >= min_support)
            {
                voted[i] = normals[i].dot(sum) < 0.0F ? Vec3f(-normals[i]) : normals[i];
                continue;
            }
            // Power iteration from the most confident normal: the principal axis is the vote's
            // winner (a start perpendicular to it would never reach it).
            Vec3f axis = start;
            for (int step = 0; step < 4; ++step)
            {
                const Vec3f next = tensor * axis;
                const float length = next.norm();
                if (!(length > 0.0F) || !std::isfinite(length))
                    break;
                axis = next / length;
            }
            if (!usable(axis))
                continue;
            const float side = axis.dot(sum);
            voted[i] = side < 0.0F ? Vec3f(-axis) : axis;
        }
    });
    normals.swap(voted);
}

/// A guided sample lies in a crease band when the flatness of its guide (the flattest of its
/// neighbourhoods) is more than this many times the cloud's median: noise alone makes every
/// sample about equally thick, and a crease keeps each scale thicker than that. On the noisy cones
/// of `pointform sample cone` (noise 0.1% to 0.3% of the diagonal) the rim's samples score 1.3 to
/// 2.6 times the median out to about five sampling steps; at 2 the noisiest (0.3%) was not parted
/// into base and side, at 1.5 and 1.7 each was.
constexpr float crease_band_flatness = 1.5F;
/// Regions of the winding check smaller than this share of the samples (or than min_region
/// samples) are not turned on their own.
constexpr double least_region_share = 0.005;
constexpr std::size_t min_region = 64;
/// At most this many regions are tried, the largest first.
constexpr std::size_t most_regions = 64;
/// The winding number is summed over about this many samples at about this many queries (4,096
/// and 1,024 turned the same regions on the noisy cones in 0.10 s instead of 0.16 s at 100k
/// samples, but left the arrow of the sweep at noise 0.2%, seed 2, with 4.1% of its area facing
/// away instead of 1.0%).
constexpr std::size_t winding_sources = 8192;
constexpr std::size_t winding_queries = 2048;
/// Sources nearer a query than this many times its k-th neighbour's distance, scaled by the
/// square root of the stride between sources (so about the sources' own spacing), are left out
/// of its sum: the surface through the query contributes nothing there for a smooth sheet, while
/// single noisy samples close by would each add a large term.
constexpr float winding_exclusion = 2.0F;
/// A region is turned when that lowers the fitted winding energy by more than this share of it
/// (and does not raise the plain one; see turn_regions_by_winding()).
constexpr double winding_gain = 0.2;
/// ... and the turns stand only if they leave the fitted energy, per query, below this: the
/// samples then make a closed, consistently oriented surface. Such surfaces score 0.001 to 0.03
/// (the bench's noisy two spheres, blobby and part at 100k and 1M, the noisy cones once turned:
/// noise, holes and the near sources left out); the LiDAR terrain of data/ (open, with roofs,
/// walls and trees), once its largest region was turned down, 0.084, which is a winding number
/// that is about the same everywhere but is no surface's (its plain energy, 0.087, was under the
/// 0.1 that bounded it before the fit).
constexpr double closed_energy = 0.05;

/// Runs `step(begin, end, round)` over fixed blocks of [0, n) in parallel, round after round
/// (from 1), until no block's step returns true (it made progress) or `most` rounds have run.
/// Steps that read what earlier rounds wrote, and skip what this round writes, give the same
/// result whatever the thread count.
template <class Step>
void in_rounds(std::size_t n, std::uint32_t most, const Step& step)
{
    for (std::uint32_t round = 1; round <= most; ++round)
    {
        std::atomic<bool> progressed{false};
        parallel_blocks(n, 4096, [&](std::size_t begin, std::size_t end) {
            if (step(begin, end, round))
                progressed.store(true, std::memory_order_relaxed);
        });
        if (!progressed.load())
            break;
    }
}

/// The samples of a guided cloud in a crease band (crease_band_flatness) or next to one.
std::vector<std::uint8_t> crease_band(std::span<const Vec3f> positions, const KnnTable& neighbors,
                                      const Guide& guide, std::size_t columns)
{
    const std::size_t n = positions.size();
    std::vector<float> values;
    const std::size_t stride = n >= noise_test_sampled ? noise_test_stride : 1;
    for (std::size_t i = 0; i < n; i += stride)
        if (usable(guide.normals[i]))
            values.push_back(guide.flatness[i]);
    if (values.empty())
        return {};
    const float limit = crease_band_flatness * middle_value(values);
    const auto thick = [&](std::size_t i) {
        return usable(guide.normals[i]) && guide.flatness[i] > limit;
    };
    std::vector<std::uint8_t> band(n, 0);
    parallel_blocks(n, 4096, [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i)
        {
            bool in = thick(i);
            for (const std::uint32_t j : neighbors.neighbors(i).first(columns))
                in = in || thick(j);
            band[i] = in ? 1 : 0;
        }
    });
    return band;
}

/// The winding numbers of turn_regions_by_winding() at `queries`, from the oriented `sources`
/// (each standing for `stride` samples) in `groups` + 1 groups: `group_of(j)` is source j's group,
/// or negative for the last. `take(query, group, term)` receives each group's share of each
/// query's winding number, in group order for a query (queries run in parallel).
///
/// The sources are gathered once, grouped (each group in sample order), in float lanes: every
/// query sums each group in winding_lanes lanes (winding_group_sum()). Positions are taken about
/// the first source and scaled by the largest extent, so that the terms (each dimensionless)
/// neither underflow nor overflow in float, whatever the cloud's units.
template <class GroupOf, class Take>
void winding_sums(std::span<const Vec3f> positions, const KnnTable& neighbors,
                  std::span<const Vec3f> normals, std::span<const std::uint32_t> sources,
                  std::size_t stride, std::span<const std::uint32_t> queries, std::size_t groups,
                  const GroupOf& group_of, const Take& take)
{
    WindingSources gathered;
    Vec3f low = Vec3f::Constant(std::numeric_limits<float>::max());
    Vec3f high = Vec3f::Constant(std::numeric_limits<float>::lowest());
    for (const std::uint32_t j : sources)
    {
        low = low.cwiseMin(positions[j]);
        high = high.cwiseMax(positions[j]);
    }
    gathered.origin = positions[sources.front()];
    // Halved first: a span of the whole float range stays finite.
    const float half_extent = (0.5F * high - 0.5F * low).maxCoeff();
    gathered.scale = half_extent > 0.0F ? 0.5F / half_extent : 1.0F;
    // A source stands for stride samples, each of area π r² (r its k-th neighbour's distance)
    // over the k samples inside it; over 4π: stride r² / (4 k).
    const double area_scale =
        static_cast<double>(stride) / (4.0 * static_cast<double>(neighbors.k)) *
        static_cast<double>(gathered.scale) * static_cast<double>(gathered.scale);
    std::vector<std::vector<std::uint32_t>> group(groups + 1);
    for (const std::uint32_t j : sources)
    {
        const std::int32_t g = group_of(j);
        group[g < 0 ? groups : static_cast<std::size_t>(g)].push_back(j);
    }
    for (std::size_t g = 0; g <= groups; ++g)
    {
        gathered.begin.push_back(gathered.size());
        for (const std::uint32_t j : group[g])
            gathered.push(
                gathered.local(positions[j]), normals[j],
                static_cast<float>(area_scale * static_cast<double>(neighbors.farthest2(j))));
        while (gathered.size() % winding_lanes != 0)
            gathered.push(Vec3f::Zero(), Vec3f::Zero(), 0.0F); // masked or zero: adds 0
    }
    gathered.begin.push_back(gathered.size());
    parallel_blocks(queries.size(), 64, [&](std::size_t begin, std::size_t end) {
        for (std::size_t qi = begin; qi < end; ++qi)
        {
            const Vec3f q = gathered.local(positions[queries[qi]]);
            const float excluded2 = winding_exclusion * winding_exclusion *
                                    neighbors.farthest2(queries[qi]) * static_cast<float>(stride) *
                                    gathered.scale * gathered.scale;
            for (std::size_t g = 0; g <= groups; ++g)
                take(qi, g,
                     winding_group_sum(gathered, gathered.begin[g], gathered.begin[g + 1], q,
                                       excluded2));
        }
    });
}

/// The winding energies of turn_regions_by_winding() over winding numbers `w(q)`, q < queries:
/// fitted, min over s of Σ (s w − ½)²; plain, Σ (w ∓ ½)² at the better sign.
struct WindingEnergy
{
    double fitted;
    double plain;
};

template <class W>
WindingEnergy winding_energy(std::size_t queries, const W& w)
{
    double sum = 0.0;
    double squares = 0.0;
    double outward = 0.0;
    double inward = 0.0;
    for (std::size_t qi = 0; qi < queries; ++qi)
    {
        const double v = w(qi);
        sum += v;
        squares += v * v;
        outward += (v - 0.5) * (v - 0.5);
        inward += (v + 0.5) * (v + 0.5);
    }
    // The fit's s = Σ w / (2 Σ w²).
    const double all = 0.25 * static_cast<double>(queries);
    return WindingEnergy{squares > 0.0 ? all - 0.25 * sum * sum / squares : all,
                         std::min(outward, inward)};
}

/// The samples that winding_sums() sums over (every stride-th oriented sample, in index order)
/// and queries at, and that stride.
struct WindingSamples
{
    std::vector<std::uint32_t> sources;
    std::vector<std::uint32_t> queries;
    std::size_t stride = 1;
};

WindingSamples winding_samples(std::span<const Vec3f> normals)
{
    WindingSamples out;
    const auto oriented = static_cast<std::size_t>(
        std::count_if(normals.begin(), normals.end(), [](const Vec3f& v) { return usable(v); }));
    out.stride = std::max<std::size_t>(1, oriented / winding_sources);
    for (std::size_t i = 0, seen = 0; i < normals.size(); ++i)
        if (usable(normals[i]) && seen++ % out.stride == 0)
            out.sources.push_back(static_cast<std::uint32_t>(i));
    const std::size_t query_stride = std::max<std::size_t>(1, out.sources.size() / winding_queries);
    for (std::size_t s = 0; s < out.sources.size(); s += query_stride)
        out.queries.push_back(out.sources[s]);
    return out;
}

/// The winding energies (winding_energy()) of the oriented `normals` at `samples`' queries.
WindingEnergy winding_energy_of(std::span<const Vec3f> positions, const KnnTable& neighbors,
                                std::span<const Vec3f> normals, const WindingSamples& samples)
{
    std::vector<double> w(samples.queries.size(), 0.0);
    if (samples.sources.empty())
        return {0.0, 0.0};
    winding_sums(
        positions, neighbors, normals, samples.sources, samples.stride, samples.queries, 0,
        [](std::uint32_t) { return -1; },
        [&](std::size_t qi, std::size_t, double term) { w[qi] += term; });
    return winding_energy(samples.queries.size(), [&](std::size_t qi) { return w[qi]; });
}

/// The generalized winding number check of a guided orientation: regions that a crease band
/// parts are turned over where that makes the winding number of the oriented samples about ½ on
/// the samples themselves.
///
/// Near a crease sharper than a right angle every scale of a noisy sample's neighbourhood spans
/// the turn, so its guide normal is the axis of the wedge between the two faces, within a
/// reliable step of both as lines: a chain of such steps hands one face's orientation to the
/// other the short way round, which is the wrong way, and no vote of neighbours can tell (the base
/// of a noisy cone as wide as high came out inside out on every seed). The samples whose guide is
/// thick at every scale (crease_band()) part the cloud into regions joined by reliable steps of
/// flat guides. Each oriented sample j, with area a_j ≈ π r_j² / k (r_j its k-th neighbour's
/// distance), is a dipole of the winding number w(q) = Σ_j a_j n_j·(p_j − q) / (4π |p_j − q|³),
/// which is 1 inside a closed, consistently oriented surface, 0 outside and ½ on it; turning a
/// region over negates its share of w everywhere. So the energy Σ_q (s w(q) − ½)² over query
/// samples q, at the scale s that makes it least (its sign settles a surface oriented inwards,
/// which the flux test turns later), is lowered region by region, the largest first, where
/// turning one lowers it by more than winding_gain of it and does not raise the plain energy
/// Σ_q (w(q) ∓ ½)². The scale takes up the bias of the areas: noise of two sampling steps puts
/// the k-th neighbour farther off, and a 1M-sample noisy blobby, rightly oriented, had w about
/// 0.78 at the median, so that the plain energy (0.136) fell to 0.087 by turning its largest
/// region inside out (a third of the samples wrong), while the fitted energy rose from 0.011 to
/// 0.086. The plain energy keeps the level: on two simulated scans of the teapot (open, with
/// holes), turning a region of 4,284-5,460 samples wrongly made w more even (fitted 0.015 ->
/// 0.012) but further from ½ (plain 0.021 -> 0.026-0.029). Turns lower both where a face is inside
/// out (the noisy cones: fitted 0.18 -> 0.03, plain 0.19-0.25 -> 0.03-0.10). A turn says the band
/// beside the region is such a crease, whose guides are no face's normal: the samples outside the
/// regions tried then take the tangent plane of the region sample they lie nearest to, carried
/// round by round from the regions (on the noisy cones the mean angle error 2.8-2.9° -> 2.3°, and
/// `reconstruct`'s Euler characteristic -46 to -78 -> -24 to -28). The turns stand only if the
/// fitted energy they leave, once the band has followed them, is that of a closed surface
/// (closed_energy), and are sought only where
/// the energy is above that to begin with: a scan with large parts unseen (a CAD part's faces the
/// cameras missed) leaves the winding number uneven however its regions are oriented, and turning
/// a rightly oriented region could still lower it by a fifth. On simulated scans of machined
/// parts (bench/peers/virtual_scan.py, seeds 1-5, a flange with a bore and four bolt holes, a
/// block with a thin fin) three of fifteen turned a region from an energy of 0.019-0.041, each
/// one wrongly (the flange's bore, 2.8% of its samples then inside out, 0.03% without the turn;
/// the fin block 8.9% -> 1.1%); every turn of the noisy cones starts at 0.18-0.19. On a cloud
/// where no region turns nothing changes: on 90 simulated scans of fandisk, spot and the teapot
/// not one sample did, nor on the LiDAR terrain of data/. (Taking the planes on every noisy cloud
/// halved the normals more than 30° off on the bench's noisy blobby and part, but its plate,
/// whose rims are narrower than the band, came out with 4x the vertices and twice the Hausdorff
/// distance.)
///
/// Sums run over every stride-th sample in index order (spatially sorted) and each query's sum is
/// serial, so the result does not depend on the thread count.
void turn_regions_by_winding(std::span<const Vec3f> positions, const KnnTable& neighbors,
                             const Guide& guide, std::size_t columns, float reliable,
                             std::vector<Vec3f>& normals)
{
    const std::size_t n = positions.size();
    constexpr std::uint32_t none = 0xFFFFFFFFU;
    // 1. Regions: the samples outside the band joined by reliable steps on one sheet (the band
    //    and the sets go once the regions are numbered: step 4 is the peak of memory).
    std::vector<std::uint32_t> region;
    std::vector<std::uint32_t> size;
    {
        const std::vector<std::uint8_t> band = crease_band(positions, neighbors, guide, columns);
        if (band.empty())
            return;
        region.assign(n, none);
        const auto in_region = [&](std::size_t i) {
            return band[i] == 0 && usable(normals[i]);
        };
        //    Which steps join are tested in parallel (a bit a column), then joined on one
        //    thread in the same order: the tests were most of the serial time (1.2 s at 10M).
        const std::size_t row_bytes = (columns + 7) / 8;
        auto joins = std::make_unique_for_overwrite<std::uint8_t[]>(n * row_bytes);
        parallel_blocks(n, 4096, [&](std::size_t begin, std::size_t end) {
            for (std::size_t i = begin; i < end; ++i)
            {
                std::uint8_t* bits = joins.get() + i * row_bytes;
                std::fill(bits, bits + row_bytes, std::uint8_t{0});
                if (!in_region(i))
                    continue;
                const auto row = neighbors.neighbors(i).first(columns);
                for (std::size_t c = 0; c < columns; ++c)
                {
                    const std::uint32_t j = row[c];
                    if (j != i && in_region(j) &&
                        std::abs(guide.normals[i].dot(guide.normals[j])) >= reliable &&
                        !guide.jumps(positions, neighbors, static_cast<std::uint32_t>(i), j))
                        bits[c / 8] |= static_cast<std::uint8_t>(1U << (c % 8));
                }
            }
        });
        DisjointSets sets(n);
        for (std::size_t i = 0; i < n; ++i)
        {
            const std::uint8_t* bits = joins.get() + i * row_bytes;
            const auto row = neighbors.neighbors(i);
            for (std::size_t c = 0; c < columns; ++c)
                if ((bits[c / 8] & (1U << (c % 8))) != 0)
                    sets.unite(i, row[c]);
        }
        joins.reset();
        std::vector<std::uint32_t> id(n, none);
        for (std::size_t i = 0; i < n; ++i)
        {
            if (!in_region(i))
                continue;
            const std::size_t root = sets.find(i);
            if (id[root] == none)
            {
                id[root] = static_cast<std::uint32_t>(size.size());
                size.push_back(0);
            }
            region[i] = id[root];
            ++size[id[root]];
        }
    }
    std::vector<std::uint32_t> tried;
    for (std::uint32_t r = 0; r < size.size(); ++r)
        if (size[r] >= min_region &&
            static_cast<double>(size[r]) >= least_region_share * static_cast<double>(n))
            tried.push_back(r);
    std::stable_sort(tried.begin(), tried.end(),
                     [&](std::uint32_t x, std::uint32_t y) { return size[x] > size[y]; });
    if (tried.size() > most_regions)
        tried.resize(most_regions);
    if (tried.size() < 2)
        return;
    const std::size_t count = tried.size();
    std::vector<std::int32_t> tried_of(size.size(), -1);
    for (std::size_t t = 0; t < count; ++t)
        tried_of[tried[t]] = static_cast<std::int32_t>(t);
    const auto tried_index = [&](std::uint32_t i) {
        return region[i] == none ? -1 : tried_of[region[i]];
    };

    // 2. Each query's winding number and the share of each region tried in it.
    const WindingSamples samples = winding_samples(normals);
    const std::vector<std::uint32_t>& sources = samples.sources;
    const std::vector<std::uint32_t>& queries = samples.queries;
    const std::size_t stride = samples.stride;
    std::vector<double> total(queries.size(), 0.0);
    std::vector<double> share(queries.size() * count, 0.0);
    winding_sums(positions, neighbors, normals, sources, stride, queries, count, tried_index,
                 [&](std::size_t qi, std::size_t g, double term) {
                     total[qi] += term;
                     if (g < count)
                         share[qi * count + g] = term;
                 });

    // 3. Turn regions, the largest first, while that lowers the energy by winding_gain.
    std::vector<std::uint8_t> turned(count, 0);
    const auto energy = [&] {
        return winding_energy(queries.size(), [&](std::size_t qi) {
            double w = total[qi];
            for (std::size_t t = 0; t < count; ++t)
                if (turned[t] != 0)
                    w -= 2.0 * share[qi * count + t];
            return w;
        });
    };
    WindingEnergy current = energy();
    // The most fitted energy of a closed, consistently oriented surface (closed_energy a query).
    const double closed_bound = closed_energy * static_cast<double>(queries.size());
    // Already a closed, consistently oriented surface's: nothing to turn.
    if (current.fitted <= closed_bound)
        return;
    bool any = false;
    for (bool changed = true; changed;)
    {
        changed = false;
        for (std::size_t t = 0; t < count; ++t)
        {
            turned[t] ^= 1U;
            const WindingEnergy trial = energy();
            if (trial.fitted < (1.0 - winding_gain) * current.fitted &&
                trial.plain <= current.plain)
            {
                current = trial;
                changed = true;
                any = true;
            }
            else
                turned[t] ^= 1U;
        }
    }
    if (!any)
        return;
    //    The turns stand if they leave the fitted energy of a closed surface (closed_energy).
    //    The regions alone may not: the band's samples turn with them only in step 4, and where
    //    the band is wide their share of w keeps the energy up (a noisy plate 0.04 thick, faces 7
    //    deviations apart, whose guides' wider scales span both faces, had 44% of its samples in
    //    the band: turning its inside-out bottom face left 0.10 per query). Then the energy is
    //    taken again once step 4 has run, and the turns stand only if that one is closed.
    const bool closed = current.fitted <= closed_bound;

    // 4. The turned regions turn. The band between a turned region and its neighbours is then a
    //    crease sharper than a right angle, whose guides are the wedge's axes, not either face's
    //    normal: every sample outside the regions tried takes the tangent plane (normal and
    //    side) of the region sample it lies nearest to, among those its neighbours on its sheet
    //    took before it, round by round from the regions; where its neighbourhood does not lie
    //    on that plane (the median distance more than plane_fit deviations of the noise: a face
    //    narrower than the band, as a plate's rim) it keeps its own normal, on that plane's side.
    //    Such a sample hands no plane on: a plate's rim, reached from one face, handed that
    //    face's plane on to samples of the far face that their own face had not reached yet (the
    //    noisy plate 0.04 thick at seed 1: 681 of its bottom face's 44,260 samples inside out,
    //    `reconstruct`'s Chamfer 0.104% of the diagonal; now 0.070%, as at the seeds where
    //    nothing turns).
    constexpr float plane_fit = 1.5F;
    std::vector<std::uint32_t> source(n, none);
    std::vector<std::uint32_t> stamp(n, none); // the round a sample took its plane in
    for (std::size_t i = 0; i < n; ++i)
    {
        const std::int32_t t = tried_index(static_cast<std::uint32_t>(i));
        if (t < 0)
            continue;
        source[i] = static_cast<std::uint32_t>(i);
        stamp[i] = 0;
        if (turned[static_cast<std::size_t>(t)] != 0)
            normals[i] = -normals[i];
    }
    std::vector<Vec3f> adopted(normals);
    in_rounds(
        n, std::numeric_limits<std::uint32_t>::max(),
        [&](std::size_t begin, std::size_t end, std::uint32_t round) {
            std::vector<float> residual(neighbors.k);
            bool local = false;
            for (std::size_t i = begin; i < end; ++i)
            {
                if (stamp[i] != none || !usable(normals[i]))
                    continue;
                const auto a = static_cast<std::uint32_t>(i);
                float nearest = std::numeric_limits<float>::infinity();
                std::uint32_t from = none;
                for (const std::uint32_t j : neighbors.neighbors(i).first(columns))
                {
                    // Samples decided in this round are skipped whichever thread got there first.
                    const std::uint32_t decided =
                        std::atomic_ref<std::uint32_t>(stamp[j]).load(std::memory_order_relaxed);
                    if (j == i || decided >= round || guide.jumps(positions, neighbors, a, j))
                        continue;
                    const std::uint32_t s = source[j];
                    if (s == none)
                        continue;
                    const float distance = std::abs((positions[i] - positions[s]).dot(normals[s]));
                    if (distance < nearest || (distance == nearest && s < from))
                    {
                        nearest = distance;
                        from = s;
                    }
                }
                if (from == none)
                    continue;
                const Vec3f& plane = normals[from];
                const auto row = neighbors.neighbors(i);
                for (std::size_t c = 0; c < row.size(); ++c)
                    residual[c] = std::abs((positions[row[c]] - positions[from]).dot(plane));
                const bool fits = middle_value(std::span<float>(residual).first(row.size())) <=
                                  plane_fit * guide.reach[i] / off_sheet_deviations;
                source[i] = fits ? from : none;
                adopted[i] = fits                           ? plane
                             : plane.dot(normals[i]) < 0.0F ? Vec3f(-normals[i])
                                                            : normals[i];
                std::atomic_ref<std::uint32_t>(stamp[i]).store(round, std::memory_order_relaxed);
                local = true;
            }
            return local;
        });
    //    A sample that no round reached (every edge of its row jumps between sheets: an outlier
    //    of the noise off its sheet) kept its own normal, whose side was never set against the
    //    turned regions: it takes the side that its row's reached samples point to. On 100k
    //    samples of a cone as wide as high with noise of 0.1% of the diagonal (seed 2), 164
    //    such samples on its smooth side were left inside out, each a pit in the field.
    parallel_blocks(n, 4096, [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i)
        {
            if (stamp[i] != none || !usable(normals[i]))
                continue;
            Vec3f sum = Vec3f::Zero();
            for (const std::uint32_t j : neighbors.neighbors(i).first(columns))
                if (j != i && stamp[j] != none)
                    sum += adopted[j];
            if (sum.dot(adopted[i]) < 0.0F)
                adopted[i] = -adopted[i];
        }
    });
    if (!closed)
    {
        if (winding_energy_of(positions, neighbors, adopted, samples).fitted > closed_bound)
        {
            for (std::size_t i = 0; i < n; ++i) // the turned regions back as they were
            {
                const std::int32_t t = tried_index(static_cast<std::uint32_t>(i));
                if (t >= 0 && turned[static_cast<std::size_t>(t)] != 0)
                    normals[i] = -normals[i];
            }
            return;
        }
    }
    normals.swap(adopted);
}

/// Rounds of follow_faced_regions(): how far (in steps of the neighbour table) the sign of a faced
/// region reaches into the samples beside it.
constexpr std::uint32_t follow_rounds = 32;
/// A sample follows only where the vote of the samples that reach it is at least this share of
/// its weight (see follow_faced_regions()).
constexpr float follow_consensus = 0.8F;

/// The samples beside a thin part's faced regions that have no side of their own take the sign
/// of the samples that balls gave a side in those regions (`faced`, face_two_sheet_regions()), on
/// their sheet, round by round; returns how many turned. Where a hole in one face leaves the
/// other face alone, no ball about it dips, and that face's samples had no side: they kept the
/// sign that orientation gave both faces (on a plate 6 deviations thick, 2.9% of its samples,
/// half of them facing away). A sample follows only where the samples that reach it agree
/// (follow_consensus): beside a rim, both faces' samples reach it.
std::size_t follow_faced_regions(std::span<const Vec3f> positions, const KnnTable& neighbors,
                                 const Guide& guide, std::size_t columns,
                                 std::span<const std::uint8_t> faced, std::vector<Vec3f>& normals)
{
    const std::size_t n = positions.size();
    if (faced.size() != n)
        return 0;
    constexpr std::uint32_t none = 0xFFFFFFFFU;
    std::vector<std::uint32_t> stamp(n, none); // the round a sample took its sign in
    for (std::size_t i = 0; i < n; ++i)
        if (faced[i] == detail::faced_by_ball)
            stamp[i] = 0;
    std::atomic<std::size_t> turned{0};
    in_rounds(n, follow_rounds, [&](std::size_t begin, std::size_t end, std::uint32_t round) {
        bool local = false;
        for (std::size_t i = begin; i < end; ++i)
        {
            if (stamp[i] != none || guide.side[i] != 0 || !usable(normals[i]))
                continue;
            float vote = 0.0F;
            float weight = 0.0F;
            bool reached = false;
            for (const std::uint32_t j : neighbors.neighbors(i).first(columns))
            {
                // Samples that took their sign in this round are skipped whichever thread
                // got there first.
                const std::uint32_t taken =
                    std::atomic_ref<std::uint32_t>(stamp[j]).load(std::memory_order_relaxed);
                if (j == i || taken >= round ||
                    guide.jumps(positions, neighbors, static_cast<std::uint32_t>(i), j))
                    continue;
                reached = true;
                const float a = normals[i].dot(normals[j]);
                vote += a;
                weight += std::abs(a);
            }
            // Only where the samples that reach it agree: where both faces' samples do (next
            // to a thin part's faced region that holds both), the sample waits.
            if (!reached || !(std::abs(vote) >= follow_consensus * weight))
                continue;
            if (vote < 0.0F)
            {
                normals[i] = -normals[i];
                turned.fetch_add(1, std::memory_order_relaxed);
            }
            std::atomic_ref<std::uint32_t>(stamp[i]).store(round, std::memory_order_relaxed);
            local = true;
        }
        return local;
    });
    return turned.load();
}

/// Whether the thin parts' facing (face_two_sheet_regions() and follow_faced_regions()), which
/// took the oriented normals from `before` to `after`, stands: not where it moves the winding
/// number of the oriented samples further from ½ on the samples by both measures of
/// winding_energy(). Two sheets a few noise deviations apart that face the same way (the lid of
/// a teapot resting in its body's opening) look to the facing as a thin solid with one face
/// oriented wrong: on two of nine simulated scans of the teapot (virtual_scan.py, seeds 31-39)
/// it turned the lid's rim, and the samples beside it followed round the body: 20% and 16% of
/// the normals inside out, 0.7% and 0.8% without the facing. At seed 31 the energies per query
/// rose from 0.011 fitted and 0.015 plain to 0.054 and 0.118. Where the facing is right, a
/// thin solid's far face goes from adding about −½ to the winding number at its near face's
/// samples (and they at its) to +½: on the bench's noisy thin plates, 0.25 fitted to 0.016-0.020
/// and 0.25 plain to 0.16-0.20.
bool facing_stands(std::span<const Vec3f> positions, const KnnTable& neighbors,
                   std::span<const Vec3f> before, std::span<const Vec3f> after)
{
    const WindingSamples samples = winding_samples(before);
    const WindingEnergy was = winding_energy_of(positions, neighbors, before, samples);
    const WindingEnergy now = winding_energy_of(positions, neighbors, after, samples);
    return !(now.fitted > was.fitted && now.plain > was.plain);
}

/// Steps 1 to 5 of orient_normals_mst() over the whole graph of `neighbors`: spanning forest,
/// patches, votes, sweeps, roots and flux. `guide` is empty for a clean cloud.
OrientedNormals orient_graph(std::span<const Vec3f> positions, std::span<const Vec3f> fine_normals,
                             const Guide& guide, const KnnTable& neighbors,
                             const OrientationOptions& options)
{
    const bool guided = !guide.normals.empty();
    const std::span<const Vec3f> normals =
        guided ? std::span<const Vec3f>(guide.normals) : fine_normals;
    const RiemannianForest forest = spanning_forest(positions, normals, guide, neighbors, options);
    const std::size_t n = positions.size();
    OrientedNormals result;
    result.normals.assign(normals.begin(), normals.end());
    result.components = forest.roots.size();

    // 1. Propagate along the trees, but only across reliable tree edges: they cut each tree into
    //    patches inside which every step is trustworthy. A patch's first sample keeps its sign.
    //    Each tree edge is judged in parallel, in the normals as they are: whether it joins v to
    //    its parent's patch, and the sign of their agreement. Flipping the parent negates the
    //    agreement exactly, so the walk in tree order only combines signs.
    enum Step : std::uint8_t
    {
        cut,       // v starts a patch
        agrees,    // joins; agreement > 0
        disagrees, // joins; agreement < 0
        neutral,   // joins; agreement 0 (or not a number): no flip either way
    };
    std::vector<std::uint8_t> step(n, cut);
    parallel_blocks(n, 4096, [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i)
        {
            const auto v = static_cast<std::uint32_t>(i);
            const std::uint32_t parent = forest.parent[v];
            const bool joins = parent != RiemannianForest::none && parent != v &&
                               usable(normals[v]) && usable(normals[parent]) &&
                               !guide.jumps(positions, neighbors, parent, v) &&
                               edge_cost(positions, normals, options.rule, parent, v) <=
                                   static_cast<float>(options.patch_cost);
            if (!joins)
                continue;
            const float a = agreement(positions, normals, options.rule, parent, v);
            step[v] = a < 0.0F ? disagrees : a > 0.0F ? agrees : neutral;
        }
    });
    std::vector<std::uint32_t> patch(n, RiemannianForest::none);
    std::uint32_t patch_count = 0;
    {
        std::vector<std::uint8_t> flipped(n, 0);
        for (const std::uint32_t v : forest.order)
        {
            if (step[v] == cut)
            {
                patch[v] = patch_count++;
                continue;
            }
            const std::uint32_t parent = forest.parent[v];
            patch[v] = patch[parent];
            if (step[v] == (flipped[parent] != 0 ? agrees : disagrees))
            {
                flipped[v] = 1;
                result.normals[v] = -result.normals[v];
            }
        }
    }
    std::vector<std::uint8_t>().swap(step);

    // 2. Patches vote on their relative orientation over every graph edge between them, and a
    //    maximum spanning forest of the patch graph (by the size of the vote) decides each
    //    patch's flip: many agreeing edges outweigh the single edge a tree happened to use.
    const std::size_t columns = graph_columns(options, neighbors);
    struct Vote
    {
        std::uint32_t a;
        std::uint32_t b;
        float weight;
    };
    //    Collected a block at a time in parallel, then joined in block order: the list (and so
    //    the sums below) is the one a single pass in sample order makes.
    constexpr std::size_t vote_block = 4096;
    std::vector<std::vector<Vote>> block_votes((n + vote_block - 1) / vote_block);
    parallel_blocks(n, vote_block, [&](std::size_t begin, std::size_t end) {
        std::vector<Vote>& out = block_votes[begin / vote_block];
        for (std::size_t i = begin; i < end; ++i)
        {
            const auto pi = patch[i];
            if (pi == RiemannianForest::none)
                continue;
            for (const std::uint32_t j : neighbors.neighbors(i).first(columns))
            {
                const auto pj = patch[j];
                if (pj == RiemannianForest::none || pj == pi ||
                    guide.jumps(positions, neighbors, static_cast<std::uint32_t>(i), j))
                    continue;
                const float w = agreement(positions, result.normals, options.rule,
                                          static_cast<std::uint32_t>(i), j);
                out.push_back({std::min(pi, pj), std::max(pi, pj), w});
            }
        }
    });
    std::vector<Vote> votes;
    {
        std::size_t total = 0;
        for (const std::vector<Vote>& part : block_votes)
            total += part.size();
        votes.reserve(total);
        for (std::vector<Vote>& part : block_votes)
        {
            votes.insert(votes.end(), part.begin(), part.end());
            std::vector<Vote>().swap(part);
        }
    }
    std::sort(votes.begin(), votes.end(),
              [](const Vote& x, const Vote& y) { return x.a != y.a ? x.a < y.a : x.b < y.b; });
    std::vector<Vote> patch_edges;
    for (std::size_t v = 0; v < votes.size();)
    {
        Vote sum = votes[v];
        double total = 0.0;
        for (; v < votes.size() && votes[v].a == sum.a && votes[v].b == sum.b; ++v)
            total += static_cast<double>(votes[v].weight);
        sum.weight = static_cast<float>(total);
        patch_edges.push_back(sum);
    }
    std::vector<Vote>().swap(votes);
    std::stable_sort(patch_edges.begin(), patch_edges.end(), [](const Vote& x, const Vote& y) {
        return std::abs(x.weight) > std::abs(y.weight);
    });
    DisjointSets patch_sets(patch_count);
    std::vector<std::uint32_t> patch_degree(patch_count + 1, 0);
    std::vector<Vote> patch_tree;
    for (const auto& e : patch_edges)
        if (patch_sets.unite(e.a, e.b))
        {
            patch_tree.push_back(e);
            ++patch_degree[e.a + 1];
            ++patch_degree[e.b + 1];
        }
    for (std::size_t p = 0; p < patch_count; ++p)
        patch_degree[p + 1] += patch_degree[p];
    std::vector<std::pair<std::uint32_t, bool>> patch_adjacent(patch_degree[patch_count]);
    {
        std::vector<std::uint32_t> fill(patch_degree.begin(), patch_degree.end() - 1);
        for (const auto& e : patch_tree)
        {
            patch_adjacent[fill[e.a]++] = {e.b, e.weight < 0.0F};
            patch_adjacent[fill[e.b]++] = {e.a, e.weight < 0.0F};
        }
    }
    // Walk each patch tree from the patch of its component's root, accumulating flips.
    constexpr std::uint8_t unvisited = 2;
    std::vector<std::uint8_t> patch_flip(patch_count, unvisited);
    std::vector<std::uint32_t> queue;
    for (const std::uint32_t root : forest.roots)
    {
        if (root == RiemannianForest::none || patch_flip[patch[root]] != unvisited)
            continue;
        patch_flip[patch[root]] = 0;
        queue.assign(1, patch[root]);
        for (std::size_t head = 0; head < queue.size(); ++head)
        {
            const std::uint32_t p = queue[head];
            for (std::uint32_t e = patch_degree[p]; e < patch_degree[p + 1]; ++e)
            {
                const auto [q, disagree] = patch_adjacent[e];
                if (patch_flip[q] != unvisited)
                    continue;
                patch_flip[q] = static_cast<std::uint8_t>(patch_flip[p] ^ (disagree ? 1U : 0U));
                queue.push_back(q);
            }
        }
    }
    for (std::size_t i = 0; i < n; ++i)
        if (patch[i] != RiemannianForest::none && patch_flip[patch[i]] == 1)
            result.normals[i] = -result.normals[i];
    //    A patch that no vote reached (each of its edges jumps between sheets: an outlier of the
    //    noise in the gap of a thin plate) takes the sign of its neighbours in reached patches.
    if (guided)
    {
        const auto reached = [&](std::size_t i) {
            return patch[i] != RiemannianForest::none && patch_flip[patch[i]] != unvisited;
        };
        std::vector<double> pull(patch_count, 0.0);
        for (std::size_t i = 0; i < n; ++i)
            if (patch[i] != RiemannianForest::none && !reached(i))
                for (const std::uint32_t j : neighbors.neighbors(i).first(columns))
                    if (reached(j))
                        pull[patch[i]] +=
                            static_cast<double>(agreement(positions, result.normals, options.rule,
                                                          static_cast<std::uint32_t>(i), j));
        for (std::size_t i = 0; i < n; ++i)
            if (patch[i] != RiemannianForest::none && !reached(i) && pull[patch[i]] < 0.0)
                result.normals[i] = -result.normals[i];
    }

    // 3. Each sample re-decides its sign by its neighbours: flip if n_i disagrees with
    //    m_i = Σ_j w_ij n_j over its k neighbours, w_ij = 1 − |n_i·ê_ij| (the edge's share in
    //    i's tangent plane, ~0 for a neighbour across a thin wall). Averaging cancels the
    //    neighbours' noise, so a poor normal takes the sign of its neighbourhood rather than of
    //    the one tree edge that reached it. Jacobi sweeps over a snapshot: deterministic.
    //    Guide normals need none: they are smooth already, and the sign of a poor normal
    //    comes from its guide below.
    //    After the first sweep only a sample with a neighbour flipped in the sweep before can
    //    flip: with the same neighbours, it would decide as it did then.
    const std::size_t sweeps = guided ? 0 : options.smoothing_sweeps;
    std::vector<std::uint8_t> changed(sweeps > 1 ? n : 0, 0);
    std::vector<std::uint8_t> changed_before;
    std::vector<Vec3f> snapshot;
    for (std::size_t sweep = 0; sweep < sweeps; ++sweep)
    {
        snapshot = result.normals;
        changed_before.swap(changed);
        changed.assign(sweep + 1 < sweeps ? n : 0, 0);
        parallel_blocks(n, 4096, [&](std::size_t begin, std::size_t end) {
            for (std::size_t i = begin; i < end; ++i)
            {
                const Vec3f& ni = snapshot[i];
                if (!usable(ni) || patch[i] == RiemannianForest::none)
                    continue;
                if (sweep > 0)
                {
                    bool affected = false;
                    for (const std::uint32_t j : neighbors.neighbors(i))
                        affected |= j != i && changed_before[j] != 0;
                    if (!affected)
                        continue;
                }
                Vec3f mean = Vec3f::Zero();
                for (const std::uint32_t j : neighbors.neighbors(i))
                {
                    if (j == i || !usable(snapshot[j]))
                        continue;
                    const Vec3f e = positions[j] - positions[i];
                    const float len2 = e.squaredNorm();
                    const float tangential =
                        len2 > 0.0F ? 1.0F - std::abs(ni.dot(e)) / std::sqrt(len2) : 1.0F;
                    mean += tangential * snapshot[j];
                }
                if (ni.dot(mean) < 0.0F)
                {
                    result.normals[i] = -ni;
                    if (!changed.empty())
                        changed[i] = 1;
                }
            }
        });
    }
    std::vector<Vec3f>().swap(snapshot);
    std::vector<std::uint8_t>().swap(changed);
    std::vector<std::uint8_t>().swap(changed_before);
    std::vector<std::uint32_t>().swap(patch);

    //    The oriented guides are the output where the sample has a normal of its own, after a
    //    vote of their neighbours on the same sheet (vote_normals()).
    std::vector<std::uint8_t> faced; // the samples of faced thin parts (TwoSheetFacing::faced_by)
    if (guided)
    {
        vote_normals(positions, neighbors, guide, result.normals);
        turn_regions_by_winding(positions, neighbors, guide, columns,
                                1.0F - static_cast<float>(options.patch_cost), result.normals);
        // Kept only where a thin part may be faced (some sample has a side).
        std::vector<Vec3f> before_facing;
        if (std::any_of(guide.side.begin(), guide.side.end(), [](std::int8_t v) { return v != 0; }))
            before_facing = result.normals;
        detail::TwoSheetFacing facing =
            detail::face_two_sheet_regions(neighbors, guide.normals, guide.side, result.normals);
        const std::size_t turned =
            facing.turned + follow_faced_regions(positions, neighbors, guide, columns,
                                                 facing.faced_by, result.normals);
        if (turned > 0 && !facing_stands(positions, neighbors, before_facing, result.normals))
            result.normals.swap(before_facing); // no thin part faced
        else
        {
            result.thin_parts = facing.faced;
            result.thin_part_turned = turned;
            faced.swap(facing.faced_by);
        }
        for (std::size_t i = 0; i < n; ++i)
            result.normals[i] = usable(fine_normals[i]) ? result.normals[i] : fine_normals[i];
    }

    // 4. Samples without a normal of their own take their tree parent's; each component's root
    //    then faces +z.
    for (const std::uint32_t v : forest.order)
    {
        const std::uint32_t parent = forest.parent[v];
        if (parent != v && !usable(result.normals[v]))
        {
            result.normals[v] = result.normals[parent];
            ++result.inherited;
        }
    }
    face_components(
        positions, neighbors, [&](std::size_t i) { return forest.component[i]; }, forest.roots,
        result.normals, faced);
    for (std::size_t i = 0; i < n; ++i)
        if (forest.parent[i] == RiemannianForest::none)
        {
            result.normals[i].setZero();
            result.unoriented.push_back(static_cast<std::uint32_t>(i));
        }
    result.flipped = count_flipped(fine_normals, result.normals);
    return result;
}

/// Clouds smaller than this are oriented over their whole graph (OrientationOptions::patches).
constexpr std::size_t min_patched = 2048;
/// Samples in a block of orient_by_patches(), in index order: one thread finds a block's patches
/// (spatially sorted samples, as compute_surfels() has them, make a block a compact piece of
/// surface). Fixed, so that the result does not depend on the thread count.
constexpr std::size_t patch_block = 4096;
/// Agreement |n_a·n_b| from which an edge joins its ends' patches in a block's first pass (normals
/// within about 18°); the other reliable edges (up to OrientationOptions::patch_cost) join after
/// them, so that a patch grows over the smoothest steps first, as a spanning tree would.
constexpr float firm_agreement = 0.95F;
/// The samples that vote in pairs across a creased sample of orient_by_patches(), nearest
/// first (at most this many, so that a large k does not square the cost).
constexpr std::size_t hop_ends = 16;
/// An edge passes no orientation when it leaves both ends' tangent planes more steeply (|n·ê|)
/// than this plus the sine of half the angle between their normals: along one smooth sheet an
/// edge tilts by about half the turn of the normals, while an edge across a thin part (the two
/// sides of a bunny's ear, or of a plate a few sampling steps thick) joins parallel normals at a
/// steep angle, and Hoppe's rule would hand one side's orientation to the other unchanged.
constexpr float steep_edge = 0.3F;

/// Whether the edge a–b leaves the sheet (see steep_edge).
bool off_sheet(const Vec3f& pa, const Vec3f& na, const Vec3f& pb, const Vec3f& nb)
{
    const Vec3f e = pb - pa;
    const float len2 = e.squaredNorm();
    const float da = na.dot(e);
    const float db = nb.dot(e);
    // Most edges lie in both tangent planes: no root needed to tell.
    if (da * da <= steep_edge * steep_edge * len2 || db * db <= steep_edge * steep_edge * len2)
        return false;
    const float length = std::sqrt(len2);
    const float half_turn = std::sqrt(std::max(0.0F, 0.5F * (1.0F - std::abs(na.dot(nb)))));
    const float limit = (half_turn + steep_edge) * length;
    return std::abs(da) > limit && std::abs(db) > limit;
}

/// Disjoint sets whose members carry a sign relative to their set's representative: uniting a
/// and b says whether a's sign is b's or the opposite.
class SignedSets
{
public:
    void reset(std::size_t n)
    {
        parent_.resize(n);
        std::iota(parent_.begin(), parent_.end(), 0U);
        odd_.assign(n, 0);
        size_.assign(n, 1);
    }

    /// x's representative and whether x's sign is the opposite of it.
    std::pair<std::uint32_t, std::uint8_t> find(std::uint32_t x)
    {
        std::uint32_t root = x;
        std::uint8_t odd = 0;
        while (parent_[root] != root)
        {
            odd ^= odd_[root];
            root = parent_[root];
        }
        // Path compression: every member on the way points at the root with its own sign.
        std::uint8_t left = odd;
        while (parent_[x] != root)
        {
            const std::uint32_t next = parent_[x];
            const std::uint8_t step = odd_[x];
            parent_[x] = root;
            odd_[x] = left;
            left ^= step;
            x = next;
        }
        return {root, odd};
    }

    /// Joins the sets of representatives ra and rb (of members a and b, whose signs against them
    /// are oa and ob) so that b's sign is the opposite of a's when `opposite`. Returns the joined
    /// set's representative and a's sign against it.
    std::pair<std::uint32_t, std::uint8_t> link(std::uint32_t ra, std::uint8_t oa, std::uint32_t rb,
                                                std::uint8_t ob, bool opposite)
    {
        const auto odd = static_cast<std::uint8_t>(oa ^ ob ^ (opposite ? 1U : 0U));
        if (size_[ra] < size_[rb])
        {
            parent_[ra] = rb;
            odd_[ra] = odd;
            size_[rb] += size_[ra];
            return {rb, static_cast<std::uint8_t>(oa ^ odd)};
        }
        parent_[rb] = ra;
        odd_[rb] = odd;
        size_[ra] += size_[rb];
        return {ra, oa};
    }

private:
    std::vector<std::uint32_t> parent_;
    std::vector<std::uint8_t> odd_;
    std::vector<std::uint32_t> size_;
};

/// Whether Hoppe's rule can be trusted on the edge a–b: the normals are within a reliable step
/// (|n_a·n_b| at least `reliable`) and the reflection rule (OrientationRule::Reflection) orients
/// b the same way. Not across a crease, where Hoppe's agreement fades to nothing at a right
/// angle and changes sign beyond it (at a cone's rim, where a flat base meets a side at 76°,
/// every edge across voted to turn one face inside out, while the reflected normal follows the
/// turn), nor across a thin part (a knife edge), where the two sides' normals are nearly
/// parallel as lines and the edge is steep to both. `reflected`, unless null, gets the
/// reflection rule's agreement.
bool hoppe_trusted(const Vec3f& pa, const Vec3f& na, const Vec3f& pb, const Vec3f& nb,
                   float reliable, float* reflected = nullptr)
{
    const float hoppe = na.dot(nb);
    if (reflected == nullptr)
    {
        if (!(std::abs(hoppe) >= reliable))
            return false;
        // The reflection rule's agreement is hoppe − 2 (n_a·e)(n_b·e) / |e|²: where the second
        // term is at most half the first, its sign is Hoppe's whatever the rounding, and the
        // division is not needed (most edges of a clean cloud lie in both tangent planes).
        const Vec3f e = pb - pa;
        const float len2 = e.squaredNorm();
        if (4.0F * std::abs(na.dot(e) * nb.dot(e)) <= std::abs(hoppe) * len2)
            return true;
    }
    const float reflection = agreement_of(pa, na, pb, nb, OrientationRule::Reflection);
    if (reflected != nullptr)
        *reflected = reflection;
    return std::abs(hoppe) >= reliable && (hoppe < 0.0F) == (reflection < 0.0F);
}

/// The vote of a graph edge a–b between two patches on their relative orientation (> 0: the
/// same), with the patches' signed normals: none for an edge off the sheet (off_sheet()), Hoppe's
/// n_a·n_b where hoppe_trusted(), the reflection rule's otherwise.
float crossing_vote(const Vec3f& pa, const Vec3f& na, const Vec3f& pb, const Vec3f& nb,
                    float reliable)
{
    if (off_sheet(pa, na, pb, nb))
        return 0.0F;
    float reflected = 0.0F;
    return hoppe_trusted(pa, na, pb, nb, reliable, &reflected) ? na.dot(nb) : reflected;
}

/// The vote of samples a and b on either side of a crease or a thin part on their relative
/// orientation (> 0: the same), with the patches' signed normals, by the tilt rule alone,
/// −(n_a·ê)(n_b·ê): at a convex crease each sample lies on the inner side of the other's
/// tangent plane, at a concave one on the outer side, and across a thin part each faces the
/// other, so the two tilts have opposite signs when the normals agree. Unlike the reflection
/// rule it holds for samples at unequal distances from a crease (at a rim of 42° the reflected
/// normal turns the wrong way once one sample is about 2.5 times as far from it as the other),
/// and unlike Hoppe's rule across a thin part, whose faces' normals agree as lines even for a
/// pair far apart along it (taking Hoppe's n_a·n_b where hoppe_trusted() turned a face of a
/// plate two sampling steps thick over again).
float across_vote(const Vec3f& pa, const Vec3f& na, const Vec3f& pb, const Vec3f& nb)
{
    const Vec3f e = pb - pa;
    const float len2 = e.squaredNorm();
    return len2 > 0.0F ? -na.dot(e) * nb.dot(e) / len2 : 0.0F;
}

/// orient_normals_mst() for clean clouds under Hoppe's rule (noisy clouds keep the guided whole
/// graph, orient_graph()): patches of consistently oriented samples, found block by block, are
/// oriented against each other, and the signs spread to every sample.
///
/// 1. Patches: in each block of patch_block samples (index order), the graph edges inside the
///    block that are reliable (|n_a·n_b| at least 1 − patch_cost), on the sheet (steep_edge) and
///    between samples that are not creased (every edge to a neighbour in the block
///    hoppe_trusted(), and no two such neighbours more than a reliable step apart), nor next
///    to a creased one, join their ends in signed disjoint sets, firm edges (firm_agreement)
///    first: a patch's samples take their signs relative to its first sample from the edges
///    that joined them.
/// 2. Every graph edge between two patches votes on their relative orientation
///    (crossing_vote(): Hoppe's agreement where hoppe_trusted(), the reflection rule's across a
///    crease or a thin part; an edge off the sheet with none: it keeps the components whole but
///    passes nothing), and so does every pair of samples in different patches across a
///    creased sample (across_vote()), summed per pair of patches, and a maximum
///    spanning forest of the patch graph (by the size of the vote) decides each patch's flip, as
///    orient_graph() does with its patches.
/// 3. Each component then faces +z at its highest sample and outwards by its flux; samples
///    without a normal inherit one over the graph's edges. (A sweep in which every sample
///    followed its neighbours changed no sign on the test shapes, the bunny scans or the 1M and
///    10M blobby, so there is none.)
///
/// Blocks are fixed and every sum is taken in block order: the result does not depend on the
/// thread count. On the clean test shapes and the bunny the signs are the whole graph's but for a
/// few samples at a thin plate's corners.
OrientedNormals orient_by_patches(std::span<const Vec3f> positions, std::span<const Vec3f> normals,
                                  const KnnTable& neighbors, const OrientationOptions& options)
{
    const std::size_t n = positions.size();
    const std::size_t columns = graph_columns(options, neighbors);
    constexpr std::size_t block = 8192;
    constexpr std::uint32_t none = RiemannianForest::none;
    const float reliable = 1.0F - static_cast<float>(options.patch_cost);
    const float firm = std::max(reliable, firm_agreement);

    // 1. Each block's patches: every sample's patch (numbered in the block first) and whether
    //    its sign is the opposite of its patch's first sample's.
    const std::size_t blocks = (n + patch_block - 1) / patch_block;
    //    Written in full by the blocks (in parallel, so the pages are touched where they are
    //    used), hence not filled first.
    const auto patch = std::make_unique_for_overwrite<std::uint32_t[]>(n);
    auto opposite = std::make_unique_for_overwrite<std::uint8_t[]>(n);
    //    Whether a sample is creased (1), next to a creased one in its block (2) or neither (0),
    //    each block writing its own samples.
    std::vector<std::uint8_t> creased(n, 0);
    std::vector<std::uint32_t> block_start(blocks + 1, 0);
    //    Each block also keeps the edges that may join two patches (those leaving the block,
    //    the unreliable ones and those off the sheet), for the votes: edge i * columns + c of
    //    the block is column c of its sample i.
    std::vector<std::vector<std::uint32_t>> crossing(blocks);
    //    (Reported as the blocks' patches are made, the bulk of the work.)
    ProgressReporter progress(options.progress, "orientation");
    parallel_blocks(
        blocks, 1,
        [&](std::size_t first, std::size_t last) {
            SignedSets sets;
            std::vector<std::uint32_t> later;
            std::vector<std::uint32_t> local_id(patch_block);
            for (std::size_t b = first; b < last; ++b)
            {
                const std::size_t begin = b * patch_block;
                const std::size_t end = std::min(n, begin + patch_block);
                sets.reset(end - begin);
                later.clear();
                auto& open = crossing[b];
                //    Joins i (whose set and sign are root and odd) and its column c, j.
                const auto join = [&](std::size_t i, std::size_t c, std::uint32_t j,
                                      std::pair<std::uint32_t, std::uint8_t>& own) {
                    const auto edge = static_cast<std::uint32_t>((i - begin) * columns + c);
                    const auto [rj, oj] = sets.find(static_cast<std::uint32_t>(j - begin));
                    if (rj == own.first)
                        return;
                    if (off_sheet(positions[i], normals[i], positions[j], normals[j]))
                        open.push_back(edge);
                    else
                        own = sets.link(own.first, own.second, rj, oj,
                                        normals[i].dot(normals[j]) < 0.0F);
                };
                //    Creased samples: Hoppe's rule is not trusted (hoppe_trusted()) on the edge to
                //    some neighbour in the block (a normal more than a reliable step away, or the
                //    other side of a knife edge or a thin part). They join no patch: near a crease
                //    the estimated normals turn from one face's to the other's the short way round
                //    as lines, which at a crease sharper than 90° is the wrong way, and a chain of
                //    reliable steps through them would join the two faces with one turned over.
                //    A sample is creased too where two of its neighbours in the block are more than
                //    a reliable step apart (its neighbourhood spans the turn, in steps each small
                //    enough to pass: the head of an arrow, whose rim turns by 124°, was joined to
                //    its shaft inside out, 73% of the samples). (Only the block's own samples can
                //    chain within it, so only its own edges are looked at.)
                bool any_creased = false;
                //    Whether j is a neighbour of i in the block with a normal.
                const auto in_block = [&](std::size_t i, std::uint32_t j) {
                    return j >= begin && j < end && j != i && usable(normals[j]);
                };
                for (std::size_t i = begin; i < end; ++i)
                {
                    if (!usable(normals[i]))
                        continue;
                    const auto row = neighbors.neighbors(i).first(columns);
                    float farthest = 1.0F;
                    std::uint32_t apart = none;
                    for (const std::uint32_t j : row)
                    {
                        if (!in_block(i, j))
                            continue;
                        if (!hoppe_trusted(positions[i], normals[i], positions[j], normals[j],
                                           reliable))
                        {
                            creased[i] = 1;
                            creased[j] = 1;
                            any_creased = true;
                            apart = none;
                            break;
                        }
                        const float agree = std::abs(normals[i].dot(normals[j]));
                        if (agree < farthest)
                        {
                            farthest = agree;
                            apart = j;
                        }
                    }
                    //    The neighbour farthest from i against the others (unless all are within a
                    //    firm step of i, and so of each other within a reliable one).
                    if (apart != none && farthest < firm)
                        for (const std::uint32_t j : row)
                        {
                            if (in_block(i, j) &&
                                std::abs(normals[apart].dot(normals[j])) < reliable)
                            {
                                creased[i] = 1;
                                any_creased = true;
                                break;
                            }
                        }
                }
                //    And the samples next to a creased one in the block (marked 2): the blend of a
                //    crease's normals is wider than the neighbourhoods that find it, and a patch
                //    chained past it through samples each within a reliable step turned the base
                //    of a cone as wide as high over (41% of the samples inside out).
                for (std::size_t i = begin; i < end && any_creased; ++i)
                    if (creased[i] == 0)
                        for (const std::uint32_t j : neighbors.neighbors(i).first(columns))
                            if (j >= begin && j < end && creased[j] == 1)
                            {
                                creased[i] = 2;
                                break;
                            }
                for (std::size_t i = begin; i < end; ++i)
                {
                    if (!usable(normals[i]))
                        continue;
                    auto own = sets.find(static_cast<std::uint32_t>(i - begin));
                    const auto row = neighbors.neighbors(i).first(columns);
                    for (std::size_t c = 0; c < columns; ++c)
                    {
                        const std::uint32_t j = row[c];
                        if (j == i)
                            continue;
                        const auto edge = static_cast<std::uint32_t>((i - begin) * columns + c);
                        if (j < begin || j >= end)
                        {
                            open.push_back(edge);
                            continue;
                        }
                        if (!usable(normals[j]))
                            continue;
                        if (creased[i] != 0 || creased[j] != 0)
                        {
                            open.push_back(edge);
                            continue;
                        }
                        const float agree = std::abs(normals[i].dot(normals[j]));
                        if (agree >= firm)
                            join(i, c, j, own);
                        else if (agree >= reliable)
                            later.push_back(edge);
                        else
                            open.push_back(edge);
                    }
                }
                for (const std::uint32_t edge : later)
                {
                    const std::size_t i = begin + edge / columns;
                    auto own = sets.find(static_cast<std::uint32_t>(i - begin));
                    join(i, edge % columns, neighbors.neighbors(i)[edge % columns], own);
                }
                std::uint32_t count = 0;
                for (std::size_t i = begin; i < end; ++i)
                    if (usable(normals[i]) &&
                        sets.find(static_cast<std::uint32_t>(i - begin)).first == i - begin)
                        local_id[i - begin] = count++;
                for (std::size_t i = begin; i < end; ++i)
                {
                    patch[i] = none;
                    opposite[i] = 0;
                    if (!usable(normals[i]))
                        continue;
                    const auto [root, odd] = sets.find(static_cast<std::uint32_t>(i - begin));
                    patch[i] = local_id[root];
                    opposite[i] = odd;
                }
                block_start[b + 1] = count;
            }
        },
        &progress);
    progress.finish();
    for (std::size_t b = 0; b < blocks; ++b)
        block_start[b + 1] += block_start[b];
    const std::size_t patch_count = block_start[blocks];
    parallel_blocks(n, block, [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i)
            if (patch[i] != none)
                patch[i] += block_start[i / patch_block];
    });
    const auto signed_normal = [&](std::uint32_t i) {
        return opposite[i] != 0 ? Vec3f(-normals[i]) : normals[i];
    };

    // 2. The votes of the edges between patches, summed per pair in each block in edge order,
    //    then over the blocks in block order.
    struct Vote
    {
        std::uint64_t pair; // lower patch << 32 | higher patch
        double weight;
    };
    std::vector<std::vector<Vote>> block_votes(blocks);
    parallel_blocks(blocks, 1, [&](std::size_t first, std::size_t last) {
        // A block's first few pairs are summed in place (a compact block touches about ten);
        // the pairs of a scattered one (samples not in spatial order) are sorted at the end.
        constexpr std::size_t searched = 64;
        std::vector<std::pair<std::uint64_t, float>> rest;
        std::vector<std::uint32_t> ends;
        for (std::size_t b = first; b < last; ++b)
        {
            rest.clear();
            auto& out = block_votes[b];
            std::size_t hit = 0;
            const std::size_t begin = b * patch_block;
            //    Adds the vote of samples a and c, of different patches, on their patches (by
            //    crossing_vote(), or by across_vote() for a pair across a creased sample).
            const auto vote = [&](std::uint32_t a, std::uint32_t c, bool across) {
                const std::uint32_t pa = patch[a];
                const std::uint32_t pc = patch[c];
                const float weight = across
                                         ? across_vote(positions[a], signed_normal(a), positions[c],
                                                       signed_normal(c))
                                         : crossing_vote(positions[a], signed_normal(a),
                                                         positions[c], signed_normal(c), reliable);
                const std::uint64_t pair =
                    (std::uint64_t{std::min(pa, pc)} << 32U) | std::max(pa, pc);
                if (hit >= out.size() || out[hit].pair != pair)
                    hit = static_cast<std::size_t>(
                        std::find_if(out.begin(), out.end(),
                                     [&](const Vote& v) { return v.pair == pair; }) -
                        out.begin());
                if (hit < out.size())
                    out[hit].weight += static_cast<double>(weight);
                else if (out.size() < searched)
                    out.push_back({pair, static_cast<double>(weight)});
                else
                    rest.emplace_back(pair, weight);
            };
            for (const std::uint32_t edge : crossing[b])
            {
                const std::size_t i = begin + edge / columns;
                const std::uint32_t j = neighbors.neighbors(i)[edge % columns];
                if (patch[i] == none || patch[j] == none || patch[j] == patch[i])
                    continue;
                vote(static_cast<std::uint32_t>(i), j, false);
            }
            std::vector<std::uint32_t>().swap(crossing[b]);
            //    Across each creased sample, every two of the samples that are not creased or
            //    next to a creased one among its neighbours (and, for a creased sample, its
            //    neighbours' of those next to one) that lie in different patches vote by
            //    across_vote(), at most hop_ends of them: the creased samples' own normals are
            //    the blend of a crease's two faces, turned the short way round, so a vote
            //    through them alone would turn one face over (a cone whose base meets its side
            //    at 45°: 41% of it inside out), while a pair across the crease votes by the
            //    faces' own normals. (The ring next to the creased samples would leave no pairs
            //    across them without its neighbours.)
            const std::size_t end = std::min(n, begin + patch_block);
            for (std::size_t i = begin; i < end; ++i)
            {
                if (creased[i] == 0)
                    continue;
                ends.clear();
                const auto add = [&](std::uint32_t j) {
                    if (j != i && patch[j] != none && creased[j] == 0 && ends.size() < hop_ends &&
                        std::find(ends.begin(), ends.end(), j) == ends.end())
                        ends.push_back(j);
                };
                for (const std::uint32_t j : neighbors.neighbors(i).first(columns))
                    add(j);
                if (creased[i] == 1)
                    for (const std::uint32_t j : neighbors.neighbors(i).first(columns))
                        if (creased[j] == 2)
                            for (const std::uint32_t q : neighbors.neighbors(j).first(columns))
                                add(q);
                for (std::size_t x = 0; x < ends.size(); ++x)
                    for (std::size_t y = x + 1; y < ends.size(); ++y)
                        if (patch[ends[x]] != patch[ends[y]])
                            vote(ends[x], ends[y], true);
            }
            std::sort(rest.begin(), rest.end());
            for (std::size_t v = 0; v < rest.size();)
            {
                Vote sum{rest[v].first, 0.0};
                for (; v < rest.size() && rest[v].first == sum.pair; ++v)
                    sum.weight += static_cast<double>(rest[v].second);
                out.push_back(sum);
            }
        }
    });
    std::vector<Vote> votes;
    for (auto& own : block_votes)
    {
        votes.insert(votes.end(), own.begin(), own.end());
        std::vector<Vote>().swap(own);
    }
    std::stable_sort(votes.begin(), votes.end(),
                     [](const Vote& x, const Vote& y) { return x.pair < y.pair; });
    std::vector<Vote> patch_edges;
    for (std::size_t v = 0; v < votes.size();)
    {
        Vote sum{votes[v].pair, 0.0};
        for (; v < votes.size() && votes[v].pair == sum.pair; ++v)
            sum.weight += votes[v].weight;
        patch_edges.push_back(sum);
    }
    std::vector<Vote>().swap(votes);
    //    The maximum spanning forest of the patch graph by the size of the votes, walked from
    //    each component's lowest patch.
    std::stable_sort(patch_edges.begin(), patch_edges.end(), [](const Vote& x, const Vote& y) {
        return std::abs(x.weight) > std::abs(y.weight);
    });
    const auto ends = [](const Vote& e) {
        return std::pair<std::uint32_t, std::uint32_t>(static_cast<std::uint32_t>(e.pair >> 32U),
                                                       static_cast<std::uint32_t>(e.pair));
    };
    std::vector<std::uint32_t> degree(patch_count + 1, 0);
    std::vector<Vote> tree;
    {
        DisjointSets sets(patch_count);
        for (const Vote& e : patch_edges)
        {
            const auto [a, b] = ends(e);
            if (sets.unite(a, b))
            {
                tree.push_back(e);
                ++degree[a + 1];
                ++degree[b + 1];
            }
        }
    }
    std::vector<Vote>().swap(patch_edges);
    for (std::size_t p = 0; p < patch_count; ++p)
        degree[p + 1] += degree[p];
    std::vector<std::pair<std::uint32_t, bool>> adjacent(degree[patch_count]);
    {
        std::vector<std::uint32_t> fill(degree.begin(), degree.end() - 1);
        for (const Vote& e : tree)
        {
            const auto [a, b] = ends(e);
            adjacent[fill[a]++] = {b, e.weight < 0.0};
            adjacent[fill[b]++] = {a, e.weight < 0.0};
        }
    }
    std::vector<std::uint8_t> patch_flip(patch_count, 0);
    std::vector<std::uint32_t> patch_component(patch_count, none);
    std::size_t components = 0;
    {
        std::vector<std::uint32_t> queue;
        for (std::uint32_t start = 0; start < patch_count; ++start)
        {
            if (patch_component[start] != none)
                continue;
            const auto c = static_cast<std::uint32_t>(components++);
            patch_component[start] = c;
            queue.assign(1, start);
            for (std::size_t head = 0; head < queue.size(); ++head)
            {
                const std::uint32_t p = queue[head];
                for (std::uint32_t e = degree[p]; e < degree[p + 1]; ++e)
                {
                    const auto [q, disagree] = adjacent[e];
                    if (patch_component[q] != none)
                        continue;
                    patch_component[q] = c;
                    patch_flip[q] = static_cast<std::uint8_t>(patch_flip[p] ^ (disagree ? 1U : 0U));
                    queue.push_back(q);
                }
            }
        }
    }

    OrientedNormals result;
    result.components = components;
    result.normals.resize(n); // every entry written below, in parallel
    std::atomic<std::size_t> undecided{0};
    parallel_blocks(n, block, [&](std::size_t begin, std::size_t end) {
        std::size_t left = 0;
        for (std::size_t i = begin; i < end; ++i)
        {
            const std::uint32_t p = patch[i];
            if (p == none)
            {
                result.normals[i] = Vec3f::Zero();
                ++left;
                continue;
            }
            result.normals[i] =
                (opposite[i] ^ patch_flip[p]) != 0 ? Vec3f(-normals[i]) : normals[i];
        }
        undecided.fetch_add(left, std::memory_order_relaxed);
    });
    std::vector<std::uint8_t>().swap(patch_flip);
    opposite.reset();

    // 3. Each component faces +z at its highest sample, then outwards by its flux.
    const auto component_of = [&](std::size_t i) {
        return patch[i] == none ? none : patch_component[patch[i]];
    };
    face_components(positions, neighbors, component_of,
                    highest_samples(positions, component_of, components), result.normals);
    std::vector<std::uint32_t>().swap(patch_component);
    result.flipped = count_flipped(normals, result.normals);
    if (undecided.load() == 0)
        return result;
    //    Samples without a normal take their nearest decided neighbour's over the graph's edges
    //    either way, round by round: a sample's own row first (nearest first), else the
    //    lowest-numbered decided sample that lists it.
    constexpr std::uint32_t not_yet = 0xFFFFFFFFU;
    std::vector<std::uint32_t> stamp(n);
    parallel_blocks(n, block, [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i)
            stamp[i] = patch[i] == none ? not_yet : 0;
    });
    const auto decided_before = [&](std::uint32_t j, std::uint32_t round) {
        return std::atomic_ref<std::uint32_t>(stamp[j]).load(std::memory_order_relaxed) < round;
    };
    const auto decide = [&](std::size_t i, std::uint32_t round) {
        std::atomic_ref<std::uint32_t>(stamp[i]).store(round, std::memory_order_relaxed);
    };
    std::vector<std::uint8_t> inherited(n, 0);
    std::vector<std::uint32_t> offer(n, not_yet);
    for (std::uint32_t round = 1;; ++round)
    {
        std::atomic<bool> open{false};
        parallel_blocks(n, block, [&](std::size_t begin, std::size_t end) {
            bool local = false;
            for (std::size_t j = begin; j < end; ++j)
            {
                if (!decided_before(static_cast<std::uint32_t>(j), round) ||
                    !usable(result.normals[j]))
                {
                    local |= stamp[j] == not_yet;
                    continue;
                }
                for (const std::uint32_t i : neighbors.neighbors(j).first(columns))
                    if (std::atomic_ref<std::uint32_t>(stamp[i]).load(std::memory_order_relaxed) ==
                        not_yet)
                        detail::lower_atomically(offer[i], static_cast<std::uint32_t>(j));
            }
            if (local)
                open.store(true, std::memory_order_relaxed);
        });
        if (!open.load())
            break;
        std::atomic<bool> progressed{false};
        parallel_blocks(n, block, [&](std::size_t begin, std::size_t end) {
            bool local = false;
            for (std::size_t i = begin; i < end; ++i)
            {
                if (stamp[i] != not_yet)
                    continue;
                std::uint32_t from = offer[i];
                for (const std::uint32_t j : neighbors.neighbors(i).first(columns))
                    if (j != i && decided_before(j, round) && usable(result.normals[j]))
                    {
                        from = j;
                        break;
                    }
                if (from == not_yet)
                    continue;
                result.normals[i] = result.normals[from];
                inherited[i] = 1;
                decide(i, round);
                local = true;
            }
            if (local)
                progressed.store(true, std::memory_order_relaxed);
        });
        if (!progressed.load())
            break;
    }
    for (std::size_t i = 0; i < n; ++i)
    {
        result.inherited += inherited[i];
        if (stamp[i] == not_yet)
            result.unoriented.push_back(static_cast<std::uint32_t>(i));
    }
    //    The samples left are components of their own, without a usable normal.
    if (!result.unoriented.empty())
    {
        std::vector<std::uint32_t> local(n, not_yet);
        for (std::size_t u = 0; u < result.unoriented.size(); ++u)
            local[result.unoriented[u]] = static_cast<std::uint32_t>(u);
        DisjointSets groups(result.unoriented.size());
        std::size_t count = result.unoriented.size();
        for (std::size_t u = 0; u < result.unoriented.size(); ++u)
            for (const std::uint32_t j : neighbors.neighbors(result.unoriented[u]).first(columns))
                if (local[j] != not_yet && groups.unite(u, local[j]))
                    --count;
        result.components += count;
    }
    return result;
}

} // namespace

OrientedNormals orient_normals_mst(std::span<const Vec3f> positions,
                                   std::span<const Vec3f> fine_normals, const KnnTable& neighbors,
                                   const OrientationOptions& options)
{
    check_sizes(positions, fine_normals, neighbors);
    check_knn_table(neighbors, positions.size(), positions.size(), "orientation");
    return detail::orient_checked_table(positions, fine_normals, neighbors, options);
}

OrientedNormals detail::orient_checked_table(std::span<const Vec3f> positions,
                                             std::span<const Vec3f> fine_normals,
                                             const KnnTable& neighbors,
                                             const OrientationOptions& options)
{
    check_sizes(positions, fine_normals, neighbors);
    return orient_with_guide(positions, fine_normals, neighbors, options,
                             grow_guide(positions, neighbors, options));
}

Guide detail::grow_guide(std::span<const Vec3f> positions, const KnnTable& neighbors,
                         const OrientationOptions& options, std::span<Vec3f> scratch)
{
    // On noisy clouds, orientation follows normals at a coarser scale and hands their signs to
    // the samples' own normals at the end. Edges that jump between sheets (Guide::jumps()) pass
    // no orientation.
    if (options.rule != OrientationRule::Hoppe || options.guide_rings == 0 || positions.empty())
        return {};
    return guide_normals(positions, neighbors, options.guide_rings, options.guide_most_rings,
                         scratch);
}

OrientedNormals detail::orient_with_guide(std::span<const Vec3f> positions,
                                          std::span<const Vec3f> fine_normals,
                                          const KnnTable& neighbors,
                                          const OrientationOptions& options, Guide guide)
{
    check_sizes(positions, fine_normals, neighbors);
    finish_guide(positions, fine_normals, neighbors, guide);
    if (options.patches && options.rule == OrientationRule::Hoppe && guide.normals.empty() &&
        positions.size() >= min_patched)
        return orient_by_patches(positions, fine_normals, neighbors, options);
    return orient_graph(positions, fine_normals, guide, neighbors, options);
}

OrientedNormals orient_normals_towards(std::span<const Vec3f> positions,
                                       std::span<const Vec3f> normals, const Vec3d& viewpoint)
{
    if (normals.size() != positions.size())
        throw InvalidInput("orient_normals_towards: sizes of points and normals differ");
    if (!viewpoint.allFinite())
        throw InvalidInput("orient_normals_towards: viewpoint must be finite");
    OrientedNormals result;
    result.normals.assign(normals.begin(), normals.end());
    for (std::size_t i = 0; i < positions.size(); ++i)
    {
        const Vec3d to_view = viewpoint - positions[i].cast<double>();
        if (result.normals[i].cast<double>().dot(to_view) < 0.0)
            result.normals[i] = -result.normals[i];
    }
    result.flipped = count_flipped(normals, result.normals);
    return result;
}

OrientedNormals orient_normals_along(std::span<const Vec3f> normals, const Vec3d& direction)
{
    if (!direction.allFinite() || direction.squaredNorm() == 0.0)
        throw InvalidInput("orient_normals_along: direction must be finite and non-zero");
    OrientedNormals result;
    result.normals.assign(normals.begin(), normals.end());
    for (auto& n : result.normals)
        if (n.cast<double>().dot(direction) < 0.0)
            n = -n;
    result.flipped = count_flipped(normals, result.normals);
    return result;
}

OrientedNormals flip_normals(std::span<const Vec3f> normals)
{
    OrientedNormals result;
    result.normals.reserve(normals.size());
    for (const auto& n : normals)
        result.normals.emplace_back(-n);
    result.flipped = normals.size();
    return result;
}

} // namespace pointform
