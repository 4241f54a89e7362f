// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/core/error.h"
#include "pointform/core/parallel.h"
#include "pointform/hermite/surfels.h"
#include "pointform/render/render.h"
#include "pointform/spatial/kd_tree.h"

#include "detail_render.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace pointform {
namespace {

constexpr std::uint32_t no_point = std::numeric_limits<std::uint32_t>::max();
constexpr std::size_t band_rows = 16; // sample rows that one task of the splatter owns

void check_cloud(const PointCloudView& cloud)
{
    if (cloud.empty())
        throw InvalidInput("render_points: the point cloud is empty");
    if (cloud.size() >= no_point)
        throw InvalidInput("render_points: too many points (" + std::to_string(cloud.size()) + ")");
    validate(cloud);
    if (!cloud.origin.allFinite())
        throw InvalidInput("render_points: the origin is not finite");
    for (std::size_t i = 0; i < cloud.size(); ++i)
        if (!cloud.positions[i].allFinite())
            throw InvalidInput("render_points: point " + std::to_string(i) + " is not finite");
}

/// Unit normals to shade by: the cloud's, estimated ones, or none (flat shading).
std::vector<Vec3f> shading_normals(const PointCloudView& cloud, const RenderOptions& options)
{
    std::vector<Vec3f> normals;
    if (cloud.has_normals())
        normals.assign(cloud.normals.begin(), cloud.normals.end());
    else if (options.estimate_normals)
    {
        try
        {
            normals = compute_surfels(cloud).surfels.normals;
        }
        catch (const InvalidInput&)
        {
            return {}; // too few or degenerate points: flat discs
        }
    }
    for (Vec3f& n : normals)
        if (n.allFinite() && n.squaredNorm() > 0.0F)
            n.normalize();
        else
            n.setZero(); // drawn as a flat, camera-facing disc
    return normals;
}

/// Disc radius of every point, in world (= local) units, scale included.
std::vector<float> splat_radii(const PointCloudView& cloud, const RenderOptions& options,
                               double extent)
{
    const std::size_t n = cloud.size();
    const auto scale = static_cast<float>(options.splat_scale);
    if (options.splat_radius > 0.0)
        return std::vector<float>(n, static_cast<float>(options.splat_radius) * scale);
    std::vector<float> radii(n, 0.0F);
    if (options.use_radii && cloud.has_radii())
    {
        for (std::size_t i = 0; i < n; ++i)
            radii[i] =
                std::isfinite(cloud.radii[i]) ? std::max(cloud.radii[i], 0.0F) * scale : 0.0F;
        return radii;
    }
    // From the sampling density: the distance to the 8th nearest other sample.
    constexpr std::size_t k = 8;
    const std::size_t neighbors = std::min(k + 1, n); // a point is its own nearest
    float median = 0.0F;
    if (neighbors >= 2)
    {
        const KdTree tree(cloud.positions);
        const KnnTable table = knn_batch(tree, cloud.positions, neighbors);
        for (std::size_t i = 0; i < n; ++i)
            radii[i] = std::sqrt(table.distances2(i)[neighbors - 1]);
        std::vector<float> sorted = radii;
        std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(n / 2),
                         sorted.end());
        median = sorted[n / 2];
    }
    if (!(median > 0.0F)) // a single point or mostly duplicates: 1% of the view
    {
        std::fill(radii.begin(), radii.end(), static_cast<float>(0.01 * extent) * scale);
        return radii;
    }
    for (float& r : radii)
        r = std::clamp(r, 0.25F * median, 4.0F * median) * scale;
    return radii;
}

} // namespace

Image render_points(const PointCloudView& cloud, const RenderOptions& options)
{
    validate(options);
    check_cloud(cloud);
    const int s = options.supersampling;
    const int sample_width = options.width * s;
    const int sample_height = options.height * s;
    constexpr std::size_t max_samples = std::size_t{1} << 28U; // 2 GiB of depth and owner buffers
    if (static_cast<std::size_t>(sample_width) * static_cast<std::size_t>(sample_height) >
        max_samples)
        throw InvalidInput("render_points: " + std::to_string(options.width) + " x " +
                           std::to_string(options.height) + " pixels at " + std::to_string(s) +
                           " x " + std::to_string(s) +
                           " samples each is too large; lower the size or the supersampling");

    const std::size_t n = cloud.size();
    const Aabb box = options.frame ? *options.frame : cloud.bounds();
    const Vec3d shift = cloud.origin - box.center();
    std::vector<Vec3f> centers(n);
    for (std::size_t i = 0; i < n; ++i)
        centers[i] = (cloud.positions[i].cast<double>() + shift).cast<float>();
    const detail::Camera camera =
        detail::fit_camera(options.frame ? detail::box_corners(*options.frame) : centers, options);

    const std::vector<Vec3f> normals = shading_normals(cloud, options);
    const std::vector<float> radii =
        splat_radii(cloud, options, box.diagonal() > 0.0 ? box.diagonal() : 1.0);

    // Bounding boxes of the discs on the supersampled grid, then the discs of each band of
    // sample rows in point order.
    struct Footprint
    {
        int x0 = 0, x1 = -1, y0 = 0, y1 = -1; // inclusive sample ranges; empty if x1 < x0
    };
    std::vector<Footprint> footprints(n);
    parallel_blocks(n, 0, [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i)
        {
            const Vec3d q = camera.project(centers[i].cast<double>());
            if (!(q.z() > 0.0) || !(radii[i] > 0.0F))
                continue;
            // 1.2: a sphere off the axis projects a little wider than r·f/z.
            const double r =
                1.2 * static_cast<double>(radii[i]) * camera.pixels_per_unit(q.z()) * s + 1.0;
            const double cx = q.x() * s;
            const double cy = q.y() * s;
            Footprint& fp = footprints[i];
            fp.x0 = static_cast<int>(std::max(std::floor(cx - r), 0.0));
            fp.x1 = static_cast<int>(std::min(std::ceil(cx + r), sample_width - 1.0));
            fp.y0 = static_cast<int>(std::max(std::floor(cy - r), 0.0));
            fp.y1 = static_cast<int>(std::min(std::ceil(cy + r), sample_height - 1.0));
        }
    });
    const std::size_t bands = (static_cast<std::size_t>(sample_height) + band_rows - 1) / band_rows;
    std::vector<std::size_t> offsets(bands + 1, 0);
    for (const Footprint& fp : footprints)
        if (fp.x1 >= fp.x0 && fp.y1 >= fp.y0)
            for (std::size_t b = static_cast<std::size_t>(fp.y0) / band_rows;
                 b <= static_cast<std::size_t>(fp.y1) / band_rows; ++b)
                ++offsets[b + 1];
    for (std::size_t b = 0; b < bands; ++b)
        offsets[b + 1] += offsets[b];
    std::vector<std::uint32_t> band_points(offsets[bands]);
    {
        std::vector<std::size_t> fill(offsets.begin(), offsets.end() - 1);
        for (std::size_t i = 0; i < n; ++i)
        {
            const Footprint& fp = footprints[i];
            if (fp.x1 >= fp.x0 && fp.y1 >= fp.y0)
                for (std::size_t b = static_cast<std::size_t>(fp.y0) / band_rows;
                     b <= static_cast<std::size_t>(fp.y1) / band_rows; ++b)
                    band_points[fill[b]++] = static_cast<std::uint32_t>(i);
        }
    }

    // Splat: each band in point order, nearest disc wins, ties to the lower index.
    const std::size_t samples =
        static_cast<std::size_t>(sample_width) * static_cast<std::size_t>(sample_height);
    std::vector<float> depth(samples, std::numeric_limits<float>::infinity());
    std::vector<std::uint32_t> owner(samples, no_point);
    const auto disc_normal = [&](std::size_t i, const Vec3d& center) {
        if (!normals.empty() && normals[i].squaredNorm() > 0.0F)
            return Vec3d(normals[i].cast<double>());
        // Flat: facing the eye.
        return camera.projection == Projection::Orthographic
                   ? Vec3d(-camera.forward)
                   : Vec3d((camera.eye - center).normalized());
    };
    // Image-plane coordinates of the sample columns and rows: a sample's ray is eye + t·(u, v, 1)
    // (perspective, t = depth) or eye + (u, v, t) (orthographic), in the camera's frame.
    std::vector<double> column_u(static_cast<std::size_t>(sample_width));
    for (int x = 0; x < sample_width; ++x)
        column_u[static_cast<std::size_t>(x)] =
            (2.0 * (x + 0.5) / sample_width - 1.0) * camera.half_x;
    const bool perspective = camera.projection == Projection::Perspective;
    parallel_blocks(bands, 1, [&](std::size_t begin, std::size_t end) {
        for (std::size_t b = begin; b < end; ++b)
        {
            const int band_y0 = static_cast<int>(b * band_rows);
            const int band_y1 = std::min(band_y0 + static_cast<int>(band_rows), sample_height) - 1;
            for (std::size_t k = offsets[b]; k < offsets[b + 1]; ++k)
            {
                const std::uint32_t i = band_points[k];
                const Footprint& fp = footprints[i];
                const Vec3d center = centers[i].cast<double>();
                const Vec3d world_normal = disc_normal(i, center);
                const Vec3d q = center - camera.eye;
                const Vec3d c(q.dot(camera.right), q.dot(camera.up), q.dot(camera.forward));
                const Vec3d m(world_normal.dot(camera.right), world_normal.dot(camera.up),
                              world_normal.dot(camera.forward));
                const double mc = m.dot(c);
                const double r2 = static_cast<double>(radii[i] * radii[i]);
                for (int y = std::max(fp.y0, band_y0); y <= std::min(fp.y1, band_y1); ++y)
                {
                    const double v = (1.0 - 2.0 * (y + 0.5) / sample_height) * camera.half_y;
                    for (int x = fp.x0; x <= fp.x1; ++x)
                    {
                        const double u = column_u[static_cast<std::size_t>(x)];
                        double t = 0.0;
                        Vec3d offset;
                        if (perspective)
                        {
                            const double facing = m.x() * u + m.y() * v + m.z();
                            if (std::abs(facing) < 1e-9)
                                continue;
                            t = mc / facing;
                            offset = Vec3d(t * u, t * v, t) - c;
                        }
                        else
                        {
                            if (std::abs(m.z()) < 1e-9)
                                continue;
                            t = (mc - m.x() * u - m.y() * v) / m.z();
                            offset = Vec3d(u, v, t) - c;
                        }
                        if (!(t > 0.0) || offset.squaredNorm() > r2)
                            continue;
                        const std::size_t slot =
                            static_cast<std::size_t>(y) * static_cast<std::size_t>(sample_width) +
                            static_cast<std::size_t>(x);
                        if (static_cast<float>(t) < depth[slot])
                        {
                            depth[slot] = static_cast<float>(t);
                            owner[slot] = i;
                        }
                    }
                }
            }
        }
    });

    // Shade and filter.
    Image image = detail::make_image(options);
    const Vec3d background = detail::to_vec(options.background);
    parallel_blocks(
        static_cast<std::size_t>(options.height), 1, [&](std::size_t begin, std::size_t end) {
            for (std::size_t row = begin; row < end; ++row)
                for (int x = 0; x < options.width; ++x)
                {
                    Vec3d sum = Vec3d::Zero();
                    for (int j = 0; j < s; ++j)
                        for (int i = 0; i < s; ++i)
                        {
                            const int sx = x * s + i;
                            const int sy = static_cast<int>(row) * s + j;
                            const std::uint32_t p =
                                owner[static_cast<std::size_t>(sy) *
                                          static_cast<std::size_t>(sample_width) +
                                      static_cast<std::size_t>(sx)];
                            if (p == no_point)
                            {
                                sum += background;
                                continue;
                            }
                            Vec3d origin, direction;
                            camera.ray((sx + 0.5) / s, (sy + 0.5) / s, origin, direction);
                            const Vec3d normal = disc_normal(p, centers[p].cast<double>());
                            sum += detail::shade(camera, options, normal, direction,
                                                 normal.dot(direction) < 0.0);
                        }
                    detail::store_pixel(image, x, static_cast<int>(row), sum, s * s);
                }
        });
    return image;
}

} // namespace pointform
