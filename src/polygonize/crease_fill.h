// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include "pointform/core/types.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <vector>

namespace pointform::detail {

/// crease_fill_for_rim(): the rim's normals fall into faces when at least this share of them lie
/// within crease_face_spread of their face's mean normal ...
constexpr double crease_face_share = 0.75;
/// ... (30°) ...
constexpr double crease_face_spread = 0.8660254037844386;
/// ... every face holds at least this share of the rim's normals (and three of them) ...
constexpr double crease_least_face_share = 0.05;
/// ... and the faces' mean normals are at least 40° apart (cos 40°) ...
constexpr double crease_least_turn = 0.766044443118978;
/// ... and apart by at least this many times the larger root-mean-square angle of a face's normals
/// from its mean: a rim on a smooth curved surface (a hole in a sphere) has normals that turn
/// evenly, and split in two its halves are about twice their own spread apart, while the faces of
/// a crease are each nearly flat beside it.
constexpr double crease_turn_over_spread = 3.0;
/// ... unless the rim is no single smooth face (its one-face fit, fit_face() over every rim vertex
/// about the mean normal, leaves heights of at least crease_kinked_rim times the rim's spread,
/// root mean square): then the shares and spreads are taken about each face's normal as fitted
/// (a curved face's normals turn with it), after the parting is refined by the fitted faces
/// (crease_regroup_rounds), and the faces must turn by crease_kinked_turn_over_spread times that
/// spread. Measured on the seven deep holes of a noisy 1M blobby (`pointform sample blobby
/// --noise 0.002 --holes 8 --hole-radius 0.04`, seed 7, the held vertices' normals): the two on
/// one ball 0.025 (a quadratic holds a sphere's cap), the five on the seam of two balls 0.13 to
/// 0.18; their faces held 91% to 94% of the normals within 30° of the fitted faces (64% to 84% of
/// their means) at 13° to 16° root mean square, turning by 50° to 64°. A face the scanner never
/// saw, whose rim runs round several faces of a bracket, 0.09, but 65% to 71% within.
constexpr double crease_kinked_rim = 0.06;
constexpr double crease_kinked_turn_over_spread = 2.0;
/// ... and the faces' envelope must pass through the rim vertices closer than this share of the
/// one-face fit's heights (root mean square): the crease explains the rim where one smooth face
/// does not. The five seams of that blobby: 0.11 to 0.42; a hole on the seam of a 100k noisy
/// blobby (seed 1) whose fill, from 27 vertices of one ball's rim, lay up to 0.057 from the
/// truth across the hole (the mesh's Chamfer 0.0626 -> 0.0641% of the diagonal): 0.52.
constexpr double crease_kinked_fit_gain = 0.5;
/// Rounds in which crease_fill_for_rim() moves rim vertices to the face that fits them best
/// (crease_fill_internal::crease_regroup_cost()) and fits the faces again.
constexpr std::size_t crease_regroup_rounds = 8;
/// The pull of a face's curvature terms towards zero, per rim vertex, in the normal equations of
/// its fit (coordinates in units of the rim's spread): a short arc of rim leaves them loose.
constexpr double crease_face_stiffness = 1e-3;
/// A parting into three faces is taken over one into two when it holds at least this share
/// more of the rim's normals within a face.
constexpr double crease_third_face_gain = 0.05;
/// The faces' planes agree on the crease's kind (convex or concave) when the mean of each face's
/// value at the other faces' rim vertices is beyond this share of the rim's root-mean-square
/// spread, on the same side for every pair.
constexpr double crease_kind_margin = 0.05;

/// \brief The faces that meet at a crease across a region that no sample supports (a hole over a
/// crease, a plate's rim, a cone's acute edge), from the region's rim: the held vertices next to
/// it, with the held surface's normals there.
///
/// Each face is a quadratic height field over its mean plane, fitted to its rim vertices'
/// heights and slopes (crease_fill_internal::fit_face()) and carried across the region, and the
/// surface across is where the faces meet: the zero set of max_g f_g at a convex crease (the
/// solid lies under every face there), of min_g f_g at a concave one. A thin plate, the
/// smoothest surface that continues the rim, cuts such a crease's corner by about the region's
/// radius times the turn; the faces meet at it. The slopes make an arc of rim fix a face's
/// curvature too, so that curved faces (two spheres' seam) keep it across the region where
/// their planes would sag by about ρ² / 2R (radius ρ, curvature radius R).
struct CreaseFill
{
    /// One face: a height field over the plane through `origin` with normal `axis`,
    /// h(u, v) = a u² + b uv + c v² + d u + e v + f in units of `scale` (u, v along `tangent`
    /// and axis × tangent).
    struct Face
    {
        Vec3d origin = Vec3d::Zero();
        Vec3d axis = Vec3d::UnitZ();
        Vec3d tangent = Vec3d::UnitX();
        double scale = 1.0;
        std::array<double, 6> height{};
    };
    std::vector<Face> faces;
    bool convex = true; ///< the crease's kind: max of the faces' values, else min
    /// The faces were fitted as curved faces to a kinked rim (crease_kinked_rim): the faired
    /// surface across may lie on either side of them (a thin plate across a seam of two balls
    /// cuts the convex way along the seam and the concave way across it).
    bool curved = false;

    /// Where x lies over face g's plane: d = (x - origin) / scale and its coordinates u, v
    /// along the tangent and the bitangent (axis × tangent).
    struct Local
    {
        Vec3d d;
        Vec3d bitangent;
        double u;
        double v;
    };
    [[nodiscard]] Local local(std::size_t g, const Vec3d& x) const
    {
        const Face& face = faces[g];
        const Vec3d d = (x - face.origin) / face.scale;
        const Vec3d bitangent = face.axis.cross(face.tangent);
        return {d, bitangent, d.dot(face.tangent), d.dot(bitangent)};
    }

    /// Face g's signed height at x: positive outside (along its axis), world units.
    [[nodiscard]] double face_value(std::size_t g, const Vec3d& x) const
    {
        const Face& face = faces[g];
        const auto [d, bitangent, u, v] = local(g, x);
        const auto& c = face.height;
        const double h = c[0] * u * u + c[1] * u * v + c[2] * v * v + c[3] * u + c[4] * v + c[5];
        return (d.dot(face.axis) - h) * face.scale;
    }

    /// Face g's unit normal at x (the gradient of face_value()).
    [[nodiscard]] Vec3d face_normal(std::size_t g, const Vec3d& x) const
    {
        const Face& face = faces[g];
        const auto [d, bitangent, u, v] = local(g, x);
        const auto& c = face.height;
        const double du = 2.0 * c[0] * u + c[1] * v + c[3];
        const double dv = c[1] * u + 2.0 * c[2] * v + c[4];
        return (face.axis - du * face.tangent - dv * bitangent).normalized();
    }

    /// The envelope of the faces but `skipped` at x (of every face when `skipped` is none).
    [[nodiscard]] double envelope(const Vec3d& x, std::size_t skipped) const
    {
        double out = 0.0;
        bool first = true;
        for (std::size_t g = 0; g < faces.size(); ++g)
        {
            if (g == skipped)
                continue;
            const double v = face_value(g, x);
            out = first ? v : convex ? std::max(out, v) : std::min(out, v);
            first = false;
        }
        return out;
    }

    /// The face whose value is the envelope's at x (the first of equals).
    [[nodiscard]] std::size_t active_face(const Vec3d& x) const
    {
        std::size_t active = 0;
        double best = face_value(0, x);
        for (std::size_t g = 1; g < faces.size(); ++g)
        {
            const double v = face_value(g, x);
            if (convex ? v > best : v < best)
            {
                best = v;
                active = g;
            }
        }
        return active;
    }

    /// The envelope of the faces at x: its zero set is the surface across the region.
    [[nodiscard]] double value(const Vec3d& x) const { return envelope(x, faces.size()); }
};

namespace crease_fill_internal {

inline double angle_of(double cosine)
{
    return std::acos(std::clamp(cosine, -1.0, 1.0));
}

/// The root-mean-square distance of points from their centroid (0 for none).
inline double rms_spread(std::span<const Vec3d> points)
{
    if (points.empty())
        return 0.0;
    Vec3d centre = Vec3d::Zero();
    for (const Vec3d& p : points)
        centre += p;
    centre /= static_cast<double>(points.size());
    double squared = 0.0;
    for (const Vec3d& p : points)
        squared += (p - centre).squaredNorm();
    return std::sqrt(squared / static_cast<double>(points.size()));
}

/// The unit mean of each of the `k` groups of unit vectors (`group[i]`: unit[i]'s), or nothing
/// when a group's sum is zero (empty, or its vectors cancel).
inline std::optional<std::vector<Vec3d>> group_means(std::span<const Vec3d> unit,
                                                     std::span<const std::uint8_t> group,
                                                     std::size_t k)
{
    std::vector<Vec3d> sum(k, Vec3d::Zero());
    for (std::size_t i = 0; i < unit.size(); ++i)
        sum[group[i]] += unit[i];
    for (Vec3d& s : sum)
    {
        const double length = s.norm();
        if (!(length > 0.0))
            return std::nullopt;
        s /= length;
    }
    return sum;
}

/// Spherical k-means of unit vectors into `k` groups from farthest-point seeds after unit[first]:
/// the group of each vector and the groups' unit means; nothing when a group is left empty.
inline std::optional<std::pair<std::vector<std::uint8_t>, std::vector<Vec3d>>> group_directions(
    std::span<const Vec3d> unit, std::size_t k, std::size_t first)
{
    const std::size_t n = unit.size();
    std::vector<Vec3d> mean;
    std::vector<double> nearest(n, 2.0);
    std::size_t pick = first;
    while (mean.size() < k)
    {
        mean.push_back(unit[pick]);
        for (std::size_t i = 0; i < n; ++i)
            nearest[i] = std::min(nearest[i], 1.0 - unit[i].dot(unit[pick]));
        pick = static_cast<std::size_t>(std::max_element(nearest.begin(), nearest.end()) -
                                        nearest.begin());
    }
    std::vector<std::uint8_t> group(n, 0);
    for (int round = 0; round < 16; ++round)
    {
        bool moved = false;
        for (std::size_t i = 0; i < n; ++i)
        {
            std::uint8_t best = 0;
            for (std::size_t g = 1; g < k; ++g)
                if (unit[i].dot(mean[g]) > unit[i].dot(mean[best]))
                    best = static_cast<std::uint8_t>(g);
            moved = moved || best != group[i];
            group[i] = best;
        }
        std::optional<std::vector<Vec3d>> means = group_means(unit, group, k);
        if (!means)
            return std::nullopt;
        mean = std::move(*means);
        if (!moved && round > 0)
            break;
    }
    return std::pair{std::move(group), std::move(mean)};
}

/// The number of unit vectors within crease_face_spread of their group's mean.
inline std::size_t count_within(std::span<const Vec3d> unit, std::span<const std::uint8_t> group,
                                std::span<const Vec3d> mean)
{
    std::size_t within = 0;
    for (std::size_t i = 0; i < unit.size(); ++i)
        within += unit[i].dot(mean[group[i]]) >= crease_face_spread ? 1U : 0U;
    return within;
}

/// group_directions() from several first seeds (the direction farthest from the mean, the two
/// ends of the directions' widest spread, and three spread over the list), the grouping that
/// holds the most directions within crease_face_spread of their group's mean (the first of
/// equals): one start can settle on a few outlying normals against all the rest.
inline std::optional<std::pair<std::vector<std::uint8_t>, std::vector<Vec3d>>> best_grouping(
    std::span<const Vec3d> unit, std::size_t k)
{
    const std::size_t n = unit.size();
    Vec3d all = Vec3d::Zero();
    for (const Vec3d& u : unit)
        all += u;
    const Vec3d centre = all / static_cast<double>(n);
    Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
    for (const Vec3d& u : unit)
        scatter += (u - centre) * (u - centre).transpose();
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(scatter);
    const Vec3d widest = eigen.eigenvectors().col(2);
    std::array<std::size_t, 6> firsts{0, 0, 0, 0, n / 3, 2 * n / 3};
    for (std::size_t i = 1; i < n; ++i)
    {
        if (unit[i].dot(all) < unit[firsts[0]].dot(all))
            firsts[0] = i;
        if (unit[i].dot(widest) < unit[firsts[1]].dot(widest))
            firsts[1] = i;
        if (unit[i].dot(widest) > unit[firsts[2]].dot(widest))
            firsts[2] = i;
    }
    std::optional<std::pair<std::vector<std::uint8_t>, std::vector<Vec3d>>> best;
    std::size_t best_within = 0;
    for (const std::size_t first : firsts)
    {
        auto grouped = group_directions(unit, k, first);
        if (!grouped)
            continue;
        const std::size_t within = count_within(unit, grouped->first, grouped->second);
        if (!best || within > best_within)
        {
            best = std::move(grouped);
            best_within = within;
        }
    }
    return best;
}

/// Least-squares height field of one face (CreaseFill::Face) through its rim vertices `at` with
/// their unit `normals`: each vertex's height and, where the face is not steep there, its two
/// slopes, so that an arc of a rim fixes the face's curvature across the region too. The
/// curvature terms are pulled slightly towards zero (a short arc leaves them loose).
inline std::optional<CreaseFill::Face> fit_face(std::span<const Vec3d> at,
                                                std::span<const Vec3d> normals, const Vec3d& axis,
                                                double scale)
{
    CreaseFill::Face face;
    face.axis = axis;
    face.scale = scale;
    for (const Vec3d& p : at)
        face.origin += p;
    face.origin /= static_cast<double>(at.size());
    face.tangent =
        (std::abs(axis.x()) < 0.9 ? Vec3d::UnitX() : Vec3d::UnitY()).cross(axis).normalized();
    const Vec3d bitangent = axis.cross(face.tangent);
    Eigen::Matrix<double, 6, 6> normal_matrix = Eigen::Matrix<double, 6, 6>::Zero();
    Eigen::Matrix<double, 6, 1> right = Eigen::Matrix<double, 6, 1>::Zero();
    const auto add = [&](const Eigen::Matrix<double, 6, 1>& row, double value) {
        normal_matrix += row * row.transpose();
        right += row * value;
    };
    for (std::size_t j = 0; j < at.size(); ++j)
    {
        const Vec3d d = (at[j] - face.origin) / scale;
        const double u = d.dot(face.tangent);
        const double v = d.dot(bitangent);
        add((Eigen::Matrix<double, 6, 1>() << u * u, u * v, v * v, u, v, 1.0).finished(),
            d.dot(axis));
        const double up = normals[j].dot(axis);
        if (up < crease_face_spread)
            continue;
        // ∂h/∂u = −n_u / n_h and ∂h/∂v = −n_v / n_h.
        add((Eigen::Matrix<double, 6, 1>() << 2.0 * u, v, 0.0, 1.0, 0.0, 0.0).finished(),
            -normals[j].dot(face.tangent) / up);
        add((Eigen::Matrix<double, 6, 1>() << 0.0, u, 2.0 * v, 0.0, 1.0, 0.0).finished(),
            -normals[j].dot(bitangent) / up);
    }
    for (int c = 0; c < 3; ++c)
        normal_matrix(c, c) += crease_face_stiffness * static_cast<double>(at.size());
    const Eigen::LDLT<Eigen::Matrix<double, 6, 6>> solver(normal_matrix);
    if (solver.info() != Eigen::Success)
        return std::nullopt;
    const Eigen::Matrix<double, 6, 1> x = solver.solve(right);
    if (!x.allFinite())
        return std::nullopt;
    for (int c = 0; c < 6; ++c)
        face.height[static_cast<std::size_t>(c)] = x(c);
    return face;
}

/// The root mean square of `fill`'s values at the rim vertices `at`, in units of the rim's
/// spread: how far its surface passes from them.
inline double fill_residual(const CreaseFill& fill, std::span<const Vec3d> at, double rim_spread)
{
    double squared = 0.0;
    for (const Vec3d& p : at)
        squared += fill.value(p) * fill.value(p);
    return std::sqrt(squared / static_cast<double>(at.size())) / rim_spread;
}

/// How badly face g of `fill` fits a rim vertex at `p` with unit normal `normal`: the cosine of
/// the angle between the normal and the face's there, negated, plus twice the vertex's height off
/// the face in units of the rim's spread (a twentieth of the spread off weighs as much as a
/// tenth of the cosine, about 26° from along).
inline double crease_regroup_cost(const CreaseFill& fill, std::size_t g, const Vec3d& p,
                                  const Vec3d& normal, double rim_spread)
{
    return -normal.dot(fill.face_normal(g, p)) + 2.0 * std::abs(fill.face_value(g, p)) / rim_spread;
}

/// How far the rim is from a single smooth face: the root mean square of the heights off the
/// height field fitted to every rim vertex over the plane of their mean normal (fit_face()), in
/// units of the rim's spread; infinite where the normals cancel, so that no plane carries them.
inline double one_face_residual(std::span<const Vec3d> at, std::span<const Vec3d> unit,
                                double rim_spread)
{
    Vec3d sum = Vec3d::Zero();
    for (const Vec3d& u : unit)
        sum += u;
    const double length = sum.norm();
    if (!(length > 0.5 * static_cast<double>(unit.size())))
        return std::numeric_limits<double>::infinity();
    const std::optional<CreaseFill::Face> face = fit_face(at, unit, sum / length, rim_spread);
    if (!face)
        return std::numeric_limits<double>::infinity();
    CreaseFill one;
    one.faces.push_back(*face);
    return fill_residual(one, at, rim_spread);
}

} // namespace crease_fill_internal

/// \brief The crease fill of a region from its rim (see CreaseFill), or nothing when the rim's
/// normals do not part into two or three nearly flat faces that meet at one kind of crease (a
/// smooth rim, whose region the thin plate fills). `rim` and `rim_normals` as fill_for_rim()'s.
[[nodiscard]] inline std::optional<CreaseFill> crease_fill_for_rim(
    std::span<const Vec3d> rim, std::span<const Vec3d> rim_normals)
{
    using crease_fill_internal::angle_of;
    if (rim.size() < 8 || rim_normals.size() != rim.size())
        return std::nullopt;
    std::vector<Vec3d> at;
    std::vector<Vec3d> unit;
    for (std::size_t i = 0; i < rim.size(); ++i)
    {
        const double length = rim_normals[i].norm();
        if (length > 0.0 && std::isfinite(length) && rim[i].allFinite())
        {
            at.push_back(rim[i]);
            unit.push_back(rim_normals[i] / length);
        }
    }
    const std::size_t n = unit.size();
    if (n < 8)
        return std::nullopt;
    // The rim parted into k faces, for k = 2 and 3: k = 3 where both do and it holds clearly
    // more of the normals within a face (a plate's rim: its two faces and the side between).
    struct Parting
    {
        std::vector<std::uint8_t> group;
        std::vector<Vec3d> mean;
        std::size_t within = 0;
    };
    const double rim_spread = crease_fill_internal::rms_spread(at);
    if (!(rim_spread > 0.0))
        return std::nullopt;
    // Each face of a parting fitted to its own rim vertices: those outside every face's spread
    // (the crease's own, whose normals are a blend of the faces') are left out.
    const auto fit_faces = [&](const Parting& parting) -> std::optional<CreaseFill> {
        const std::size_t k = parting.mean.size();
        std::vector<std::vector<Vec3d>> face_at(k);
        std::vector<std::vector<Vec3d>> face_normals(k);
        for (std::size_t i = 0; i < n; ++i)
            if (unit[i].dot(parting.mean[parting.group[i]]) >= crease_face_spread)
            {
                face_at[parting.group[i]].push_back(at[i]);
                face_normals[parting.group[i]].push_back(unit[i]);
            }
        CreaseFill fill;
        for (std::size_t g = 0; g < k; ++g)
        {
            std::optional<CreaseFill::Face> face =
                face_at[g].size() < 3 ? std::nullopt
                                      : crease_fill_internal::fit_face(face_at[g], face_normals[g],
                                                                       parting.mean[g], rim_spread);
            if (!face)
                return std::nullopt;
            fill.faces.push_back(*face);
        }
        // The crease's kind from every pair of faces: each face's value at the other's vertices.
        int convex = 0;
        int concave = 0;
        for (std::size_t a = 0; a < k; ++a)
            for (std::size_t b = 0; b < k; ++b)
            {
                if (a == b)
                    continue;
                double sum = 0.0;
                for (const Vec3d& p : face_at[b])
                    sum += fill.face_value(a, p);
                const double mean_value = sum / static_cast<double>(face_at[b].size());
                convex += mean_value < -crease_kind_margin * rim_spread ? 1 : 0;
                concave += mean_value > crease_kind_margin * rim_spread ? 1 : 0;
            }
        const auto pairs = static_cast<int>(k * (k - 1));
        if (convex != pairs && concave != pairs)
            return std::nullopt;
        fill.convex = convex == pairs;
        return fill;
    };
    // Whether a parting holds as faces: crease_face_share of the normals within
    // crease_face_spread of their face's direction at their vertex (`direction(i)`), every face
    // with three of them and crease_least_face_share of the rim, and the faces' mean normals
    // apart by crease_least_turn and by `turn_over_spread` times the larger root-mean-square
    // angle of a face's own normals from those directions. Sets the parting's `within`.
    const auto holds = [&](Parting& parting, const auto& direction, double turn_over_spread) {
        const std::size_t k = parting.mean.size();
        std::vector<std::size_t> size(k, 0);
        std::vector<std::size_t> own(k, 0);
        std::vector<double> squared(k, 0.0);
        for (std::size_t i = 0; i < n; ++i)
        {
            const std::uint8_t g = parting.group[i];
            const double cosine = unit[i].dot(direction(i));
            ++size[g];
            if (cosine >= crease_face_spread)
            {
                ++own[g];
                squared[g] += angle_of(cosine) * angle_of(cosine);
            }
        }
        parting.within = 0;
        for (std::size_t g = 0; g < k; ++g)
            parting.within += own[g];
        bool ok = static_cast<double>(parting.within) >= crease_face_share * static_cast<double>(n);
        double spread = 0.0;
        for (std::size_t g = 0; g < k; ++g)
        {
            ok = ok && own[g] >= 3 &&
                 static_cast<double>(size[g]) >= crease_least_face_share * static_cast<double>(n);
            if (own[g] > 0)
                spread = std::max(spread, std::sqrt(squared[g] / static_cast<double>(own[g])));
        }
        for (std::size_t a = 0; a < k; ++a)
            for (std::size_t b = a + 1; b < k; ++b)
            {
                const double cosine = parting.mean[a].dot(parting.mean[b]);
                ok = ok && cosine <= crease_least_turn &&
                     angle_of(cosine) >= turn_over_spread * spread;
            }
        return ok;
    };
    // A kinked rim's parting refined (crease_regroup_rounds): each rim vertex to the face that
    // fits it best (crease_regroup_cost()), the faces fitted again, until no vertex moves. Parted
    // by their normals alone, the vertices of curved faces under noisy normals fall partly to the
    // wrong face. The faces as last fitted, or nothing where a face is lost.
    const auto regroup = [&](Parting& parting) -> std::optional<CreaseFill> {
        const std::size_t k = parting.mean.size();
        std::optional<CreaseFill> fill;
        for (std::size_t round = 0; round <= crease_regroup_rounds; ++round)
        {
            fill = fit_faces(parting);
            if (!fill || round == crease_regroup_rounds)
                return fill;
            bool moved = false;
            for (std::size_t i = 0; i < n; ++i)
            {
                const std::uint8_t current = parting.group[i];
                std::uint8_t best = current;
                double least = crease_fill_internal::crease_regroup_cost(*fill, current, at[i],
                                                                         unit[i], rim_spread);
                for (std::size_t g = 0; g < k; ++g)
                {
                    if (g == current)
                        continue;
                    const double cost = crease_fill_internal::crease_regroup_cost(
                        *fill, g, at[i], unit[i], rim_spread);
                    if (cost < least)
                    {
                        least = cost;
                        best = static_cast<std::uint8_t>(g);
                    }
                }
                moved = moved || best != parting.group[i];
                parting.group[i] = best;
            }
            if (!moved)
                return fill;
            std::optional<std::vector<Vec3d>> means =
                crease_fill_internal::group_means(unit, parting.group, k);
            if (!means)
                return std::nullopt;
            parting.mean = std::move(*means);
        }
        return fill;
    };
    const double one_face = crease_fill_internal::one_face_residual(at, unit, rim_spread);
    const bool kinked = one_face >= crease_kinked_rim;
    std::optional<CreaseFill> chosen;
    std::size_t chosen_within = 0;
    for (std::size_t k = 2; k <= 3; ++k)
    {
        auto grouped = crease_fill_internal::best_grouping(unit, k);
        if (!grouped)
            continue;
        Parting parting{std::move(grouped->first), std::move(grouped->second), 0};
        std::optional<CreaseFill> fill;
        // Faces nearly flat about their mean normals ...
        if (holds(
                parting, [&](std::size_t i) { return parting.mean[parting.group[i]]; },
                crease_turn_over_spread))
            fill = fit_faces(parting);
        // ... or, on a kinked rim, about the curved faces fitted to them.
        else if (kinked)
        {
            fill = regroup(parting);
            if (fill)
                fill->curved = true;
            if (fill &&
                (!holds(
                     parting,
                     [&](std::size_t i) { return fill->face_normal(parting.group[i], at[i]); },
                     crease_kinked_turn_over_spread) ||
                 crease_fill_internal::fill_residual(*fill, at, rim_spread) >
                     crease_kinked_fit_gain * one_face))
                fill.reset();
        }
        if (fill && (!chosen || static_cast<double>(parting.within) >=
                                    static_cast<double>(chosen_within) +
                                        crease_third_face_gain * static_cast<double>(n)))
        {
            chosen = std::move(fill);
            chosen_within = parting.within;
        }
    }
    return chosen;
}

} // namespace pointform::detail
