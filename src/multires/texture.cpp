// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/multires/texture.h"

#include "pointform/core/error.h"
#include "pointform/core/parallel.h"
#include "pointform/multires/level_of_detail.h"
#include "pointform/spatial/kd_tree.h"
#include "pointform/spatial/triangle_bvh.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <tuple>
#include <vector>

namespace pointform {

namespace {

TextureImage blank(const Atlas& atlas)
{
    TextureImage image;
    image.width = atlas.size;
    image.height = atlas.size;
    image.channels = 3;
    image.pixels.assign(static_cast<std::size_t>(atlas.size) * atlas.size * 3, 0);
    return image;
}

/// A texel next to a chart whose centre lies outside it: which chart, the barycentric
/// coordinates of the chart's point nearest to the centre, and that distance.
struct EdgeTexel
{
    std::size_t index = 0; ///< y * size + x
    double distance = 0.0;
    std::uint32_t chart = 0;
    Vec3d barycentric;
};

/// Calls texel(x, y, chart, barycentric) once for every texel that a chart covers (its
/// barycentric coordinates in the chart's base face): first every texel whose centre lies in a
/// chart, charts in parallel (no two share one: gutters of at least one texel lie between
/// them); then every other texel whose centre lies within half a diagonal (√2 / 2) of a chart,
/// at the chart's point nearest to the centre (the nearest chart's, ties to the lower index).
/// Conservative coverage: a chart smaller than a few texels, whose sub-triangles may hold no
/// texel centre, still gets every texel it touches (a 128-texel atlas of 240 charts had left
/// triangles that bilinear look-ups saw as black), and bilinear filtering at a chart's edge
/// reads texels of that chart.
template <typename Texel>
void for_each_chart_texel(const Atlas& atlas, Texel texel)
{
    const double size = atlas.size;
    constexpr double reach = 0.7071067811865476;
    const std::size_t charts = atlas.corners.size();
    constexpr std::size_t block = 8;
    std::vector<std::vector<EdgeTexel>> edges((charts + block - 1) / block);
    // Texels whose centre lies in a chart (each in one chart only: distinct bytes per thread).
    std::vector<char> inside(static_cast<std::size_t>(atlas.size) * atlas.size, 0);
    parallel_blocks(charts, block, [&](std::size_t begin, std::size_t end) {
        std::vector<EdgeTexel>& found = edges[begin / block];
        for (std::size_t f = begin; f < end; ++f)
        {
            const auto& c = atlas.corners[f];
            const Vec2d a = c[0] * size;
            const Vec2d b = c[1] * size;
            const Vec2d d = c[2] * size;
            const double area = (b - a).x() * (d - a).y() - (b - a).y() * (d - a).x();
            if (area == 0.0)
                continue;
            const Vec2d lo = a.cwiseMin(b).cwiseMin(d) - Vec2d::Constant(reach);
            const Vec2d hi = a.cwiseMax(b).cwiseMax(d) + Vec2d::Constant(reach);
            const int x0 = std::max(0, static_cast<int>(std::floor(lo.x())));
            const int y0 = std::max(0, static_cast<int>(std::floor(lo.y())));
            const int x1 = std::min(atlas.size - 1, static_cast<int>(std::ceil(hi.x())));
            const int y1 = std::min(atlas.size - 1, static_cast<int>(std::ceil(hi.y())));
            const auto weights = [&](const Vec2d& p) {
                const double w1 = ((p - a).x() * (d - a).y() - (p - a).y() * (d - a).x()) / area;
                const double w2 = ((b - a).x() * (p - a).y() - (b - a).y() * (p - a).x()) / area;
                return Vec3d(1.0 - w1 - w2, w1, w2);
            };
            for (int y = y0; y <= y1; ++y)
                for (int x = x0; x <= x1; ++x)
                {
                    const Vec2d p(x + 0.5, y + 0.5);
                    const Vec3d w = weights(p);
                    if (w.minCoeff() >= 0.0)
                    {
                        inside[static_cast<std::size_t>(y) * static_cast<std::size_t>(atlas.size) +
                               static_cast<std::size_t>(x)] = 1;
                        texel(x, y, static_cast<std::uint32_t>(f), w);
                        continue;
                    }
                    // The nearest point of the triangle (in the plane z = 0).
                    const auto lift = [](const Vec2d& q) {
                        return Vec3d(q.x(), q.y(), 0.0);
                    };
                    const Vec3d w_near =
                        closest_point_barycentric(lift(p), lift(a), lift(b), lift(d));
                    const double best =
                        (p - (w_near.x() * a + w_near.y() * b + w_near.z() * d)).norm();
                    if (best > reach)
                        continue;
                    found.push_back(
                        {static_cast<std::size_t>(y) * static_cast<std::size_t>(atlas.size) +
                             static_cast<std::size_t>(x),
                         best, static_cast<std::uint32_t>(f), w_near});
                }
        }
    });
    std::vector<EdgeTexel> all;
    for (const auto& found : edges)
        all.insert(all.end(), found.begin(), found.end());
    // The centres inside some chart are taken; of the rest, the nearest chart per texel.
    std::erase_if(all, [&](const EdgeTexel& e) { return inside[e.index] != 0; });
    std::sort(all.begin(), all.end(), [](const EdgeTexel& p, const EdgeTexel& q) {
        return std::tie(p.index, p.distance, p.chart) < std::tie(q.index, q.distance, q.chart);
    });
    all.erase(
        std::unique(all.begin(), all.end(),
                    [](const EdgeTexel& p, const EdgeTexel& q) { return p.index == q.index; }),
        all.end());
    parallel_blocks(all.size(), 256, [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i)
        {
            const auto x = static_cast<int>(all[i].index % static_cast<std::size_t>(atlas.size));
            const auto y = static_cast<int>(all[i].index / static_cast<std::size_t>(atlas.size));
            texel(x, y, all[i].chart, all[i].barycentric);
        }
    });
}

std::size_t texel_index(const TextureImage& image, int x, int y)
{
    return (static_cast<std::size_t>(y) * static_cast<std::size_t>(image.width) +
            static_cast<std::size_t>(x)) *
           static_cast<std::size_t>(image.channels);
}

std::uint8_t to_byte(double value)
{
    return static_cast<std::uint8_t>(std::clamp(std::lround(value), 0L, 255L));
}

} // namespace

std::size_t dilate(TextureImage& image, std::vector<std::uint8_t>& mask, int rounds)
{
    std::size_t filled = 0;
    const int w = image.width;
    const int h = image.height;
    const int channels = image.channels;
    for (int round = 0; round < rounds; ++round)
    {
        std::vector<std::uint8_t> next = mask;
        std::vector<std::uint8_t> pixels = image.pixels;
        std::size_t this_round = 0;
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x)
            {
                const std::size_t i = static_cast<std::size_t>(y) * w + x;
                if (mask[i] != 0)
                    continue;
                std::array<int, 4> sum{};
                int count = 0;
                const std::array<std::pair<int, int>, 4> around = {
                    std::pair{x - 1, y}, std::pair{x + 1, y}, std::pair{x, y - 1},
                    std::pair{x, y + 1}};
                for (const auto& [nx, ny] : around)
                {
                    if (nx < 0 || ny < 0 || nx >= w || ny >= h)
                        continue;
                    const std::size_t j = static_cast<std::size_t>(ny) * w + nx;
                    if (mask[j] == 0)
                        continue;
                    for (int c = 0; c < channels; ++c)
                        sum[static_cast<std::size_t>(c)] +=
                            image.pixels[j * static_cast<std::size_t>(channels) + c];
                    ++count;
                }
                if (count == 0)
                    continue;
                for (int c = 0; c < channels; ++c)
                    pixels[i * static_cast<std::size_t>(channels) + c] = static_cast<std::uint8_t>(
                        (sum[static_cast<std::size_t>(c)] + count / 2) / count);
                next[i] = 1;
                ++this_round;
            }
        mask.swap(next);
        image.pixels.swap(pixels);
        filled += this_round;
        if (this_round == 0)
            break;
    }
    return filled;
}

TextureImage checker_texture(const Atlas& atlas, int square)
{
    if (square <= 0)
        square = std::max(2, atlas.size / 64);
    TextureImage image = blank(atlas);
    for (int y = 0; y < atlas.size; ++y)
        for (int x = 0; x < atlas.size; ++x)
        {
            const bool dark = ((x / square) + (y / square)) % 2 == 0;
            const std::size_t i = texel_index(image, x, y);
            image.pixels[i] = dark ? 70 : 225;
            image.pixels[i + 1] = dark ? 80 : 225;
            image.pixels[i + 2] = dark ? 110 : 215;
        }
    return image;
}

TextureImage atlas_image(const Atlas& atlas, const TextureImage& image)
{
    if (image.empty() || image.width <= 0 || image.height <= 0)
        throw InvalidInput("texture: the image is empty");
    TextureImage out = blank(atlas);
    parallel_blocks(static_cast<std::size_t>(atlas.size), 16,
                    [&](std::size_t begin, std::size_t end) {
                        for (std::size_t y = begin; y < end; ++y)
                            for (int x = 0; x < atlas.size; ++x)
                            {
                                const Vec2d uv((x + 0.5) / atlas.size,
                                               (static_cast<double>(y) + 0.5) / atlas.size);
                                const Vec3d c = sample_texture(image, uv);
                                const std::size_t i = texel_index(out, x, static_cast<int>(y));
                                for (int k = 0; k < 3; ++k)
                                    out.pixels[i + static_cast<std::size_t>(k)] = to_byte(c[k]);
                            }
                    });
    return out;
}

TextureImage bake_colors(const MultiresMesh& mesh, const Parameterization& parameterization,
                         const Atlas& atlas, std::size_t level, const PointCloudView& samples,
                         const BakeOptions& options, BakeReport* report)
{
    check_level(mesh, level);
    if (samples.size() == 0)
        throw InvalidInput("bake_colors: the samples are empty");
    if (!samples.has_colors())
        throw InvalidInput("bake_colors: the samples have no colours (red, green, blue)");
    if (options.neighbors == 0 || options.neighbors > 64)
        throw InvalidInput("bake_colors: neighbors must lie in 1 to 64");
    const KdTree tree(samples.positions);
    const std::size_t k = std::min(options.neighbors, samples.size());
    const std::vector<Triangle> faces = mesh.faces(level);
    const std::span<const Vec3d> x = mesh.positions();
    const Vec3d shift = mesh.origin() - samples.origin;

    TextureImage image = blank(atlas);
    std::vector<std::uint8_t> mask(static_cast<std::size_t>(atlas.size) * atlas.size, 0);
    std::vector<double> distance(mask.size(), 0.0);
    for_each_chart_texel(atlas, [&](int tx, int ty, std::uint32_t chart, const Vec3d& beta) {
        const Parameterization::Location at = Parameterization::locate(chart, beta, level);
        const Triangle& t = faces[at.face];
        const Vec3d p = at.barycentric.x() * x[t[0]] + at.barycentric.y() * x[t[1]] +
                        at.barycentric.z() * x[t[2]] + shift;
        std::array<std::uint32_t, 64> ids{};
        std::array<float, 64> d2{};
        const std::size_t found =
            tree.knn(p.cast<float>(), k, std::span(ids).first(k), std::span(d2).first(k));
        Vec3d colour = Vec3d::Zero();
        double total = 0.0;
        const double eps = 1e-12 + 1e-6 * std::sqrt(static_cast<double>(d2[found - 1]));
        for (std::size_t i = 0; i < found; ++i)
        {
            const double w = 1.0 / std::pow(std::sqrt(static_cast<double>(d2[i])) + eps, 2.0);
            const Color& c = samples.colors[ids[i]];
            colour += w * Vec3d(c.r, c.g, c.b);
            total += w;
        }
        colour /= total;
        const std::size_t i = texel_index(image, tx, ty);
        for (int c = 0; c < 3; ++c)
            image.pixels[i + static_cast<std::size_t>(c)] = to_byte(colour[c]);
        const std::size_t m = static_cast<std::size_t>(ty) * atlas.size + tx;
        mask[m] = 1;
        distance[m] = std::sqrt(static_cast<double>(d2[0]));
    });
    BakeReport r;
    double distance_sum = 0.0;
    for (std::size_t m = 0; m < mask.size(); ++m)
        if (mask[m] != 0)
        {
            ++r.texels;
            distance_sum += distance[m];
        }
    r.mean_distance = r.texels > 0 ? distance_sum / static_cast<double>(r.texels) : 0.0;
    r.dilated = dilate(image, mask, atlas.gutter + 1);

    if (report != nullptr)
    {
        // Each sample against the texture at the nearest vertex of the level.
        std::vector<Vec3f> vertices(mesh.vertex_count(level));
        for (std::size_t v = 0; v < vertices.size(); ++v)
            vertices[v] = (x[v] + shift).cast<float>();
        const KdTree near(vertices);
        std::vector<double> squared(samples.size(), 0.0);
        parallel_blocks(samples.size(), 4096, [&](std::size_t begin, std::size_t end) {
            for (std::size_t s = begin; s < end; ++s)
            {
                const PointId v = near.nearest(samples.positions[s]);
                const BaseCoordinates& bc = parameterization.coordinates()[v.value];
                const Vec3d baked = sample_texture(image, atlas.uv(bc.face, bc.barycentric));
                const Color& c = samples.colors[s];
                squared[s] = (baked - Vec3d(c.r, c.g, c.b)).squaredNorm() / 3.0;
            }
        });
        double sum = 0.0;
        for (const double q : squared)
            sum += q;
        r.rms_color_error = std::sqrt(sum / static_cast<double>(samples.size()));
        *report = r;
    }
    return image;
}

TextureImage bake_normal_map(const MultiresMesh& mesh, const Parameterization& parameterization,
                             const Atlas& atlas, const TexturedMesh& coarse, std::size_t fine)
{
    if (coarse.lods.size() != 1 || coarse.lod_levels.size() != 1 || coarse.normals.empty() ||
        coarse.tangents.empty())
        throw InvalidInput(
            "bake_normal_map: the coarse mesh must be one textured level with "
            "normals and tangents");
    const std::size_t level = coarse.lod_levels[0];
    check_level(mesh, fine);
    if (fine <= level)
        throw InvalidInput("bake_normal_map: the fine level " + std::to_string(fine) +
                           " must be finer than the textured level " + std::to_string(level));
    (void)parameterization;
    const std::vector<Triangle> fine_faces = mesh.faces(fine);
    const std::vector<Vec3d> fine_normals =
        vertex_normals(mesh.positions(), fine_faces, mesh.vertex_count(fine));
    const std::vector<Triangle>& coarse_faces = coarse.lods[0];

    // Texels outside every chart (beyond the dilated gutters) hold the unperturbed normal.
    TextureImage image = blank(atlas);
    for (std::size_t i = 0; i < image.pixels.size(); i += 3)
    {
        image.pixels[i] = 128;
        image.pixels[i + 1] = 128;
        image.pixels[i + 2] = 255;
    }
    std::vector<std::uint8_t> mask(static_cast<std::size_t>(atlas.size) * atlas.size, 0);
    for_each_chart_texel(atlas, [&](int tx, int ty, std::uint32_t chart, const Vec3d& beta) {
        const Parameterization::Location at_coarse = Parameterization::locate(chart, beta, level);
        const Parameterization::Location at_fine = Parameterization::locate(chart, beta, fine);
        const Triangle& c = coarse_faces[at_coarse.face];
        const Vec3d& m = at_coarse.barycentric;
        Vec3d normal = Vec3d::Zero();
        Vec3d tangent = Vec3d::Zero();
        for (int k = 0; k < 3; ++k)
        {
            const std::uint32_t i = c[static_cast<std::size_t>(k)];
            normal += m[k] * coarse.normals[i].cast<double>();
            tangent += m[k] * coarse.tangents[i].head<3>().cast<double>();
        }
        normal.normalize();
        tangent -= tangent.dot(normal) * normal;
        tangent = tangent.norm() > 0.0 ? Vec3d(tangent.normalized()) : normal.unitOrthogonal();
        const Vec3d bitangent =
            normal.cross(tangent) * static_cast<double>(coarse.tangents[c[0]].w());
        const Triangle& f = fine_faces[at_fine.face];
        const Vec3d& u = at_fine.barycentric;
        const Vec3d n =
            (u.x() * fine_normals[f[0]] + u.y() * fine_normals[f[1]] + u.z() * fine_normals[f[2]])
                .normalized();
        const Vec3d local(n.dot(tangent), n.dot(bitangent), n.dot(normal));
        const std::size_t i = texel_index(image, tx, ty);
        for (int k = 0; k < 3; ++k)
            image.pixels[i + static_cast<std::size_t>(k)] = to_byte(127.5 * (local[k] + 1.0));
        mask[static_cast<std::size_t>(ty) * atlas.size + tx] = 1;
    });
    (void)dilate(image, mask, atlas.gutter + 1);
    return image;
}

} // namespace pointform

namespace pointform {

TextureOutcome texture_hierarchy(const MultiresMesh& mesh, const TextureRequest& request,
                                 const PointCloudView* samples)
{
    if (mesh.level_count() == 0)
        throw InvalidInput("texture: the hierarchy is empty");
    TextureOutcome out;
    out.level = request.level.value_or(mesh.finest_level());
    check_level(mesh, out.level);
    if (request.normal_map_level && *request.normal_map_level >= out.level)
        throw InvalidInput("texture: the normal map's level " +
                           std::to_string(*request.normal_map_level) +
                           " must be coarser than the textured level " + std::to_string(out.level));
    if (request.source == TextureRequest::Source::BakeColors &&
        (samples == nullptr || !samples->has_colors()))
        throw InvalidInput(
            "texture: baking colours needs a scan with colours (red, green, "
            "blue)");
    if (request.source == TextureRequest::Source::Image && request.image.empty())
        throw InvalidInput("texture: the image is empty");

    const Parameterization parameterization(mesh);
    out.atlas = make_atlas(mesh, out.level, request.atlas);
    std::vector<std::size_t> levels;
    if (request.normal_map_level)
        levels.push_back(*request.normal_map_level);
    else
        for (std::size_t l = 0; l <= out.level; ++l)
            levels.push_back(l);
    out.mesh = textured_levels(mesh, parameterization, out.atlas, levels);
    out.distortion = atlas_distortion(mesh, parameterization, out.atlas, levels);
    switch (request.source)
    {
        case TextureRequest::Source::Checker:
            out.mesh.base_color = checker_texture(out.atlas);
            break;
        case TextureRequest::Source::Image:
            out.mesh.base_color = atlas_image(out.atlas, request.image);
            break;
        case TextureRequest::Source::BakeColors:
        {
            BakeReport report;
            out.mesh.base_color = bake_colors(mesh, parameterization, out.atlas, out.level,
                                              *samples, request.bake, &report);
            out.bake = report;
            break;
        }
    }
    if (request.normal_map_level)
        out.mesh.normal_map =
            bake_normal_map(mesh, parameterization, out.atlas, out.mesh, out.level);
    return out;
}

} // namespace pointform
