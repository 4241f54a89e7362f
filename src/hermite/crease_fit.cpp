// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/hermite/crease_fit.h"

#include "pointform/core/error.h"
#include "pointform/core/parallel.h"

#include <limits>

namespace pointform::detail {

/// How far points are from a plane, from their covariance C (eigenvalues λ0 ≤ λ1 ≤ λ2):
/// 3 det C / (I2 tr C), I2 the sum of C's principal 2 × 2 minors: 0 on a plane, 1 for an
/// isotropic blob, about 3 λ0 / (λ1 + λ2) when thin (as the orientation's noise test measures).
double flatness(std::span<const Vec3f> positions, std::span<const std::uint32_t> points)
{
    if (points.size() < 3)
        return 0.0;
    Vec3d mean = Vec3d::Zero();
    for (const std::uint32_t j : points)
        mean += positions[j].cast<double>();
    mean /= static_cast<double>(points.size());
    Eigen::Matrix3d c = Eigen::Matrix3d::Zero();
    for (const std::uint32_t j : points)
    {
        const Vec3d y = positions[j].cast<double>() - mean;
        c.noalias() += y * y.transpose();
    }
    const double minors = c(0, 0) * c(1, 1) - c(0, 1) * c(0, 1) + c(0, 0) * c(2, 2) -
                          c(0, 2) * c(0, 2) + c(1, 1) * c(2, 2) - c(1, 2) * c(1, 2);
    const double denominator = minors * c.trace();
    return denominator > 0.0 ? 3.0 * c.determinant() / denominator : 0.0;
}

/// Whether the median of `flatness` (one a sample of a subsample; reordered) is under
/// clean_flatness.
bool clean_cloud(std::vector<double>& flatness)
{
    if (flatness.empty())
        return true;
    const auto middle = flatness.begin() + static_cast<std::ptrdiff_t>(flatness.size() / 2);
    std::nth_element(flatness.begin(), middle, flatness.end());
    return *middle < clean_flatness;
}

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
                 std::span<const Vec3f> normals, const Vec3f& normal, double reach)
{
    bool band = false;
    for (std::size_t j = 1; j < hood.count && !band; ++j)
    {
        const float cosine = normals[neighbors[j]].dot(normal);
        band = cosine <= wall_cosine && cosine > wedge_cosine;
    }
    if (!band)
        return false;
    const double tolerance = 0.02 * reach;
    for (std::size_t c = 0; c < hood.count; ++c)
    {
        const Vec3d n = c == 0 ? normal.cast<double>() : normals[neighbors[c]].cast<double>();
        if (!(n.squaredNorm() > 0.5)) // a sample without a normal bounds nothing
            continue;
        bool under = true;
        for (std::size_t j = 0; j < hood.count && under; ++j)
            under = hood.x[j].dot(n) <= tolerance;
        if (under)
            return true;
    }
    return false;
}

CreasePlane crease_plane(CreaseNeighbourhood& hood, std::span<const Vec3f> positions,
                         std::span<const Vec3f> normals, std::span<const std::uint32_t> neighbors,
                         std::size_t i, const Vec3f& normal, bool clean)
{
    if (neighbors.size() < 10)
        return CreasePlane{normal};
    hood.count = std::min(neighbors.size(), CreaseNeighbourhood::capacity);
    const Vec3d s = positions[i].cast<double>();
    double far2 = 0.0;
    for (std::size_t j = 0; j < hood.count; ++j)
    {
        hood.x[j] = positions[neighbors[j]].cast<double>() - s;
        far2 = std::max(far2, hood.x[j].squaredNorm());
    }
    // A surface's k nearest spread as a disc (the farthest of 48 about 2.2 times as far as the
    // tenth); a stray point's reach a surface far off past its few fellows (a cluster of 10 to
    // 30 strays 1 to 1.5 from a sphere: 10 to 25 times), and have no face to fit.
    const double tenth2 = hood.x[std::min<std::size_t>(10, hood.count - 1)].squaredNorm();
    if (!(far2 > 0.0) || !(far2 <= 16.0 * tenth2))
        return CreasePlane{normal};
    hood.floor = 1e-3 * std::sqrt(far2);
    // A crease turns some neighbours' normals by more than 30° (and not by more than 120°,
    // 143° at a wedge's edge: those face away, the other side of a thin wall); curvature over the
    // neighbourhood turns them less (7° on the tube of the 100k torus of bench/peers), though it
    // may leave residuals off the plane that look like outliers (the tube's curvature along one
    // direction only).
    const bool wedge = clean && convex_edge(hood, neighbors, normals, normal, std::sqrt(far2));
    const float away = wedge ? wedge_cosine : wall_cosine;
    hood.lower_quartile = wedge;
    bool turned = false;
    for (std::size_t j = 1; j < hood.count && !turned; ++j)
    {
        const float cosine = normals[neighbors[j]].dot(normal);
        turned = cosine < crease_turn_cosine && cosine > away;
    }
    const Vec3d original = normal.cast<double>();
    if (!turned)
        return CreasePlane{normal};
    for (std::size_t j = 0; j < hood.count; ++j)
        hood.spatial[j] = std::exp(-hood.x[j].squaredNorm() / (0.25 * far2));
    // Under noise a sample's plane leaves no outliers where the noise hides the crease, and
    // the plane fitted instead is the noise's: only clean clouds go on without outliers.
    const bool outliers = hood.has_outliers(original);
    if (!outliers && !clean)
        return CreasePlane{normal};

    const auto principal = hood.principal_axes([](std::size_t) { return 1.0; });
    const Vec3d e0 = principal->eigenvectors().col(0);
    const Vec3d e1 = principal->eigenvectors().col(1);
    // In clean clouds, two more starts from the neighbours' own normals, which away from the
    // crease are their faces': the one turned furthest from the sample's (the other face, or
    // this one where the principal normal leans to the other), and the one turned furthest from
    // that.
    const auto furthest_turned = [&](const Vec3f& from) {
        std::size_t furthest = 0;
        float furthest_cosine = 2.0F;
        for (std::size_t j = 1; j < hood.count; ++j)
        {
            const float cosine = normals[neighbors[j]].dot(from);
            if (cosine > away && cosine < furthest_cosine)
            {
                furthest_cosine = cosine;
                furthest = j;
            }
        }
        return normals[neighbors[furthest]];
    };
    Vec3d first_face = Vec3d::Constant(std::numeric_limits<double>::quiet_NaN());
    Vec3d second_face = first_face;
    if (clean)
    {
        const Vec3f first = furthest_turned(normal);
        first_face = first.cast<double>();
        second_face = furthest_turned(first).cast<double>();
    }
    std::array<Vec3d, 6> starts = {
        original, e1, (e0 + e1).normalized(), (e0 - e1).normalized(), first_face, second_face};
    std::array<std::optional<Vec3d>, 6> fits;
    std::array<double, 6> cuts{};
    double tightest = std::numeric_limits<double>::infinity();
    for (std::size_t c = 0; c < starts.size(); ++c)
    {
        if (!starts[c].allFinite())
            continue;
        const Vec3d start = starts[c].dot(original) < 0.0 ? Vec3d(-starts[c]) : starts[c];
        fits[c] = hood.refit(start, original);
        if (!fits[c])
            continue;
        cuts[c] = hood.cut(*fits[c]);
        tightest = std::min(tightest, cuts[c]);
        // A plane from the normal that holds nearly the whole neighbourhood (curvature, not a
        // crease, set off the test): the other starts would not do better.
        if (c == 0 && (!clean || cuts[c] < 0.5 * std::sqrt(far2)) &&
            hood.support(*fits[c], cuts[c]) >= 0.9 * hood.total())
            break;
    }
    std::optional<std::size_t> best;
    double best_support = 0.0;
    for (std::size_t c = 0; c < fits.size(); ++c)
    {
        if (!fits[c])
            continue;
        const double support = hood.support(*fits[c], tightest);
        if (support > best_support)
        {
            best = c;
            best_support = support;
        }
    }
    if (!best || (!outliers && !hood.has_outliers(*fits[*best])))
        return CreasePlane{normal};
    Vec3d fitted = fits[*best]->normalized();
    if (clean)
    {
        // The plane faces the way the neighbours it holds do, not as the sample's normal: by a
        // sharp edge that normal is a blend of the faces' and may be turned over (on the clean
        // 100k cone 0.8% of the estimated normals, all within 0.02 of the rim), and a sample on
        // the edge that takes the other face's plane, signed like its own normal, faced into
        // the wedge.
        Vec3d facing = Vec3d::Zero();
        for (std::size_t j = 0; j < hood.count; ++j)
            if (std::abs(hood.x[j].dot(fitted)) <= cuts[*best])
                facing += normals[neighbors[j]].cast<double>();
        if (facing.dot(fitted) < 0.0)
            fitted = -fitted;
    }
    return {.normal = fitted.cast<float>(),
            .refitted = true,
            .cut = cuts[*best],
            .away = away,
            .wedge = wedge};
}

bool clean_table(std::span<const Vec3f> positions, const KnnTable& table)
{
    // The median flatness of a fixed subsample of the rows (as the point field tests its own
    // neighbourhoods).
    const std::size_t n = table.rows();
    const std::size_t stride = std::max<std::size_t>(1, n / clean_test_rows);
    std::vector<double> flat((n + stride - 1) / stride);
    for (std::size_t r = 0; r < flat.size(); ++r)
        flat[r] = flatness(positions, table.neighbors(r * stride));
    return clean_cloud(flat);
}

std::size_t refit_crease_normals(std::span<const Vec3f> positions, const KnnTable& table,
                                 std::span<Vec3f> normals)
{
    const std::size_t n = positions.size();
    PF_ASSERT(table.rows() == n && normals.size() == n);
    if (!clean_table(positions, table))
        return 0;
    const std::size_t blocks = (n + crease_refit_block - 1) / crease_refit_block;
    // Each block's refitted normals, applied once every block has read the old ones.
    std::vector<std::vector<std::pair<std::uint32_t, Vec3f>>> changed(blocks);
    parallel_blocks(n, crease_refit_block, [&](std::size_t begin, std::size_t end) {
        std::vector<std::pair<std::uint32_t, Vec3f>>& out = changed[begin / crease_refit_block];
        std::vector<std::uint32_t> row(table.k);
        CreaseNeighbourhood hood;
        for (std::size_t i = begin; i < end; ++i)
        {
            const Vec3f& normal = normals[i];
            if (!(normal.squaredNorm() > 0.5F))
                continue;
            // The sample first, as crease_plane() reads its neighbours.
            const std::span<const std::uint32_t> neighbors = table.neighbors(i);
            row[0] = static_cast<std::uint32_t>(i);
            std::size_t count = 1;
            for (const std::uint32_t j : neighbors)
                if (j != i && count < row.size())
                    row[count++] = j;
            const CreasePlane plane = crease_plane(hood, positions, normals,
                                                   std::span(row).first(count), i, normal, true);
            if (plane.refitted && plane.normal.allFinite())
                out.emplace_back(static_cast<std::uint32_t>(i), plane.normal);
        }
    });
    std::size_t count = 0;
    for (const auto& block : changed)
        for (const auto& [i, normal] : block)
        {
            normals[i] = normal;
            ++count;
        }
    return count;
}

} // namespace pointform::detail
