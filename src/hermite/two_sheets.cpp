// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "two_sheets.h"

#include "pointform/core/disjoint_sets.h"
#include "pointform/core/parallel.h"
#include "pointform/spatial/kd_tree.h"

#include "orientation_detail.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>
#include <optional>

namespace pointform::detail {
namespace {

/// Samples (consecutive in index order) whose offsets are pooled: at least this many lie behind
/// each sample's kurtosis (its own block's and its neighbours' blocks').
constexpr std::size_t pooled_block = 512;
/// The kurtosis of the pooled offsets up to which a sample lies in two bands for certain.
/// Measured (`pointform sample`, 100k samples, noise 0.2% of the diagonal, 8 holes; pooled over
/// blocks of 512): 2.66-3.2 at the 0.1st percentile on noisy spheres, cones, CAD-like parts and
/// plates 0.04 and 0.05 thick, 2.8-3.0 on simulated scans of CAD parts, 2.84 on the shipped
/// LiDAR tile and 2.44 on the PCL stereo scene of a mug (its depths come in layers); 1.77-2.33
/// (0.1st to 99.9th) on a plate 0.02 thick (faces 3.5 deviations apart), median 2.06 at 0.03
/// (5 deviations). A normal distribution scores 3, two bands d deviations apart
/// (3 + 3 d²/2 + d⁴/16) / (1 + d²/4)²: 1.87 at d = 3.5.
constexpr float certain_kurtosis = 2.2F;
/// Samples connected through the neighbour table to such samples lie in the same two bands up
/// to this kurtosis (where the bands part, at a thin plate's rims and holes, the test is weaker):
/// the plate 0.03 thick, Chamfer 0.274% of the diagonal (only the certain ones) -> 0.16.
constexpr float likely_kurtosis = 2.5F;
/// A region is oriented by its bands when this many of its samples are certain (by their
/// kurtosis or from a ball, ball_sides())...
constexpr std::size_t min_certain = 64;
/// ... and at least this share of them. Where the offsets are one band, a few blocks still pool
/// to a low kurtosis by chance, and the sides they give are the offsets' signs, which say
/// nothing: at 1M samples (the widest guide neighbourhood leans to the sample's own face) a plate
/// 0.04 thick had regions of 7,600-14,300 samples, 0-5.7% of them certain, and facing them left
/// 5.16% of its normals facing away (0.23% with this share; 0.05% once the balls, made of a
/// subsample, found the plate). Plates at 100k whose faces noise joins: 36% certain (0.015
/// thick, by their kurtosis alone; the balls do not dip) to 100% (0.035).
constexpr double min_certain_share = 0.15;
/// A region is undecided when its normals facing away from its mid-surface outnumber those facing
/// towards it, or the other way round, by less than this share of its samples: where
/// orientation gave both faces of a thin part one sign, the two counts are the faces' (0.000 to
/// 0.002 of the samples apart on the plates 0.02 and 0.03 thick); thin parts that orientation
/// got right (a teapot's lid, a cow's ears in simulated scans) score 0.72 to 0.86.
constexpr double undecided = 0.2;
/// An undecided region faces inwards (a slot) when its normals facing towards its mid-surface
/// outnumber those facing away by at least this share, and away (a thin solid) otherwise.
constexpr double leaning_in = 0.1;

/// A block of samples more than this share of which have a coordinate equal to a neighbour's
/// is quantized (a grid of depths or of stored integers), and its offsets come in layers that
/// are no faces: a sphere whose coordinates were rounded to 0.03 (about 1.5 sampling steps)
/// scored 2.07-2.69, and its normals turned.
constexpr double max_tied_share = 0.25;

/// Whether sample i has a coordinate exactly equal to one of its neighbours' (other than its own
/// place).
bool tied_coordinate(std::span<const Vec3f> positions, const KnnTable& neighbors, std::size_t i)
{
    const Vec3f& p = positions[i];
    for (const std::uint32_t j : neighbors.neighbors(i))
    {
        const Vec3f& q = positions[j];
        if (j != i && q != p && (q.x() == p.x() || q.y() == p.y() || q.z() == p.z()))
            return true;
    }
    return false;
}

/// Sums of the powers 1 to 4 of offsets, and their count.
struct Powers
{
    std::array<double, 4> sum{};
    double count = 0.0;

    void add(double r)
    {
        const double r2 = r * r;
        sum[0] += r;
        sum[1] += r2;
        sum[2] += r2 * r;
        sum[3] += r2 * r2;
        count += 1.0;
    }
    void add(const Powers& p)
    {
        for (std::size_t k = 0; k < 4; ++k)
            sum[k] += p.sum[k];
        count += p.count;
    }
    /// The kurtosis of the offsets about their mean (3 for a normal distribution, 1 for two
    /// equal spikes); infinite without a spread.
    [[nodiscard]] double kurtosis() const
    {
        if (count == 0.0)
            return std::numeric_limits<double>::infinity();
        const double m1 = sum[0] / count;
        const double s2 = sum[1] / count;
        const double s3 = sum[2] / count;
        const double s4 = sum[3] / count;
        const double m2 = s2 - m1 * m1;
        const double m4 = s4 - 4.0 * m1 * s3 + 6.0 * m1 * m1 * s2 - 3.0 * m1 * m1 * m1 * m1;
        return m2 > 0.0 ? m4 / (m2 * m2) : std::numeric_limits<double>::infinity();
    }
};

/// Samples in a ball of ball_sides(): its centre sample and the nearest others. Measured
/// (Python on the positions, about 8,000 balls a cloud; `pointform sample`, 100k samples, noise
/// 0.2% of the diagonal, 8 holes): with 256, 89-95% of the balls on plates 6-7 deviations thick
/// dip, and 0-0.1% on noisy cones, CAD-like parts, spheres and simulated scans of CAD parts.
constexpr std::size_t ball_samples = 256;
/// Every ball_stride-th sample of the balls' cloud (in index order: spatially sorted samples, as
/// compute_surfels() has them, spread the centres evenly) is a ball's centre: each sample lies in
/// about four balls.
constexpr std::size_t ball_stride = 64;
/// Above this many samples the balls are found in every s-th sample (index order), s = n over
/// it: a ball of a fixed number of samples is then as wide at 1M or 10M samples as at 100k,
/// where it was measured (at 1M the 256 nearest of all the samples span a third as much, a plate
/// 0.035 thick's faces no longer both), and there are as many balls at any size. Their heights
/// are then those of all the samples within the ball's reach (about s · 256), whose histogram is
/// that much less noisy: on a noisy plate 0.02 thick at 1M, 75% of the balls dip where 62% did
/// with the subsample's 256 alone, and no ball of noisy 1M spheres, tori, cones, blobbies or
/// CAD-like parts comes near a dip (the centre bin at least 0.9 of the sides' peak in all but
/// one of 8,300).
constexpr std::size_t ball_cloud = 100000;
/// Above ball_cloud samples, a ball is measured over all the samples in its reach only where the
/// subsample's heights dip at all (the centre bin at most the sides' peak). On the 1M noisy
/// blobby (one sheet) the orientation took 1.70 s before the balls measured all the samples,
/// 1.96 s with every ball measured so, 1.76 s with these only (medians of 5 runs, 2 threads);
/// the 1M plates 0.02-0.04 got the same normals but for 29-209 of 0.93M (±0.01% facing away).
constexpr double max_remeasured_dip = 1.0;
/// A ball's heights dip when the centre bin of their histogram holds at most this share of the
/// lower of the two sides' highest bins. Over the balls above: median 0.08-0.23 on the plates,
/// 0.75-0.89 at the 0.1st percentile on the one-sheet shapes.
constexpr double max_dip = 0.6;
/// A ball beside one that counts (below) counts too when its dip is at least shallow but sure:
/// the centre bin at most this share of the sides' peak, and below it by at least
/// min_dip_significance deviations of the two counts' difference (Poisson counts:
/// √(centre + peak)), among enough balls about it that are too (the neighbour test below). Faces
/// 3.5 deviations apart dip only so much (two normal bands at ±1.75 leave 0.43 of the peak
/// between them, less the bins' and the counts' noise): on the 1M plate 0.02 thick 96% of the
/// balls are below 0.7 and 60% count by max_dip and their neighbours; with this, 90%. The
/// balls of 256 samples in the 0.7-0.8 band on one sheet are not that sure (1.2-2.4 deviations on
/// a simulated scan of the teapot); but deep dips that failed the neighbour test are, and let in
/// beside counted balls without that test they grew into the teapot's body and turned it inside
/// out (47% of its area facing away).
constexpr double max_shallow_dip = 0.8;
constexpr double min_dip_significance = 3.0;
/// The other balls' centres in a ball that its neighbour test looks at (the nearest first).
constexpr std::size_t ball_neighbours = 16;
/// A dipping ball counts when at least this many of the other balls' centres in it, and at least
/// half of them, dip too: a thin part's balls dip together, while on one sheet a ball dips alone
/// (the rim of a hole in a curved face, which takes the middle heights away). With every dipping
/// ball counting, the normals of 11 of the 64 noisy shapes and simulated scans of CAD parts in the
/// A/B set of RESULTS_reconstruct.md turned (40-2,308 samples: blobbies, tori, cones, brackets,
/// teapots; the torus's 132 at the rim of a hole in its outer face); with the test, none.
constexpr std::size_t min_agreeing_balls = 2;
/// A sample's guide must lie within 60° of its ball's axis for the ball to give it a side...
constexpr float min_axis_alignment = 0.5F;
/// ... unless the ball's two bands lie less than this many of their own deviations apart
/// (Ball::separation): then the sample's guide becomes the ball's axis, and it takes its band.
/// Where faces are that close, a sample's guide is grown from a neighbourhood whose flatness the
/// noise sets, 0.21-0.29 (0.06-0.12 on a plate 0.05 thick at 100k), and 14% of the faces' guides
/// on the 1M plate 0.02 thick (3.8 deviations) lay more than 60° off. The samples left without a
/// side were 16% wrong; with the axis, the plate's normals facing away went from 5.8% to 4.8%.
/// Where the faces are farther apart (5.0 at 0.03 thick, 7.1 at 0.05), a guide across the axis is
/// most likely the plate's rim, a face of its own, and is kept.
constexpr float max_realigned_separation = 4.5F;
/// ... and the guides across the axis in the ball agree in direction less than this
/// (Ball::across_agreement): where they agree, they are a rim's.
constexpr float max_across_agreement = 0.5F;
/// ... and lie about the ball like its other samples (Ball::across_offset below this): at a
/// corner, where two rims' guides cross, their directions do not agree, but the rims lie at
/// the ball's edge.
constexpr float max_across_offset = 0.25F;

/// A ball of ball_sides(): the plane through its samples' centroid across their least axis, and
/// how their heights along the axis dip.
struct Ball
{
    Vec3f centroid = Vec3f::Zero();
    Vec3f axis = Vec3f::Zero();
    /// The histogram's centre bin over the lower of the sides' highest bins (dip_of()).
    double dip = std::numeric_limits<double>::infinity();
    /// That difference in deviations of the counts.
    double significance = 0.0;
    /// The mean heights above and below the centroid, apart, over the deviation of the heights
    /// about their own side's mean: two normal bands d deviations apart score about d.
    float separation = 0.0F;
    /// How much the guides of its samples that lie across the axis (more than 60° off) agree in
    /// direction within the plane: |Σ (cos 2θ, sin 2θ)| over their count, θ their angle in the
    /// plane (lines, not directions). A rim's guides, across the rim, score near 1; guides that
    /// noise turned, at random, near 0.
    float across_agreement = 0.0F;
    /// Where those samples lie: their centroid's distance from all the samples' centroid, across
    /// the axis, over the samples' deviation across it. A rim's samples lie at the ball's edge
    /// (about 0.8 for a ball halved by a straight rim); samples that noise turned are spread
    /// over the ball like the others (near 0).
    float across_offset = 0.0F;
};

/// How heights (about their mean, with mean square `variance`) dip: a histogram of the heights
/// over their deviation, in 9 bins of half a deviation, and its centre bin against the lower of
/// the two sides' highest bins. Two bands more than about 4 deviations of the noise apart leave a
/// hole in the middle; one sheet's heights, curved or creased, do not (a curved cap's heights are
/// spread evenly, its kurtosis as low as two bands').
void dip_of(std::span<const float> heights, double variance, Ball& ball)
{
    if (!(variance > 0.0))
        return;
    const double scale = 2.0 / std::sqrt(variance); // bins of half a deviation
    std::array<std::uint32_t, 9> bins{};
    for (const float h : heights)
    {
        const double b = std::floor(static_cast<double>(h) * scale + 4.5);
        if (b >= 0.0 && b < 9.0)
            ++bins[static_cast<std::size_t>(b)];
    }
    const std::uint32_t below = *std::max_element(bins.begin(), bins.begin() + 4);
    const std::uint32_t above = *std::max_element(bins.begin() + 5, bins.end());
    const double side = static_cast<double>(std::max<std::uint32_t>(1, std::min(below, above)));
    const auto centre = static_cast<double>(bins[4]);
    ball.dip = centre / side;
    ball.significance = (side - centre) / std::sqrt(side + centre);
}

/// The separation of heights about their mean (Ball::separation).
float separation_of(std::span<const float> heights)
{
    std::array<double, 2> sum{};
    std::array<std::size_t, 2> count{};
    for (const float h : heights)
    {
        sum[h > 0.0F ? 1 : 0] += static_cast<double>(h);
        ++count[h > 0.0F ? 1 : 0];
    }
    if (count[0] == 0 || count[1] == 0)
        return 0.0F;
    const std::array<double, 2> mean{sum[0] / static_cast<double>(count[0]),
                                     sum[1] / static_cast<double>(count[1])};
    double within = 0.0;
    for (const float h : heights)
    {
        const double d = static_cast<double>(h) - mean[h > 0.0F ? 1 : 0];
        within += d * d;
    }
    within /= static_cast<double>(heights.size());
    return within > 0.0 ? static_cast<float>((mean[1] - mean[0]) / std::sqrt(within)) : 0.0F;
}

/// Ball::across_agreement and Ball::across_offset of the guides of `members` (at
/// `positions`) about the ball's axis.
void measure_across(std::span<const std::uint32_t> members, std::span<const Vec3f> positions,
                    std::span<const Vec3f> guide_normals, Ball& ball)
{
    const Vec3f& axis = ball.axis;
    const Vec3f u = axis.unitOrthogonal();
    const Vec3f v = axis.cross(u);
    double c = 0.0;
    double s = 0.0;
    Eigen::Vector2d at_all = Eigen::Vector2d::Zero();
    Eigen::Vector2d at_across = Eigen::Vector2d::Zero();
    double spread = 0.0;
    std::size_t across = 0;
    for (const std::uint32_t m : members)
    {
        const Vec3f d = positions[m] - ball.centroid;
        const Eigen::Vector2d place(d.dot(u), d.dot(v));
        at_all += place;
        spread += place.squaredNorm();
        const Vec3f& g = guide_normals[m];
        if (!(g.squaredNorm() > 0.0F) || std::abs(g.dot(axis)) >= min_axis_alignment)
            continue;
        const double a = g.dot(u);
        const double b = g.dot(v);
        const double length2 = a * a + b * b;
        if (!(length2 > 0.0))
            continue;
        c += (a * a - b * b) / length2;
        s += 2.0 * a * b / length2;
        at_across += place;
        ++across;
    }
    if (across == 0 || members.empty())
        return;
    const auto count = static_cast<double>(members.size());
    at_all /= count;
    spread = std::sqrt(std::max(0.0, spread / count - at_all.squaredNorm()));
    ball.across_agreement = static_cast<float>(std::hypot(c, s) / static_cast<double>(across));
    if (spread > 0.0)
        ball.across_offset =
            static_cast<float>((at_across / static_cast<double>(across) - at_all).norm() / spread);
}

/// The ball about sample `centre` of `cloud`: its ball_samples nearest there (`members`, with
/// their squared distances), the other balls' centres in it (`near`) and its squared reach.
/// False where the cloud has too few samples.
bool find_ball(const KdTree& tree, std::span<const Vec3f> cloud, std::size_t centre,
               std::vector<std::uint32_t>& members, std::vector<float>& distances,
               std::vector<std::uint32_t>& near, float& reach2)
{
    near.clear();
    members.resize(ball_samples);
    distances.resize(ball_samples);
    if (tree.knn(cloud[centre], ball_samples, members, distances) < ball_samples)
        return false;
    for (std::size_t k = 1; k < ball_samples && near.size() < ball_neighbours; ++k)
        if (members[k] % ball_stride == 0)
            near.push_back(members[k] / ball_stride);
    reach2 = distances.back();
    return true;
}

/// The plane of the samples `members` of `positions`, about `origin` (the ball's centre), and
/// how their heights dip and part; with `guide_normals` (indexed as `positions`), how the guides
/// across the axis lie. False where they have no plane. `heights` is a buffer.
bool measure_ball(std::span<const Vec3f> positions, std::span<const std::uint32_t> members,
                  const Vec3f& origin_sample, std::span<const Vec3f> guide_normals,
                  std::vector<float>& heights, Ball& ball)
{
    const std::size_t found = members.size();
    if (found < ball_samples)
        return false;
    // About the centre sample in double: the sums of squares neither lose the noise to the
    // coordinates' size nor depend on the order of the members.
    const Eigen::Vector3d origin = origin_sample.cast<double>();
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const std::uint32_t m : members)
        mean += positions[m].cast<double>() - origin;
    mean /= static_cast<double>(found);
    Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
    for (const std::uint32_t m : members)
    {
        const Eigen::Vector3d d = positions[m].cast<double>() - origin - mean;
        covariance += d * d.transpose();
    }
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance);
    if (solver.info() != Eigen::Success || !(solver.eigenvalues()(2) > 0.0))
        return false;
    const Eigen::Vector3d axis = solver.eigenvectors().col(0);
    heights.resize(found);
    double variance = 0.0;
    for (std::size_t k = 0; k < found; ++k)
    {
        const double h = (positions[members[k]].cast<double>() - origin - mean).dot(axis);
        heights[k] = static_cast<float>(h);
        variance += h * h;
    }
    ball.centroid = (origin + mean).cast<float>();
    ball.axis = axis.cast<float>();
    dip_of(heights, variance / static_cast<double>(found), ball);
    ball.separation = separation_of(heights);
    if (!guide_normals.empty())
        measure_across(members, positions, guide_normals, ball);
    return true;
}

} // namespace

void ball_sides(std::span<const Vec3f> positions, std::span<Vec3f> guide_normals,
                std::span<std::int8_t> sides)
{
    const std::size_t n = positions.size();
    if (n < 2 * ball_samples || guide_normals.size() != n || sides.size() != n)
        return;
    // The balls' cloud: every step-th sample.
    const std::size_t step = std::max<std::size_t>(1, n / ball_cloud);
    std::vector<Vec3f> thinned;
    if (step > 1)
    {
        thinned.reserve(n / step + 1);
        for (std::size_t i = 0; i < n; i += step)
            thinned.push_back(positions[i]);
    }
    const std::span<const Vec3f> cloud =
        step > 1 ? std::span<const Vec3f>(thinned) : std::span<const Vec3f>(positions);
    const KdTree tree(cloud);
    const std::size_t count = (cloud.size() + ball_stride - 1) / ball_stride;
    std::vector<Ball> balls(count);
    std::vector<float> reach2(count, 0.0F); // the squared distance to a ball's farthest sample
    std::vector<std::uint8_t> measured(count, 0);
    std::vector<std::array<std::uint32_t, ball_neighbours>> near(count);
    std::vector<std::uint8_t> near_count(count, 0);
    parallel_blocks(count, 16, [&](std::size_t begin, std::size_t end) {
        std::vector<std::uint32_t> members;
        std::vector<float> distances;
        std::vector<float> heights;
        std::vector<std::uint32_t> others;
        for (std::size_t b = begin; b < end; ++b)
        {
            const std::size_t centre = b * ball_stride;
            measured[b] = find_ball(tree, cloud, centre, members, distances, others, reach2[b]) &&
                                  measure_ball(cloud, members, cloud[centre],
                                               step > 1 ? std::span<const Vec3f>() : guide_normals,
                                               heights, balls[b])
                              ? 1
                              : 0;
            std::copy(others.begin(), others.end(), near[b].begin());
            near_count[b] = static_cast<std::uint8_t>(others.size());
        }
    });
    // Above the subsample, the balls whose heights dip at all are measured again over all the
    // samples within their reach, from a kd-tree of them all.
    std::optional<KdTree> all;
    if (step > 1)
    {
        std::vector<std::uint32_t> again;
        for (std::size_t b = 0; b < count; ++b)
            if (measured[b] != 0 && balls[b].dip <= max_remeasured_dip)
                again.push_back(static_cast<std::uint32_t>(b));
        if (!again.empty())
        {
            all.emplace(positions);
            parallel_blocks(again.size(), 4, [&](std::size_t begin, std::size_t end) {
                std::vector<std::uint32_t> members;
                std::vector<float> distances;
                std::vector<float> heights;
                for (std::size_t a = begin; a < end; ++a)
                {
                    const std::size_t b = again[a];
                    const Vec3f& centre = cloud[b * ball_stride];
                    members.clear();
                    distances.clear();
                    all->radius_search(centre, std::sqrt(reach2[b]), members, distances);
                    balls[b] = Ball{};
                    measured[b] =
                        measure_ball(positions, members, centre, guide_normals, heights, balls[b])
                            ? 1
                            : 0;
                }
            });
        }
    }
    const auto dips = [&](std::size_t b) {
        return measured[b] != 0 && balls[b].dip <= max_dip;
    };
    const auto dips_shallowly = [&](std::size_t b) {
        return measured[b] != 0 && balls[b].dip <= max_shallow_dip &&
               balls[b].significance >= min_dip_significance;
    };
    // Whether ball b and enough of the balls about it pass `test`.
    const auto agreed = [&](std::size_t b, const auto& test) {
        if (!test(b))
            return false;
        std::size_t agreeing = 0;
        for (std::size_t k = 0; k < near_count[b]; ++k)
            agreeing += test(near[b][k]) ? 1U : 0U;
        return agreeing >= min_agreeing_balls && 2 * agreeing >= near_count[b];
    };
    std::vector<std::uint8_t> kept(count, 0);
    bool any = false;
    for (std::size_t b = 0; b < count; ++b)
    {
        kept[b] = agreed(b, dips) ? 1 : 0;
        any = any || kept[b] != 0;
    }
    if (!any)
        return;
    // The balls that dip shallowly, among enough others that do, beside counted ones, and beside
    // those, to the end: the set the sweeps grow to is the same in any order. Which balls may grow
    // does not change from sweep to sweep.
    std::vector<std::uint8_t> may_grow(count, 0);
    for (std::size_t b = 0; b < count; ++b)
        may_grow[b] = kept[b] == 0 && agreed(b, dips_shallowly) ? 1 : 0;
    for (bool grown = true; grown;)
    {
        grown = false;
        for (std::size_t b = 0; b < count; ++b)
        {
            if (kept[b] != 0 || may_grow[b] == 0)
                continue;
            const auto others = std::span(near[b]).first(near_count[b]);
            if (std::any_of(others.begin(), others.end(),
                            [&](std::uint32_t o) { return kept[o] != 0; }))
            {
                kept[b] = 1;
                grown = true;
            }
        }
    }
    // Each sample's claim: the squared distance to the nearest centre of a kept ball holding it
    // (its float bits, which order as the values do) above that ball's index; the least claim
    // wins whichever thread makes it. A ball of the thinned cloud holds every sample within its
    // reach.
    constexpr std::uint64_t unclaimed = ~std::uint64_t{0};
    std::vector<std::uint64_t> claim(n, unclaimed);
    parallel_blocks(count, 16, [&](std::size_t begin, std::size_t end) {
        std::vector<std::uint32_t> members(ball_samples);
        std::vector<float> distances(ball_samples);
        for (std::size_t b = begin; b < end; ++b)
        {
            if (kept[b] == 0)
                continue;
            const Vec3f& centre = cloud[b * ball_stride];
            if (all)
            {
                members.clear();
                distances.clear();
                all->radius_search(centre, std::sqrt(reach2[b]), members, distances);
            }
            else
                tree.knn(centre, ball_samples, members, distances);
            for (std::size_t k = 0; k < members.size(); ++k)
                lower_atomically(
                    claim[members[k]],
                    (std::uint64_t{std::bit_cast<std::uint32_t>(distances[k])} << 32U) | b);
        }
    });
    // The kept balls whose faces are close: their own bands, and those of every kept ball about
    // them (at a rim, a ball's rim samples fill its gap and close its bands up).
    std::vector<std::uint8_t> close(count, 0);
    for (std::size_t b = 0; b < count; ++b)
    {
        if (kept[b] == 0)
            continue;
        const auto others = std::span(near[b]).first(near_count[b]);
        close[b] = balls[b].separation < max_realigned_separation &&
                           balls[b].across_agreement < max_across_agreement &&
                           balls[b].across_offset < max_across_offset &&
                           std::none_of(others.begin(), others.end(),
                                        [&](std::uint32_t o) {
                                            return kept[o] != 0 && !(balls[o].separation <
                                                                     max_realigned_separation);
                                        })
                       ? 1
                       : 0;
    }
    parallel_blocks(n, 4096, [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i)
        {
            if (claim[i] == unclaimed)
                continue;
            const std::size_t b = claim[i] & 0xFFFFFFFFU;
            const Ball& ball = balls[b];
            const float height = (positions[i] - ball.centroid).dot(ball.axis);
            if (height == 0.0F)
                continue;
            const float along = guide_normals[i].dot(ball.axis);
            if (std::abs(along) >= min_axis_alignment)
                sides[i] = (height > 0.0F) == (along > 0.0F) ? ball_side : -ball_side;
            else if (close[b] != 0)
            {
                guide_normals[i] = ball.axis;
                sides[i] = height > 0.0F ? ball_side : -ball_side;
            }
        }
    });
}

std::vector<std::int8_t> two_sheet_sides(std::span<const Vec3f> positions,
                                         const KnnTable& neighbors,
                                         std::span<const Vec3f> guide_normals,
                                         std::span<const float> offsets)
{
    const std::size_t n = guide_normals.size();
    std::vector<std::int8_t> sides(n, 0);
    if (n == 0 || offsets.size() != n || positions.size() != n || neighbors.k == 0 ||
        neighbors.rows() != n)
        return sides;
    const auto counts = [&](std::size_t i) {
        return usable(guide_normals[i]) && std::isfinite(offsets[i]);
    };
    const std::size_t blocks = (n + pooled_block - 1) / pooled_block;
    std::vector<Powers> block_sums(blocks);

    parallel_blocks(blocks, 16, [&](std::size_t begin, std::size_t end) {
        for (std::size_t b = begin; b < end; ++b)
        {
            Powers sum;
            std::size_t samples = 0;
            std::size_t tied = 0;
            for (std::size_t i = b * pooled_block; i < std::min(n, (b + 1) * pooled_block); ++i)
            {
                ++samples;
                tied += tied_coordinate(positions, neighbors, i) ? 1U : 0U;
                if (counts(i))
                    sum.add(static_cast<double>(offsets[i]));
            }
            // Quantized coordinates make layers that are no faces: the block says nothing.
            if (static_cast<double>(tied) <= max_tied_share * static_cast<double>(samples))
                block_sums[b] = sum;
        }
    });
    parallel_blocks(n, 4096, [&](std::size_t begin, std::size_t end) {
        std::vector<std::size_t> pooled;
        for (std::size_t i = begin; i < end; ++i)
        {
            if (!counts(i) || offsets[i] == 0.0F || block_sums[i / pooled_block].count == 0.0)
                continue;
            pooled.assign(1, i / pooled_block);
            for (const std::uint32_t j : neighbors.neighbors(i))
                if (std::find(pooled.begin(), pooled.end(), j / pooled_block) == pooled.end())
                    pooled.push_back(j / pooled_block);
            Powers sum;
            for (const std::size_t b : pooled)
                sum.add(block_sums[b]);
            const double kurtosis = sum.kurtosis();
            const std::int8_t strength = kurtosis <= static_cast<double>(certain_kurtosis)  ? 2
                                         : kurtosis <= static_cast<double>(likely_kurtosis) ? 1
                                                                                            : 0;
            sides[i] = static_cast<std::int8_t>(offsets[i] > 0.0F ? strength : -strength);
        }
    });
    return sides;
}

TwoSheetFacing face_two_sheet_regions(const KnnTable& neighbors,
                                      std::span<const Vec3f> guide_normals,
                                      std::span<const std::int8_t> sides, std::span<Vec3f> normals)
{
    TwoSheetFacing facing;
    const std::size_t n = sides.size();
    if (std::none_of(sides.begin(), sides.end(), [](std::int8_t s) { return std::abs(s) >= 2; }))
        return facing;
    // Regions: the samples with a side, joined through the table. Per region (by its root):
    // samples, certain samples (|side| at least 2), and how many of their normals face away
    // from the mid-surface less how many face towards it.
    DisjointSets regions(n);
    for (std::size_t i = 0; i < n; ++i)
        if (sides[i] != 0)
            for (const std::uint32_t j : neighbors.neighbors(i))
                if (j != i && sides[j] != 0)
                    regions.unite(i, j);
    struct Tally
    {
        std::uint32_t samples = 0;
        std::uint32_t certain = 0;
        std::int32_t away = 0;
        std::int8_t turn = 0;
    };
    std::vector<Tally> tally(n);
    for (std::size_t i = 0; i < n; ++i)
    {
        if (sides[i] == 0)
            continue;
        Tally& t = tally[regions.find(i)];
        ++t.samples;
        t.certain += std::abs(sides[i]) >= 2 ? 1U : 0U;
        const float along = normals[i].dot(guide_normals[i]) * static_cast<float>(sides[i]);
        t.away += along > 0.0F ? 1 : along < 0.0F ? -1 : 0;
    }
    for (Tally& t : tally)
    {
        const auto samples = static_cast<double>(t.samples);
        const auto certain_samples = static_cast<double>(t.certain);
        if (t.certain < min_certain || certain_samples < min_certain_share * samples ||
            std::abs(static_cast<double>(t.away)) >= undecided * samples)
            continue;
        t.turn = static_cast<double>(t.away) < -leaning_in * samples ? -1 : 1;
        ++facing.faced;
    }
    if (facing.faced > 0)
        facing.faced_by.assign(n, 0);
    for (std::size_t i = 0; i < n; ++i)
    {
        if (sides[i] == 0)
            continue;
        const std::int8_t turn = tally[regions.find(i)].turn;
        if (turn == 0)
            continue;
        facing.faced_by[i] = std::abs(sides[i]) == ball_side ? faced_by_ball : faced_by_kurtosis;
        const Vec3f wanted = guide_normals[i] * static_cast<float>(sides[i] > 0 ? turn : -turn);
        if (!(wanted.dot(normals[i]) > 0.0F))
        {
            normals[i] = wanted;
            ++facing.turned;
        }
    }
    return facing;
}

} // namespace pointform::detail
