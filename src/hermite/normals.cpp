// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/hermite/normals.h"

#include "pointform/core/error.h"
#include "pointform/core/parallel.h"
#include "pointform/spatial/kd_tree.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace pointform {
namespace {

/// Below this ratio λ1/λ2 the neighbourhood is taken as a line (or a point): its normal is
/// undefined. Relative, so independent of units.
constexpr double collinear_ratio = 1e-10;

/// The covariance of positions[indices] about their mean, and that mean, summed in double about
/// the first point (so the sums do not lose precision far from the origin). Indices in range,
/// at least one.
struct Moments
{
    Vec3d centroid;
    Mat3d covariance;
};

Moments moments_of(std::span<const Vec3f> positions, std::span<const std::uint32_t> indices)
{
    // The six distinct sums of the outer products (the covariance is symmetric), each taken in
    // the order of the points: the same sums as p pᵀ in full, at two thirds of the products.
    const Vec3d shift = positions[indices[0]].cast<double>();
    double sx = 0.0, sy = 0.0, sz = 0.0;
    double xx = 0.0, xy = 0.0, xz = 0.0, yy = 0.0, yz = 0.0, zz = 0.0;
    for (const auto index : indices)
    {
        const Vec3f& q = positions[index];
        const double x = static_cast<double>(q.x()) - shift.x();
        const double y = static_cast<double>(q.y()) - shift.y();
        const double z = static_cast<double>(q.z()) - shift.z();
        sx += x;
        sy += y;
        sz += z;
        xx += x * x;
        xy += x * y;
        xz += x * z;
        yy += y * y;
        yz += y * z;
        zz += z * z;
    }
    const double count = static_cast<double>(indices.size());
    const Vec3d mean(sx / count, sy / count, sz / count);
    Mat3d covariance;
    covariance(0, 0) = xx / count - mean.x() * mean.x();
    covariance(1, 1) = yy / count - mean.y() * mean.y();
    covariance(2, 2) = zz / count - mean.z() * mean.z();
    covariance(0, 1) = covariance(1, 0) = xy / count - mean.x() * mean.y();
    covariance(0, 2) = covariance(2, 0) = xz / count - mean.x() * mean.z();
    covariance(1, 2) = covariance(2, 1) = yz / count - mean.y() * mean.z();
    return {mean + shift, covariance};
}

/// moments_of() with NeighbourWeights::Local: each point weighted by (1 − d² / far2)³, d its
/// distance from `centre` (the fitted point) and far2 the squared distance of the row's farthest
/// (KnnTable::farthest2()). The sums are taken about the centre. Falls back on the uniform moments
/// where every point sits at the centre.
Moments local_moments_of(std::span<const Vec3f> positions, std::span<const std::uint32_t> indices,
                         const Vec3f& centre, float far2)
{
    if (!(far2 > 0.0F))
        return moments_of(positions, indices);
    const Vec3d shift = centre.cast<double>();
    const double inverse = 1.0 / static_cast<double>(far2);
    double total = 0.0;
    Vec3d sum = Vec3d::Zero();
    Mat3d outer = Mat3d::Zero();
    for (const auto index : indices)
    {
        const Vec3d p = positions[index].cast<double>() - shift;
        const double d2 = p.squaredNorm();
        // The point itself is left out: at its own place it would weigh most, and tie the plane
        // to itself (a stray off a surface took a plane through it, not the surface's).
        const double t = d2 > 0.0 ? std::max(0.0, 1.0 - d2 * inverse) : 0.0;
        const double w = t * t * t;
        total += w;
        sum += w * p;
        outer.noalias() += (w * p) * p.transpose();
    }
    if (!(total > 0.0))
        return moments_of(positions, indices);
    const Vec3d mean = sum / total;
    return {mean + shift, outer / total - mean * mean.transpose()};
}

/// The sum of the principal 2×2 minors of a symmetric matrix (λ0λ1 + λ0λ2 + λ1λ2): about
/// λ1λ2 when λ0 is small, zero on a line, to double rounding (the closed-form eigen-solve leaves
/// an exact line's middle eigenvalue at up to a few 1e-9 of the largest).
double second_invariant(const Mat3d& c)
{
    return c(0, 0) * c(1, 1) - c(0, 1) * c(0, 1) + c(0, 0) * c(2, 2) - c(0, 2) * c(0, 2) +
           c(1, 1) * c(2, 2) - c(1, 2) * c(1, 2);
}

/// The plane of a covariance by Eigen's closed-form solve: its eigenvalues, and its normal unless
/// the points are coincident or collinear (λ1 / λ2, or I2 / I1², below collinear_ratio).
LocalPlane solve_plane(const Moments& moments)
{
    LocalPlane fit;
    fit.centroid = moments.centroid;
    Eigen::SelfAdjointEigenSolver<Mat3d> solver;
    solver.computeDirect(moments.covariance);
    fit.eigenvalues = solver.eigenvalues().cwiseMax(0.0);
    const double largest = fit.eigenvalues[2];
    const double trace = moments.covariance.trace();
    fit.degenerate = !(largest > 0.0) || fit.eigenvalues[1] <= collinear_ratio * largest ||
                     second_invariant(moments.covariance) <= collinear_ratio * trace * trace ||
                     !solver.eigenvectors().allFinite();
    if (!fit.degenerate)
        fit.normal = solver.eigenvectors().col(0).normalized();
    return fit;
}

/// Below this ratio I2 / I1² of a covariance's invariants (about λ1 / λ2 when λ0 is small, and
/// at least λ1 / (3 λ2)) fast_normal() leaves the neighbourhood to solve_plane(): nearly a line,
/// where the least eigenvalue is close to the middle one and the rule for a line applies.
constexpr double fast_min_spread = 1e-6;

/// The invariants of a covariance C, whose characteristic polynomial is
/// p(λ) = λ³ − I1 λ² + I2 λ − I3, and whether fast_normal() takes it (else solve_plane() does).
struct Cubic
{
    double i1 = 0.0;
    double i2 = 0.0;
    double i3 = 0.0;
    bool fast = false;
};

Cubic cubic_of(const Mat3d& c)
{
    Cubic cubic;
    cubic.i1 = c.trace();
    cubic.i2 = second_invariant(c);
    cubic.fast = cubic.i1 > 0.0 && cubic.i2 > fast_min_spread * cubic.i1 * cubic.i1;
    if (cubic.fast)
        cubic.i3 = c.determinant();
    return cubic;
}

/// Samples whose least eigenvalues least_roots() finds together.
constexpr std::size_t root_group = 4;

/// The least root λ0 of each fast cubic, by Newton's method from 0, which climbs to it without
/// overshooting (p is increasing and concave below its least root, since λ0 ≤ I1 / 3). The
/// cubics are solved in lockstep, each by the same steps as alone: its chain of divisions
/// overlaps the others' instead of waiting on itself.
std::array<double, root_group> least_roots(const std::array<Cubic, root_group>& cubics,
                                           std::size_t count)
{
    std::array<double, root_group> lambda{};
    std::array<bool, root_group> active{};
    for (std::size_t g = 0; g < count; ++g)
        active[g] = cubics[g].fast;
    for (int step = 0; step < 64; ++step)
    {
        bool any = false;
        for (std::size_t g = 0; g < count; ++g)
        {
            if (!active[g])
                continue;
            const Cubic& c = cubics[g];
            const double value = ((lambda[g] - c.i1) * lambda[g] + c.i2) * lambda[g] - c.i3;
            const double slope = (3.0 * lambda[g] - 2.0 * c.i1) * lambda[g] + c.i2;
            const double move = -value / slope;
            if (!(move > 0.0) || !std::isfinite(move))
            {
                active[g] = false; // at the root to rounding (or past it by rounding)
                continue;
            }
            lambda[g] += move;
            active[g] = move > 1e-15 * c.i1;
            any = any || active[g];
        }
        if (!any)
            break;
    }
    return lambda;
}

/// The unit eigenvector of the least eigenvalue λ0 of a covariance C, without trigonometry: the
/// longest column of adj(C − λ0 I), which spans the kernel of C − λ0 I when λ0 is simple. Zero
/// when C is nearly a line (not `fast`) or λ0 is not clearly simple (the columns all but vanish):
/// solve_plane() then decides.
Vec3d fast_normal(const Mat3d& c, const Cubic& cubic, double lambda)
{
    if (!cubic.fast)
        return Vec3d::Zero();
    const Mat3d m = c - lambda * Mat3d::Identity();
    const Vec3d a = m.row(1).cross(m.row(2)).transpose();
    const Vec3d b = m.row(0).cross(m.row(2)).transpose();
    const Vec3d d = m.row(0).cross(m.row(1)).transpose();
    const double na = a.squaredNorm();
    const double nb = b.squaredNorm();
    const double nd = d.squaredNorm();
    const Vec3d& longest = na >= nb && na >= nd ? a : (nb >= nd ? b : d);
    const double length2 = std::max({na, nb, nd});
    // The columns' length is about (λ1 − λ0)(λ2 − λ0): tiny against I2 when λ0 is (nearly) double.
    if (!(length2 > (fast_min_spread * cubic.i2) * (fast_min_spread * cubic.i2)))
        return Vec3d::Zero();
    return longest / std::sqrt(length2);
}

/// NeighbourWeights::Local tries a refit where the uniform fit's least eigenvalue is over this
/// share of the middle one: where the neighbourhood reaches another sheet or bends round a crease
/// its normal is ill-defined, and elsewhere the two fits agree. On the clean 100k plate 2.2
/// spacings thick, 44% of the samples; on clean CAD shapes (fandisk, the part of bench/peers)
/// 3-4%, at their creases (where parallel_sheet() keeps most of them from the refit).
constexpr double local_ambiguity = 0.2;

/// Whether a fit's least eigenvalue λ0 is over local_ambiguity of the middle one λ1.
bool ambiguous(double lambda0, double lambda1)
{
    return lambda0 > local_ambiguity * lambda1;
}

/// ambiguous() for a fast cubic's least root λ0: λ1 and λ2 are the roots of
/// λ² − (I1 − λ0) λ + (I2 − λ0 (I1 − λ0)).
bool ambiguous(const Cubic& cubic, double lambda0)
{
    const double sum = cubic.i1 - lambda0;
    const double product = cubic.i2 - lambda0 * sum;
    return ambiguous(lambda0, 0.5 * (sum - std::sqrt(std::max(0.0, sum * sum - 4.0 * product))));
}

/// Neighbours farther than this share of the farthest's distance from the refitted plane are
/// off it: parallel_sheet() looks at them.
constexpr double off_sheet = 0.25;

/// How evenly the neighbours off a refitted plane must stand off it (the spread of their heights
/// over their mean) to be a parallel sheet.
constexpr double sheet_spread = 0.3;

/// The band of heights, as shares of the far sheet's mean height, where parallel_sheet() wants
/// no neighbour.
constexpr std::array<double, 2> sheet_gap = {0.2, 0.6};

/// Whether the neighbours of sample i that stand off the plane through it with normal n (more
/// than off_sheet of the farthest's distance) all lie on one side of it, at heights within
/// sheet_spread of their mean, with none between the two sheets (sheet_gap): a sheet parallel to
/// the sample's own, the far side of a part thinner than the neighbourhood. Past a crease the
/// other face rises from the edge, and it has samples at every height. On the clean 100k shapes
/// of bench/peers 40% of the thin plate's samples pass, none of the blobby's and 0.1% of the
/// part's and fandisk's (0.2-0.3% without the gap: by the concave grooves of the blobby, where
/// the walls' farther samples stood at one height, and the refits moved the 1M blobby's
/// Hausdorff distance 0.085 -> 0.090% of the diagonal).
bool parallel_sheet(std::span<const Vec3f> positions, std::span<const std::uint32_t> row,
                    std::size_t i, const Vec3d& n, double reach)
{
    const Vec3d centre = positions[i].cast<double>();
    std::size_t count = 0;
    int side = 0;
    double lowest = std::numeric_limits<double>::infinity();
    double highest = 0.0;
    double sum = 0.0;
    for (const std::uint32_t j : row)
    {
        const double h = (positions[j].cast<double>() - centre).dot(n);
        const double height = std::abs(h);
        if (!(height > off_sheet * reach))
            continue;
        const int this_side = h > 0.0 ? 1 : -1;
        if (side != 0 && this_side != side)
            return false;
        side = this_side;
        ++count;
        lowest = std::min(lowest, height);
        highest = std::max(highest, height);
        sum += height;
    }
    if (count == 0)
        return false;
    const double mean = sum / static_cast<double>(count);
    if (!(highest - lowest < sheet_spread * mean))
        return false;
    // Nothing between the sheets: a face that rises from the sample's own (a groove's wall, whose
    // farther samples can stand at one height) has samples at every height up to them.
    for (const std::uint32_t j : row)
    {
        const double height = std::abs((positions[j].cast<double>() - centre).dot(n));
        if (height > sheet_gap[0] * mean && height < sheet_gap[1] * mean)
            return false;
    }
    return true;
}

/// Sample i's normal refitted with NeighbourWeights::Local, kept where that fit spans a plane
/// and its neighbours off the plane are a parallel sheet (parallel_sheet()). At a crease the
/// refit would take the sample's own face, and the point field's crease fits, which start from
/// the blended normal, filled the concave grooves of the clean 100k blobby of bench/peers
/// deeper (its Hausdorff distance 0.26 -> 0.32% of the diagonal).
void refit_locally(std::span<const Vec3f> positions, const KnnTable& neighbors, std::size_t i,
                   Vec3f& normal)
{
    const std::span<const std::uint32_t> row = neighbors.neighbors(i);
    const float far2 = neighbors.farthest2(i);
    const LocalPlane fit = solve_plane(local_moments_of(positions, row, positions[i], far2));
    if (!fit.degenerate &&
        parallel_sheet(positions, row, i, fit.normal, std::sqrt(static_cast<double>(far2))))
        normal = fit.normal.cast<float>();
}

} // namespace

LocalPlane fit_plane(std::span<const Vec3f> positions, std::span<const std::uint32_t> indices)
{
    if (indices.empty())
        throw InvalidInput("fit_plane: no indices");
    for (const std::uint32_t index : indices)
        if (index >= positions.size())
            throw InvalidInput("fit_plane: index " + std::to_string(index) +
                               " is out of range for " + std::to_string(positions.size()) +
                               " points");
    return solve_plane(moments_of(positions, indices));
}

Normals estimate_normals(std::span<const Vec3f> positions, const KnnTable& neighbors,
                         const ProgressCallback& progress, NeighbourWeights weights)
{
    const bool local = weights == NeighbourWeights::Local;
    // The rows' indices are checked below as each fit reads them.
    check_knn_table_shape(neighbors, positions.size(), "estimate_normals");
    Normals result;
    result.normals.resize(positions.size());
    // Each block's degenerate samples, in order; the blocks are joined in order.
    constexpr std::size_t block = 4096;
    std::vector<std::vector<std::uint32_t>> degenerate((positions.size() + block - 1) / block);
    ProgressReporter reporter(progress, "normals");
    parallel_blocks(
        positions.size(), block,
        [&](std::size_t begin, std::size_t end) {
            std::vector<std::uint32_t>& flat = degenerate[begin / block];
            std::array<Moments, root_group> moments;
            std::array<Cubic, root_group> cubics;
            for (std::size_t first = begin; first < end; first += root_group)
            {
                const std::size_t count = std::min(root_group, end - first);
                for (std::size_t g = 0; g < count; ++g)
                {
                    const std::size_t i = first + g;
                    check_knn_row(neighbors, i, positions.size(), "estimate_normals");
                    moments[g] = moments_of(positions, neighbors.neighbors(i));
                    cubics[g] = cubic_of(moments[g].covariance);
                }
                const std::array<double, root_group> lambda = least_roots(cubics, count);
                for (std::size_t g = 0; g < count; ++g)
                {
                    const std::size_t i = first + g;
                    const Vec3d fast = fast_normal(moments[g].covariance, cubics[g], lambda[g]);
                    if (fast.squaredNorm() > 0.0)
                    {
                        result.normals[i] = fast.cast<float>();
                        if (local && ambiguous(cubics[g], lambda[g]))
                            refit_locally(positions, neighbors, i, result.normals[i]);
                        continue;
                    }
                    const LocalPlane fit = solve_plane(moments[g]);
                    result.normals[i] = fit.normal.cast<float>();
                    if (fit.degenerate)
                        flat.push_back(static_cast<std::uint32_t>(i));
                    else if (local && ambiguous(fit.eigenvalues[0], fit.eigenvalues[1]))
                        refit_locally(positions, neighbors, i, result.normals[i]);
                }
            }
        },
        &reporter);
    reporter.finish();
    for (const std::vector<std::uint32_t>& flat : degenerate)
        result.degenerate.insert(result.degenerate.end(), flat.begin(), flat.end());
    return result;
}

Normals estimate_normals(std::span<const Vec3f> positions, const NormalOptions& options)
{
    if (options.k < 3)
        throw InvalidInput("estimate_normals: k = " + std::to_string(options.k) +
                           " is too small; a plane needs at least 3 neighbours");
    if (positions.size() <= options.k)
        throw InvalidInput("estimate_normals: " + std::to_string(positions.size()) +
                           " points are fewer than k + 1 = " + std::to_string(options.k + 1));
    const KdTree tree(positions);
    const KnnTable table =
        knn_batch(tree, positions, options.k + 1, {.progress = options.progress});
    return estimate_normals(positions, table, options.progress);
}

} // namespace pointform
