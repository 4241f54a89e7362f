// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/spatial/feature_grid.h"

#include "pointform/core/error.h"
#include "pointform/core/parallel.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace pointform {

namespace {

/// site_distance2 of a node before any site is known.
constexpr std::uint32_t unreached = std::numeric_limits<std::uint32_t>::max();

/// Scratch for one line of nodes (a row or a column), reused along a block of lines.
struct LineScratch
{
    std::vector<std::uint32_t> value; ///< the line's squared distances before this pass
    std::vector<std::uint32_t> point; ///< and their representatives
    std::vector<std::uint32_t> apex;  ///< nodes whose parabolas form the lower envelope
    /// Where each envelope parabola starts to be the lowest: the rational start_num/start_den.
    std::vector<std::int64_t> start_num, start_den;

    explicit LineScratch(std::size_t n)
        : value(n), point(n), apex(n), start_num(n + 1), start_den(n + 1)
    {}
};

/// One pass of the separable transform along a line of `n` nodes, `stride` apart from `first`:
/// each node gets min over nodes q of the line of (value(q) + (node − q)²), with q's
/// representative (Felzenszwalb & Huttenlocher, "Distance transforms of sampled functions",
/// 2012). The parabolas' crossings are rationals compared exactly in 64-bit integers, so the
/// minimum is exact; where parabolas tie, the choice depends on the line's values alone.
void lower_envelope(FeatureGrid::Node* first, std::size_t n, std::size_t stride, LineScratch& line)
{
    for (std::size_t q = 0; q < n; ++q)
    {
        line.value[q] = first[q * stride].site_distance2;
        line.point[q] = first[q * stride].point;
    }
    const auto sq = [](std::int64_t x) {
        return x * x;
    };
    std::ptrdiff_t top = -1; // the last parabola of the envelope
    for (std::size_t q = 0; q < n; ++q)
    {
        if (line.value[q] == unreached)
        {
            continue;
        }
        const auto qi = static_cast<std::int64_t>(q);
        std::int64_t num = 0;
        std::int64_t den = 1;
        while (top >= 0)
        {
            const auto t = static_cast<std::size_t>(top);
            const auto p = static_cast<std::int64_t>(line.apex[t]);
            // The parabolas of p and q cross at s = (value(q) + q² − value(p) − p²) / 2(q − p).
            num = static_cast<std::int64_t>(line.value[q]) + sq(qi) -
                  static_cast<std::int64_t>(line.value[line.apex[t]]) - sq(p);
            den = 2 * (qi - p);
            // p's parabola is nowhere strictly lowest when s is at or before where it starts.
            if (top > 0 && num * line.start_den[t] <= line.start_num[t] * den)
            {
                --top;
                continue;
            }
            break;
        }
        ++top;
        const auto t = static_cast<std::size_t>(top);
        line.apex[t] = static_cast<std::uint32_t>(q);
        line.start_num[t] = num; // unused for the first parabola, which starts at −∞
        line.start_den[t] = den;
    }
    if (top < 0)
    {
        return; // no site reaches this line yet: it stays unreached
    }
    std::size_t j = 0;
    const auto last = static_cast<std::size_t>(top);
    for (std::size_t q = 0; q < n; ++q)
    {
        const auto qi = static_cast<std::int64_t>(q);
        // Move on while the next parabola starts strictly before q.
        while (j < last && line.start_num[j + 1] < qi * line.start_den[j + 1])
        {
            ++j;
        }
        const std::uint32_t p = line.apex[j];
        const std::int64_t d = qi - static_cast<std::int64_t>(p);
        FeatureGrid::Node& out = first[q * stride];
        out.site_distance2 = line.value[p] + static_cast<std::uint32_t>(d * d);
        out.point = line.point[p];
    }
}

/// The first pass, along a row of `n` nodes where the sites have distance 0 and the other nodes
/// are unreached: each node takes the nearest site of the row (the one before it on a tie),
/// as lower_envelope() would, in two sweeps.
void nearest_in_row(FeatureGrid::Node* row, std::size_t n)
{
    std::size_t previous = n; // the last site seen, n before the first
    for (std::size_t q = 0; q < n; ++q)
    {
        if (row[q].site_distance2 == 0)
        {
            previous = q;
        }
        else if (previous < n)
        {
            const std::size_t d = q - previous;
            row[q] = FeatureGrid::Node{.point = row[previous].point,
                                       .site_distance2 = static_cast<std::uint32_t>(d * d)};
        }
    }
    std::size_t next = n; // the nearest site after, n before one is seen
    for (std::size_t q = n; q-- > 0;)
    {
        if (row[q].site_distance2 == 0)
        {
            next = q;
        }
        else if (next < n)
        {
            const std::size_t d = next - q;
            // Strictly nearer only: a tie keeps the site before.
            if (static_cast<std::uint64_t>(d * d) < row[q].site_distance2)
            {
                row[q] = FeatureGrid::Node{.point = row[next].point,
                                           .site_distance2 = static_cast<std::uint32_t>(d * d)};
            }
        }
    }
}

} // namespace

FeatureGrid::FeatureGrid(std::span<const Vec3f> points, const Aabb& box, std::size_t max_nodes)
{
    if (points.empty())
    {
        throw InvalidInput("feature grid: no points");
    }
    if (points.size() >= std::numeric_limits<std::uint32_t>::max())
    {
        throw InvalidInput("feature grid: more than 2^32 - 1 points");
    }
    if (max_nodes < 2 || max_nodes > 1024)
    {
        throw InvalidInput("feature grid: nodes per side must be between 2 and 1024, not " +
                           std::to_string(max_nodes));
    }
    if (box.is_empty() || !box.min.allFinite() || !box.max.allFinite())
    {
        throw InvalidInput("feature grid: the box is empty or not finite");
    }
    const Vec3d size = box.size();
    const double longest = size.maxCoeff();
    origin_ = box.min;
    spacing_ = longest > 0.0 ? longest / static_cast<double>(max_nodes - 1) : 1.0;
    inv_spacing_ = 1.0 / spacing_;
    for (Eigen::Index a = 0; a < 3; ++a)
    {
        const double cells = std::ceil(size[a] * inv_spacing_);
        dims_[static_cast<std::size_t>(a)] = static_cast<std::uint32_t>(
            std::clamp(cells + 1.0, 2.0, static_cast<double>(max_nodes)));
    }
    const std::size_t nx = dims_[0];
    const std::size_t ny = dims_[1];
    const std::size_t nz = dims_[2];
    nodes_.assign(nx * ny * nz, Node{.point = 0, .site_distance2 = unreached});

    // Sites and their representatives, in index order so that ties keep the smallest index.
    double snap2 = 0.0;
    for (std::size_t i = 0; i < points.size(); ++i)
    {
        const Vec3f& p = points[i];
        if (!p.allFinite() || !box.contains(p.cast<double>()))
        {
            throw InvalidInput("feature grid: point " + std::to_string(i) +
                               " is not finite or outside the box");
        }
        const auto [x, y, z] = site_of(p);
        const Vec3d offset = p.cast<double>() - node_position(x, y, z);
        const double d2 = offset.squaredNorm();
        snap2 = std::max(snap2, d2);
        Node& site = nodes_[(static_cast<std::size_t>(z) * ny + y) * nx + x];
        if (site.site_distance2 == unreached ||
            d2 < (points[site.point].cast<double>() - node_position(x, y, z)).squaredNorm())
        {
            site = Node{.point = static_cast<std::uint32_t>(i), .site_distance2 = 0};
        }
    }
    // Rounded up past the rounding of the distances that lower bounds subtract it from.
    snap_radius_ = std::sqrt(snap2) * (1.0 + 1e-9) + 1e-9 * spacing_;

    // The separable transform: along x, then y, then z; each line on its own, so blocks of
    // lines in parallel give the same nodes whatever the thread count.
    const auto pass = [&](std::size_t lines, std::size_t length, std::size_t stride,
                          auto&& line_start) {
        parallel_blocks(lines, 64, [&](std::size_t begin, std::size_t end) {
            LineScratch scratch(length);
            for (std::size_t l = begin; l < end; ++l)
            {
                lower_envelope(nodes_.data() + line_start(l), length, stride, scratch);
            }
        });
    };
    // Rows along x: line l = y + ny z starts at l nx.
    parallel_blocks(ny * nz, 256, [&](std::size_t begin, std::size_t end) {
        for (std::size_t l = begin; l < end; ++l)
        {
            nearest_in_row(nodes_.data() + l * nx, nx);
        }
    });
    // Columns along y: line l = x + nx z starts at x + nx ny z (neighbouring lines share cache
    // lines).
    pass(nx * nz, ny, nx, [&](std::size_t l) { return (l % nx) + (l / nx) * nx * ny; });
    // Columns along z: line l = x + nx y starts at l.
    pass(nx * ny, nz, nx * ny, [&](std::size_t l) { return l; });
}

std::array<std::uint32_t, 3> FeatureGrid::site_of(const Vec3f& point) const
{
    std::array<std::uint32_t, 3> site{};
    for (std::size_t a = 0; a < 3; ++a)
    {
        const auto axis = static_cast<Eigen::Index>(a);
        const double t =
            std::round((static_cast<double>(point[axis]) - origin_[axis]) * inv_spacing_);
        site[a] = static_cast<std::uint32_t>(std::clamp(t, 0.0, static_cast<double>(dims_[a] - 1)));
    }
    return site;
}

double FeatureGrid::lower_bound(const Vec3d& p) const
{
    std::array<std::uint32_t, 3> nearest{};
    for (std::size_t a = 0; a < 3; ++a)
    {
        const auto axis = static_cast<Eigen::Index>(a);
        const double t = (p[axis] - origin_[axis]) * inv_spacing_;
        if (!(t >= 0.0 && t <= static_cast<double>(dims_[a] - 1)))
        {
            return 0.0;
        }
        nearest[a] = static_cast<std::uint32_t>(std::lround(t));
    }
    const auto [i, j, k] = nearest;
    const double site_distance =
        std::sqrt(static_cast<double>(node(i, j, k).site_distance2)) * spacing_;
    return site_distance - snap_radius_ - (p - node_position(i, j, k)).norm();
}

std::optional<FeatureGrid::CellQuery> FeatureGrid::query(const Vec3d& p) const
{
    std::array<std::uint32_t, 3> low{};
    for (std::size_t a = 0; a < 3; ++a)
    {
        const auto axis = static_cast<Eigen::Index>(a);
        const double t = (p[axis] - origin_[axis]) * inv_spacing_;
        // Written so that NaN fails too.
        if (!(t >= 0.0 && t <= static_cast<double>(dims_[a] - 1)))
        {
            return std::nullopt;
        }
        low[a] = std::min(static_cast<std::uint32_t>(t), dims_[a] - 2);
    }
    CellQuery out;
    out.lower_bound = -std::numeric_limits<double>::infinity();
    const std::size_t nx = dims_[0];
    const std::size_t ny = dims_[1];
    for (std::uint32_t corner = 0; corner < 8; ++corner)
    {
        const std::uint32_t i = low[0] + (corner & 1U);
        const std::uint32_t j = low[1] + ((corner >> 1U) & 1U);
        const std::uint32_t k = low[2] + ((corner >> 2U) & 1U);
        const Node& node = nodes_[(static_cast<std::size_t>(k) * ny + j) * nx + i];
        out.points[corner] = node.point;
        const double site_distance = std::sqrt(static_cast<double>(node.site_distance2)) * spacing_;
        out.lower_bound = std::max(
            out.lower_bound, site_distance - snap_radius_ - (p - node_position(i, j, k)).norm());
    }
    return out;
}

} // namespace pointform
