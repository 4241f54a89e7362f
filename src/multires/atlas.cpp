// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/multires/atlas.h"

#include "pointform/core/error.h"
#include "pointform/core/memory.h"
#include "pointform/core/parallel.h"
#include "pointform/multires/level_of_detail.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>
#include <numeric>
#include <string>

namespace pointform {

namespace {

/// A base triangle in its own plane: corner `first` at (0, 0), the next at (length, 0), the last
/// at (apex_x, height), height > 0; `first` starts the longest edge.
struct ChartShape
{
    int first = 0;
    double length = 0.0;
    double apex_x = 0.0;
    double height = 0.0;
};

/// A chart placed in a shelf: upright (longest edge at the shelf's bottom, apex up) or
/// inverted (turned by 180 degrees: longest edge at the shelf's top, apex down); texel
/// coordinates with y growing downwards.
struct Placement
{
    std::array<Vec2d, 3> corner; ///< the chart's corners first, first + 1, first + 2
    double top = 0.0;
    double bottom = 0.0;
    double right = 0.0;
};

/// The x of the boundary of a convex polygon at height y: its leftmost (`left`) or rightmost
/// crossing. \pre y within the polygon's extent
double boundary_x(const std::array<Vec2d, 3>& p, double y, bool left)
{
    double out =
        left ? std::numeric_limits<double>::infinity() : -std::numeric_limits<double>::infinity();
    for (int k = 0; k < 3; ++k)
    {
        const Vec2d& a = p[static_cast<std::size_t>(k)];
        const Vec2d& b = p[static_cast<std::size_t>((k + 1) % 3)];
        const double lo = std::min(a.y(), b.y());
        const double hi = std::max(a.y(), b.y());
        if (y < lo || y > hi)
            continue;
        const double x = hi == lo ? (left ? std::min(a.x(), b.x()) : std::max(a.x(), b.x()))
                                  : a.x() + (b.x() - a.x()) * (y - a.y()) / (b.y() - a.y());
        out = left ? std::min(out, x) : std::max(out, x);
    }
    return out;
}

/// The least shift to the right that puts `moving` a gutter `g` away from `fixed`: for every
/// pair of points less than g apart in y, at least g apart in x (so at least g apart). The
/// right boundary of `fixed` widened by g in y is concave and the left boundary of `moving`
/// convex, so their largest difference is at one of their breakpoints.
double clearance(const std::array<Vec2d, 3>& fixed, const std::array<Vec2d, 3>& moving, double g)
{
    double f_top = fixed[0].y();
    double f_bottom = fixed[0].y();
    double m_top = moving[0].y();
    double m_bottom = moving[0].y();
    std::size_t rightmost = 0;
    for (std::size_t k = 0; k < 3; ++k)
    {
        f_top = std::min(f_top, fixed[k].y());
        f_bottom = std::max(f_bottom, fixed[k].y());
        m_top = std::min(m_top, moving[k].y());
        m_bottom = std::max(m_bottom, moving[k].y());
        if (fixed[k].x() > fixed[rightmost].x())
            rightmost = k;
    }
    const double lo = std::max(m_top, f_top - g);
    const double hi = std::min(m_bottom, f_bottom + g);
    if (lo > hi)
        return -std::numeric_limits<double>::infinity(); // never within g in y
    const auto widened_right = [&](double y) {
        // max over |dy| <= g of the right boundary at y + dy: concave, so at the clamp of its peak.
        const double at =
            std::clamp(fixed[rightmost].y(), std::max(y - g, f_top), std::min(y + g, f_bottom));
        return boundary_x(fixed, at, false);
    };
    double need = -std::numeric_limits<double>::infinity();
    const auto consider = [&](double y) {
        if (y >= lo && y <= hi)
            need = std::max(need, widened_right(y) + g - boundary_x(moving, y, true));
    };
    consider(lo);
    consider(hi);
    for (std::size_t k = 0; k < 3; ++k)
    {
        consider(moving[k].y());
        consider(fixed[k].y() - g);
        consider(fixed[k].y());
        consider(fixed[k].y() + g);
    }
    return need;
}

/// Charts placed this far back in a row are checked against a new one.
constexpr std::size_t packing_window = 8;

/// Shelf packing at `scale` texels a world unit: rows left to right, the tallest charts first,
/// each chart upright or inverted, whichever lets it sit further left against the charts before
/// it in its row (so triangles interleave like a strip), a gutter apart from every other chart
/// and from the texture's border by half a gutter; false if they do not fit in size × size.
bool pack(std::span<const ChartShape> shapes, std::span<const std::uint32_t> order, double scale,
          int size, int gutter, std::vector<Placement>& placed)
{
    const double side = size;
    const double g = gutter;
    const double inset = 0.5 * g;
    double row_top = inset; // the current row's top
    double row_height = -1.0;
    std::vector<std::uint32_t> row;
    for (const std::uint32_t f : order)
    {
        const ChartShape& s = shapes[f];
        const double length = s.length * scale;
        const double height = s.height * scale;
        const double apex = s.apex_x * scale;
        if (length + 2 * inset > side)
            return false;
        const auto place = [&](double top, double row_h, bool inverted) {
            Placement p;
            if (inverted)
                p.corner = {Vec2d(length, top), Vec2d(0.0, top),
                            Vec2d(length - apex, top + height)};
            else
                p.corner = {Vec2d(0.0, top + row_h), Vec2d(length, top + row_h),
                            Vec2d(apex, top + row_h - height)};
            double shift = inset;
            const std::size_t from = row.size() > packing_window ? row.size() - packing_window : 0;
            for (std::size_t r = from; r < row.size(); ++r)
                shift = std::max(shift, clearance(placed[row[r]].corner, p.corner, g));
            for (Vec2d& c : p.corner)
                c.x() += shift;
            p.right = std::max({p.corner[0].x(), p.corner[1].x(), p.corner[2].x()});
            p.top = std::min({p.corner[0].y(), p.corner[1].y(), p.corner[2].y()});
            p.bottom = std::max({p.corner[0].y(), p.corner[1].y(), p.corner[2].y()});
            return p;
        };
        if (row_height < 0.0)
            row_height = height; // the first (tallest) chart of a row sets its height
        Placement best = place(row_top, row_height, false);
        const Placement turned = place(row_top, row_height, true);
        if (turned.right < best.right)
            best = turned;
        if (best.right + inset > side)
        {
            // A new row below, at least a gutter under every chart of this one.
            double bottom = row_top;
            for (const std::uint32_t r : row)
                bottom = std::max(bottom, placed[r].bottom);
            row_top = bottom + g;
            row_height = height;
            row.clear();
            best = place(row_top, row_height, false);
        }
        if (best.bottom + inset > side)
            return false;
        placed[f] = best;
        row.push_back(f);
    }
    return true;
}

std::size_t next_power_of_two(double value)
{
    return std::bit_ceil(static_cast<std::size_t>(std::ceil(std::max(value, 1.0))));
}

/// (u, v) with v pointing up: the orientation in which charts are counter-clockwise.
Vec2d upright(const Vec2d& uv)
{
    return {uv.x(), -uv.y()};
}

double cross2(const Vec2d& a, const Vec2d& b)
{
    return a.x() * b.y() - a.y() * b.x();
}

} // namespace

Atlas make_atlas(const MultiresMesh& mesh, std::size_t level, const AtlasOptions& options)
{
    if (mesh.level_count() == 0)
        throw InvalidInput("atlas: the hierarchy is empty");
    check_level(mesh, level);
    if (options.size != 0 && (options.size < min_atlas_size || options.size > max_atlas_size))
        throw InvalidInput("atlas: texture size " + std::to_string(options.size) + " is outside " +
                           std::to_string(min_atlas_size) + " to " +
                           std::to_string(max_atlas_size));
    if (options.gutter < 1 || options.gutter > 64)
        throw InvalidInput("atlas: gutter " + std::to_string(options.gutter) +
                           " is outside 1 to 64 texels");
    const std::span<const Triangle> faces = mesh.base_faces();
    std::vector<ChartShape> shapes(faces.size());
    double largest = 0.0;
    for (std::size_t f = 0; f < faces.size(); ++f)
    {
        std::array<Vec3d, 3> p;
        for (int k = 0; k < 3; ++k)
            p[static_cast<std::size_t>(k)] =
                mesh.positions()[faces[f][static_cast<std::size_t>(k)]];
        ChartShape& s = shapes[f];
        for (int k = 0; k < 3; ++k)
        {
            const double l =
                (p[static_cast<std::size_t>((k + 1) % 3)] - p[static_cast<std::size_t>(k)]).norm();
            if (l > s.length)
            {
                s.length = l;
                s.first = k;
            }
        }
        const Vec3d& a = p[static_cast<std::size_t>(s.first)];
        const Vec3d& b = p[static_cast<std::size_t>((s.first + 1) % 3)];
        const Vec3d& c = p[static_cast<std::size_t>((s.first + 2) % 3)];
        const Vec3d along = (b - a) / s.length;
        s.apex_x = (c - a).dot(along);
        s.height = (c - a).cross(along).norm();
        if (!(s.height > 1e-12 * s.length) || !std::isfinite(s.height))
            throw InvalidInput("atlas: base face " + std::to_string(f) +
                               " has no area: it cannot be a chart");
        largest = std::max(largest, s.length);
    }

    Atlas atlas;
    atlas.gutter = options.gutter;
    if (options.size != 0)
        atlas.size = options.size;
    else
    {
        // About 8 texels a face of the level, every chart at least 16 texels across, for a
        // packing that covers at least 45% of the texture (60% with interleaved shelves; the
        // margin gives level J more texels a face).
        const double by_faces = std::sqrt(8.0 * static_cast<double>(mesh.face_count(level)) / 0.45);
        const double by_charts = std::sqrt(128.0 * static_cast<double>(faces.size()) / 0.45);
        atlas.size = static_cast<int>(
            std::clamp<std::size_t>(next_power_of_two(std::max(by_faces, by_charts)), 256, 8192));
    }
    // The colour texture, a normal map and the baking's per-texel buffers.
    const double texels = static_cast<double>(atlas.size) * atlas.size;
    check_memory(texels * 40.0,
                 "a texture of " + std::to_string(atlas.size) + " x " + std::to_string(atlas.size) +
                     " texels",
                 "choose a smaller --size");

    // The tallest charts first; the largest scale at which the shelves fit (bisection).
    std::vector<std::uint32_t> order(faces.size());
    std::iota(order.begin(), order.end(), 0U);
    std::stable_sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
        return shapes[a].height > shapes[b].height;
    });
    std::vector<Placement> placed(faces.size());
    double lo = 0.0;
    double hi = (atlas.size - atlas.gutter) / largest;
    const auto too_small = [&] {
        return InvalidInput("atlas: " + std::to_string(faces.size()) + " charts with gutters of " +
                            std::to_string(atlas.gutter) + " texels do not fit in " +
                            std::to_string(atlas.size) + " x " + std::to_string(atlas.size) +
                            " texels; choose a larger --size");
    };
    if (!pack(shapes, order, 0.0, atlas.size, atlas.gutter, placed))
        throw too_small();
    for (int step = 0; step < 40; ++step)
    {
        const double mid = 0.5 * (lo + hi);
        (pack(shapes, order, mid, atlas.size, atlas.gutter, placed) ? lo : hi) = mid;
    }
    // Gutters alone filling the texture leave the charts no size: the longest under a texel
    // (none at all where only points fit) would texture nothing.
    if (!(lo * largest >= 1.0))
        throw too_small();
    (void)pack(shapes, order, lo, atlas.size, atlas.gutter, placed);
    atlas.texels_per_unit = lo;

    atlas.corners.resize(faces.size());
    double covered = 0.0;
    for (std::size_t f = 0; f < faces.size(); ++f)
    {
        const ChartShape& s = shapes[f];
        auto& c = atlas.corners[f];
        for (int k = 0; k < 3; ++k)
            c[static_cast<std::size_t>((s.first + k) % 3)] =
                placed[f].corner[static_cast<std::size_t>(k)] / atlas.size;
        covered += 0.5 * s.length * s.height * lo * lo;
    }
    atlas.texel_usage = covered / texels;
    return atlas;
}

TexturedMesh textured_levels(const MultiresMesh& mesh, const Parameterization& parameterization,
                             const Atlas& atlas, std::span<const std::size_t> levels)
{
    check_levels(mesh, levels);
    const std::size_t finest = levels.back();
    const std::vector<Triangle> faces = mesh.faces(finest);
    const unsigned shift = static_cast<unsigned>(2 * finest);

    // One vertex per (vertex, chart) pair, sorted by vertex: vertex ids grow with the level, so
    // each level's pairs are a prefix.
    std::vector<std::uint64_t> keys;
    keys.reserve(3 * faces.size() / 2 + 16);
    for (std::size_t f = 0; f < faces.size(); ++f)
    {
        const auto chart = static_cast<std::uint64_t>(f >> shift);
        for (const std::uint32_t v : faces[f])
            keys.push_back((std::uint64_t{v} << 32) | chart);
    }
    parallel_sort(keys);
    keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
    const auto index_of = [&](std::uint32_t v, std::uint64_t chart) {
        const std::uint64_t key = (std::uint64_t{v} << 32) | chart;
        return static_cast<std::uint32_t>(std::lower_bound(keys.begin(), keys.end(), key) -
                                          keys.begin());
    };

    TexturedMesh out;
    out.origin = mesh.origin();
    const std::size_t n = keys.size();
    out.positions.resize(n);
    out.uvs.resize(n);
    parallel_blocks(n, 4096, [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i)
        {
            const auto v = static_cast<std::uint32_t>(keys[i] >> 32);
            const auto chart = static_cast<std::uint32_t>(keys[i] & 0xffffffffU);
            out.positions[i] = mesh.positions()[v].cast<float>();
            out.uvs[i] = atlas.uv(chart, parameterization.coordinates_in(chart, v)).cast<float>();
        }
    });
    for (const std::size_t level : levels)
    {
        const std::vector<Triangle> level_faces = level == finest ? faces : mesh.faces(level);
        const unsigned level_shift = static_cast<unsigned>(2 * level);
        std::vector<Triangle> triangles(level_faces.size());
        parallel_blocks(level_faces.size(), 4096, [&](std::size_t begin, std::size_t end) {
            for (std::size_t f = begin; f < end; ++f)
                for (int k = 0; k < 3; ++k)
                    triangles[f][static_cast<std::size_t>(k)] =
                        index_of(level_faces[f][static_cast<std::size_t>(k)], f >> level_shift);
        });
        out.lods.push_back(std::move(triangles));
        out.lod_vertex_counts.push_back(static_cast<std::size_t>(
            std::lower_bound(keys.begin(), keys.end(),
                             std::uint64_t{mesh.vertex_count(level)} << 32) -
            keys.begin()));
        out.lod_levels.push_back(level);
    }

    // Normals: area-weighted over the finest level's faces, per hierarchy vertex. Tangents: per
    // (vertex, chart), the area-weighted surface direction of +u, and the sign of image-up (−v).
    const std::span<const Vec3d> x = mesh.positions();
    const std::vector<Vec3d> vertex_normal = vertex_normals(x, faces, mesh.vertex_count(finest));
    std::vector<Vec3d> tangent(n, Vec3d::Zero());
    std::vector<Vec3d> bitangent(n, Vec3d::Zero());
    const std::vector<Triangle>& finest_triangles = out.lods.back();
    for (std::size_t f = 0; f < faces.size(); ++f)
    {
        const Triangle& t = faces[f];
        const Vec3d e1 = x[t[1]] - x[t[0]];
        const Vec3d e2 = x[t[2]] - x[t[0]];
        const Vec3d area_normal = e1.cross(e2);
        const Triangle& c = finest_triangles[f];
        const Vec2d d1 = (out.uvs[c[1]] - out.uvs[c[0]]).cast<double>();
        const Vec2d d2 = (out.uvs[c[2]] - out.uvs[c[0]]).cast<double>();
        const double det = cross2(d1, d2);
        if (det == 0.0)
            continue;
        const Vec3d along_u = (e1 * d2.y() - e2 * d1.y()) / det;
        const Vec3d along_v = (e2 * d1.x() - e1 * d2.x()) / det;
        const double weight = 0.5 * area_normal.norm();
        for (const std::uint32_t i : c)
        {
            tangent[i] += weight * along_u;
            bitangent[i] -= weight * along_v; // image up
        }
    }
    out.normals.resize(n);
    out.tangents.resize(n);
    parallel_blocks(n, 4096, [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i)
        {
            const auto v = static_cast<std::uint32_t>(keys[i] >> 32);
            const Vec3d& normal = vertex_normal[v];
            Vec3d t = tangent[i] - tangent[i].dot(normal) * normal;
            if (!(t.norm() > 0.0))
                t = normal.unitOrthogonal();
            t.normalize();
            const double w = normal.cross(t).dot(bitangent[i]) < 0.0 ? -1.0 : 1.0;
            out.normals[i] = normal.cast<float>();
            out.tangents[i] = Eigen::Vector4f(static_cast<float>(t.x()), static_cast<float>(t.y()),
                                              static_cast<float>(t.z()), static_cast<float>(w));
        }
    });
    return out;
}

std::vector<AtlasDistortion> atlas_distortion(const MultiresMesh& mesh,
                                              const Parameterization& parameterization,
                                              const Atlas& atlas,
                                              std::span<const std::size_t> levels)
{
    check_levels(mesh, levels);
    std::vector<AtlasDistortion> out;
    const std::span<const Vec3d> x = mesh.positions();
    for (const std::size_t level : levels)
    {
        const std::vector<Triangle> faces = mesh.faces(level);
        const unsigned shift = static_cast<unsigned>(2 * level);
        struct FaceStretch
        {
            double area3 = 0.0; // surface area
            double area2 = 0.0; // texture area (0 if flipped)
            double sum2 = 0.0;  // (Γ² + γ²) / 2, unnormalised
            double big = 0.0;   // Γ
            double small = 0.0; // γ
            bool flipped = false;
        };
        std::vector<FaceStretch> per(faces.size());
        parallel_blocks(faces.size(), 4096, [&](std::size_t begin, std::size_t end) {
            for (std::size_t f = begin; f < end; ++f)
            {
                const auto chart = static_cast<std::uint32_t>(f >> shift);
                std::array<Vec2d, 3> s;
                for (int k = 0; k < 3; ++k)
                    s[static_cast<std::size_t>(k)] =
                        upright(atlas.uv(chart, parameterization.coordinates_in(
                                                    chart, faces[f][static_cast<std::size_t>(k)])));
                const Vec3d& q0 = x[faces[f][0]];
                const Vec3d& q1 = x[faces[f][1]];
                const Vec3d& q2 = x[faces[f][2]];
                FaceStretch& r = per[f];
                r.area3 = 0.5 * (q1 - q0).cross(q2 - q0).norm();
                const double area2 = 0.5 * cross2(s[1] - s[0], s[2] - s[0]);
                if (!(area2 > 0.0))
                {
                    r.flipped = true;
                    continue;
                }
                r.area2 = area2;
                // Sander et al.: the partial derivatives of the surface point along s and t.
                const Vec3d ds = (q0 * (s[1].y() - s[2].y()) + q1 * (s[2].y() - s[0].y()) +
                                  q2 * (s[0].y() - s[1].y())) /
                                 (2.0 * area2);
                const Vec3d dt = (q0 * (s[2].x() - s[1].x()) + q1 * (s[0].x() - s[2].x()) +
                                  q2 * (s[1].x() - s[0].x())) /
                                 (2.0 * area2);
                const double a = ds.dot(ds);
                const double b = ds.dot(dt);
                const double c = dt.dot(dt);
                const double root = std::sqrt((a - c) * (a - c) + 4.0 * b * b);
                r.sum2 = 0.5 * (a + c);
                r.big = std::sqrt(std::max(0.0, 0.5 * (a + c + root)));
                r.small = std::sqrt(std::max(0.0, 0.5 * (a + c - root)));
            }
        });
        AtlasDistortion d;
        d.level = level;
        d.faces = faces.size();
        double total3 = 0.0;
        double total2 = 0.0;
        for (const FaceStretch& r : per)
        {
            total3 += r.area3;
            total2 += r.area2;
        }
        // Normalise so that the texture's total area matches the surface's.
        const double scale = total3 > 0.0 ? std::sqrt(total2 / total3) : 1.0;
        double weighted = 0.0;
        double weight = 0.0;
        std::size_t measured = 0;
        for (const FaceStretch& r : per)
        {
            if (r.flipped)
            {
                ++d.flipped;
                continue;
            }
            weighted += r.area3 * r.sum2 * scale * scale;
            weight += r.area3;
            d.linf_stretch = std::max(d.linf_stretch, r.big * scale);
            if (r.small > 0.0)
            {
                d.angle_distortion += r.big / r.small - 1.0;
                d.area_distortion += std::abs(std::log(r.big * r.small * scale * scale));
                ++measured;
            }
        }
        d.l2_stretch = weight > 0.0 ? std::sqrt(weighted / weight) : 0.0;
        if (measured > 0)
        {
            d.angle_distortion /= static_cast<double>(measured);
            d.area_distortion /= static_cast<double>(measured);
        }
        out.push_back(d);
    }
    return out;
}

} // namespace pointform
