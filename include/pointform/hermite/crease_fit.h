// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

/// \file
/// \brief The crease-aware plane fit that the point field's quadrics and the estimated normals
/// share: a sample's plane refitted to the neighbours on its own side of a crease
/// (crease_plane()), and the tests it rests on. Internal to the library.

#include "pointform/core/types.h"
#include "pointform/spatial/neighborhoods.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

namespace pointform::detail {

/// cos 30°: a neighbour whose normal turns further sets off crease_plane()'s refit.
inline constexpr float crease_turn_cosine = 0.8660254F;

/// A neighbour whose normal turns from a sample's by more than 120° (cos −0.5) faces away: the
/// other side of a thin wall, which bounds nothing, not the other face of a crease
/// (crease_plane(), crease_limit()). Under noise a thin part's two sides, a tube narrower than
/// the neighbourhood, turn their normals by that much: taking neighbours turned up to 143° for
/// faces in every cloud moved the simulated teapot scan 3's Chamfer 0.130 -> 0.137% of the
/// diagonal, spot scan 1's 0.121 -> 0.125% and the noisy 100k plate's Hausdorff 0.83 -> 1.04%.
inline constexpr float wall_cosine = -0.5F;

/// ... except at the edge of a clean cloud's convex wedge (convex_edge()), where faces turned up
/// to 143° (cos −0.8) are a crease: a wedge of 37° or more, as the 45° rim of a cone, whose
/// faces' normals turn by 135°. Taken for two sides of a wall, neither face's samples bounded the
/// other's: past the rim the base's planes ran on over the side and the side's under the base,
/// sheets of inside 0.02 deep (an influence radius 0.029) beside the edge, and on the clean 100k
/// cone (`pointform sample cone`, raw points) marching cubes of the field had 151 boundary loops.
inline constexpr float wedge_cosine = -0.8F;

/// Iterations of crease_plane()'s reweighting from each start.
inline constexpr int crease_iterations = 16;

/// The reweighting has converged when the normal turns by less than about 1e-4 radians in an
/// iteration (cos 1e-4 ≈ 1 − 5e-9). Four iterations at most (from a principal normal 40° off
/// a face at the edges of the 1M clean plate of bench/peers) left planes tilted 10°, which ran
/// 0.004 past the edge.
inline constexpr double crease_converged = 1.0 - 5e-9;

/// A sample's neighbours (relative to the sample) as crease_plane() weighs them: the nearest
/// `capacity` of them where PointFieldOptions::quadric_k asks for more.
struct CreaseNeighbourhood
{
    static constexpr std::size_t capacity = 256;
    std::array<Vec3d, capacity> x;
    std::array<double, capacity> spatial; ///< a Gaussian of half the farthest distance
    std::size_t count = 0;
    double floor = 0.0; ///< the least residual scale, 1e-3 of the farthest distance
    mutable std::array<double, capacity> scratch; ///< cut()'s residuals
    /// Whether cut() takes the residuals' scale from their lower quartile, not their median.
    bool lower_quartile = false;

    /// The cut of Tukey's biweight for the residuals of the plane through the sample with
    /// normal n: 3 robust standard deviations (1.4826 × their median), at least 3 floor. With
    /// lower_quartile, 3.139 × their lower quartile (where a quarter of normal residuals' sizes
    /// lie under 0.3186 σ): a face that holds a quarter of the neighbourhood sets the scale,
    /// where the median needs half. At a wedge's edge a sample's own face holds less than half:
    /// from the median the refits ran to planes between the faces (on the clean 100k cone, a
    /// base sample 0.015 from the rim took a plane turned 5° from the base's with a cut of 0.012,
    /// another a plane turned 80°, whose field put a fin of inside under the base).
    [[nodiscard]] double cut(const Vec3d& n) const
    {
        std::array<double, capacity>& residual = scratch;
        for (std::size_t j = 0; j < count; ++j)
            residual[j] = std::abs(x[j].dot(n));
        const auto middle =
            residual.begin() + static_cast<std::ptrdiff_t>(lower_quartile ? count / 4 : count / 2);
        std::nth_element(residual.begin(), middle,
                         residual.begin() + static_cast<std::ptrdiff_t>(count));
        return 3.0 * std::max((lower_quartile ? 3.139 : 1.4826) * *middle, floor);
    }

    /// Whether some residual exceeds cut(n), without sorting: the largest residual r exceeds
    /// 3 × max(1.4826 × median, floor) where it exceeds 3 floor and more than half of the
    /// residuals lie under r / (3 × 1.4826) (then the median does).
    [[nodiscard]] bool has_outliers(const Vec3d& n) const
    {
        double largest = 0.0;
        for (std::size_t j = 0; j < count; ++j)
        {
            scratch[j] = std::abs(x[j].dot(n));
            largest = std::max(largest, scratch[j]);
        }
        if (!(largest > 3.0 * floor))
            return false;
        const double median_below = largest / (3.0 * 1.4826);
        std::size_t below = 0;
        for (std::size_t j = 0; j < count; ++j)
            below += scratch[j] < median_below ? 1U : 0U;
        return below > count / 2;
    }

    [[nodiscard]] double weight(std::size_t j, const Vec3d& n, double cut) const
    {
        const double t = x[j].dot(n) / cut;
        return t * t < 1.0 ? spatial[j] * (1.0 - t * t) * (1.0 - t * t) : 0.0;
    }

    /// How much of the neighbourhood the plane with normal n holds at the given cut.
    [[nodiscard]] double support(const Vec3d& n, double cut) const
    {
        double sum = 0.0;
        for (std::size_t j = 0; j < count; ++j)
            sum += weight(j, n, cut);
        return sum;
    }

    /// The support of a plane that held every neighbour: the spatial weights' sum.
    [[nodiscard]] double total() const
    {
        double sum = 0.0;
        for (std::size_t j = 0; j < count; ++j)
            sum += spatial[j];
        return sum;
    }

    /// The principal axes (eigenvalues ascending) of the neighbours weighted by w(j) (those of
    /// weight 0 left out), about their weighted centroid, written to `centroid` if given;
    /// nullopt where no weight is positive.
    template <typename Weight>
    [[nodiscard]] std::optional<Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>> principal_axes(
        Weight w, Vec3d* centroid = nullptr) const
    {
        double weight_sum = 0.0;
        Vec3d mean = Vec3d::Zero();
        for (std::size_t j = 0; j < count; ++j)
        {
            const double wj = w(j);
            if (wj == 0.0)
                continue;
            weight_sum += wj;
            mean += wj * x[j];
        }
        if (!(weight_sum > 0.0))
            return std::nullopt;
        mean /= weight_sum;
        Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
        for (std::size_t j = 0; j < count; ++j)
        {
            const double wj = w(j);
            if (wj == 0.0)
                continue;
            const Vec3d y = x[j] - mean;
            covariance.noalias() += wj * y * y.transpose();
        }
        if (centroid != nullptr)
            *centroid = mean;
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
        solver.computeDirect(covariance);
        return solver;
    }

    /// Iteratively reweighted least squares from `start` (signed like `sign`); nullopt where
    /// the weighted neighbours span no plane.
    [[nodiscard]] std::optional<Vec3d> refit(Vec3d n, const Vec3d& sign) const
    {
        for (int iteration = 0; iteration < crease_iterations; ++iteration)
        {
            const double c = cut(n);
            std::array<double, capacity> w;
            for (std::size_t j = 0; j < count; ++j)
                w[j] = weight(j, n, c);
            const auto axes = principal_axes([&](std::size_t j) { return w[j]; });
            // A line or a point (too few weighted neighbours off a line): no plane.
            if (!axes || !(axes->eigenvalues()[1] > 1e-6 * axes->eigenvalues()[2]) ||
                !axes->eigenvectors().allFinite())
                return std::nullopt;
            const Vec3d next = axes->eigenvectors().col(0);
            const Vec3d previous = n;
            n = next.dot(sign) < 0.0 ? Vec3d(-next) : next;
            if (std::abs(n.dot(previous)) > crease_converged)
                break;
        }
        return n;
    }
};

/// Median flatness() of the samples' fit neighbourhoods under which a cloud counts as clean for
/// crease_plane(): the orientation's noise threshold (orient_normals_mst()), where a disc of
/// radius ρ with position noise σ scores about 6 σ² / ρ², so noise under about ρ / 17.
/// Curvature scores 4e-4 to 3e-3 on the clean shapes of bench/peers, the bunny scans about
/// 0.01; its noisy clouds 0.1 to 0.9.
inline constexpr double clean_flatness = 0.02;

/// How far points are from a plane, from their covariance C (eigenvalues λ0 ≤ λ1 ≤ λ2):
/// 3 det C / (I2 tr C), I2 the sum of C's principal 2 × 2 minors: 0 on a plane, 1 for an
/// isotropic blob, about 3 λ0 / (λ1 + λ2) when thin (as the orientation's noise test measures).
double flatness(std::span<const Vec3f> positions, std::span<const std::uint32_t> points);

/// Whether the median of `flatness` (one a sample of a subsample; reordered) is under
/// clean_flatness.
bool clean_cloud(std::vector<double>& flatness);

/// Rows of a table whose flatness refit_crease_normals() takes the median of (every
/// n / clean_test_rows-th).
inline constexpr std::size_t clean_test_rows = 20000;

/// Whether a cloud is clean by its neighbour table: clean_cloud() over the flatness() of every
/// n / clean_test_rows-th row.
bool clean_table(std::span<const Vec3f> positions, const KnnTable& table);

/// Whether sample i (neighbourhood `hood`, normal `normal`, farthest neighbour at `reach`) is
/// at the edge of a convex wedge: some neighbour's normal turns from its own by 120-143°
/// (between wall_cosine and wedge_cosine), and some plane through the sample, with its own normal
/// or a neighbour's, has every neighbour on its inner side (within 2% of the reach). Two faces
/// that meet at a convex edge lie under a plane through it; a thin wall's two sides do too, but
/// their normals turn by about 180°. Where two sheets cross or one sheet is doubled over another
/// (the clean samples of data/meshes/teapot.obj, at its spout and handle) the neighbours lie on
/// both sides of every such plane. The estimated normals by the edge are blended between the
/// faces', so the sample's own normal alone failed the test at 4,390 of the clean cone's samples.
bool convex_edge(const CreaseNeighbourhood& hood, std::span<const std::uint32_t> neighbors,
                 std::span<const Vec3f> normals, const Vec3f& normal, double reach);

/// crease_plane()'s result: the sample's normal, and where it was refitted, the fit's cut and
/// the tests behind it (for the point field's crease line, crease_limit()).
struct CreasePlane
{
    Vec3f normal; ///< the refitted normal, or the sample's own where `refitted` is false
    bool refitted = false;
    double cut = 0.0;         ///< the biweight's cut of the chosen plane
    float away = wall_cosine; ///< neighbours turned past this cosine face away
    bool wedge = false;       ///< the sample is at a clean convex wedge's edge (convex_edge())
};

/// The normal of sample i (relative to whose position `hood` is filled) refitted to the neighbours
/// on its own side of a crease. A principal component normal averages over every face in the
/// neighbourhood: at a crease it tilts toward the other face (up to 54° at the corners of the 100k
/// plate of bench/peers, and in a concave crease it can lie nearly in the surface), and the quadric
/// fitted in its frame bends round the crease and reaches past it (a lip of half the plate's
/// thickness beyond a corner). Where some neighbours' normals turn by more than 30° (elsewhere the
/// normal is kept), a plane through the sample is fitted by iteratively reweighted least squares
/// (weights falling with a neighbour's distance and with its residual, Tukey's biweight) from six
/// starts: the normal, the middle principal direction and the two diagonals between it and the
/// smallest (the faces of a crease whose principal normal lies between them), and the normals of
/// two neighbours, the one turned furthest from the sample's and the one turned furthest from that
/// (the faces' own normals, away from the crease); the plane that holds most of the neighbourhood
/// at the tightest of their scales wins, signed like the sample's normal. A sample about a spacing
/// from a crease, whose neighbourhood lies mostly on the other face, needs the neighbours' starts:
/// from the others every refit ran to the plane between the faces (its cut, from the median
/// residual, then holds both), whose quadric filled a concave groove by up to 1.4 spacings on the
/// 1M clean blobby of bench/peers. It replaces the normal where the normal's plane leaves some
/// neighbours off by more than 3 robust standard deviations of the residuals
/// (CreaseNeighbourhood::cut()), or, in a `clean` cloud (clean_cloud()), where the fitted plane
/// does. A first plane that holds 90% of the neighbourhood's weight (in a clean cloud: at a cut
/// under half the neighbourhood's reach) is taken at once: on the 100k clean part of bench/peers
/// the other starts then doubled the field's build time for 0.5% in Chamfer. At a box's corner
/// three faces share the neighbourhood, the principal plane fits none of them, and its residuals
/// spread too evenly to count as outliers; its cut then spans the neighbourhood and so holds all of
/// it: with the outlier test on the normal's plane only and the early plane taken at any cut, the
/// corners of the 100k clean plate kept their principal normals, whose surfaces put a lip
/// 0.025 past the corner (Hausdorff 0.86% of the diagonal against 0.38%). Under noise as
/// large as the sampling step (the 1M noisy part of bench/peers) the same rules fitted planes
/// to the noise (a sample 3.6 deviations off a corner tilted 65° into the next face, a dent
/// 0.03 deep; Chamfer 0.0584% -> 0.0591% of the diagonal).
/// Measured with a numpy prototype of this fit on the 100k clean plate and blobby of
/// bench/peers (estimated normals, samples within 0.15 of a corner and of a concave crease):
/// error to the nearer true face normal over 30° on 61 and 22 samples with the principal
/// normal, 43 and 13 with one start (the normal), 21 and 4 with the four.
CreasePlane crease_plane(CreaseNeighbourhood& hood, std::span<const Vec3f> positions,
                         std::span<const Vec3f> normals, std::span<const std::uint32_t> neighbors,
                         std::size_t i, const Vec3f& normal, bool clean);

/// Samples a block of refit_crease_normals() takes (its parallel blocks).
inline constexpr std::size_t crease_refit_block = 4096;

/// \brief Refits the estimated, oriented normals of a clean cloud (clean_table()) at its creases
/// to each sample's own face (crease_plane() over the sample's row of `table`, the sample itself
/// in it): a principal component normal there is a blend of the faces'. Every refit reads the
/// normals as they were, so the result does not depend on the order or the threads. A noisy cloud
/// keeps its normals: its planes would be fitted to the noise (crease_plane()).
/// \return how many normals changed
std::size_t refit_crease_normals(std::span<const Vec3f> positions, const KnnTable& table,
                                 std::span<Vec3f> normals);

} // namespace pointform::detail
