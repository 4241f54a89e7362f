// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/core/error.h"
#include "pointform/render/render.h"

#include "detail_render.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

namespace pointform {
namespace {

void require(bool ok, const std::string& field, double value, const std::string& expected)
{
    if (!ok)
        throw InvalidInput("render option " + field + " = " + std::to_string(value) +
                           ": expected " + expected);
}

double radians(double degrees)
{
    return degrees * std::numbers::pi / 180.0;
}

} // namespace

void validate(const RenderOptions& options)
{
    constexpr int max_side = 16384;
    require(options.width >= 1 && options.width <= max_side, "width", options.width, "1..16384");
    require(options.height >= 1 && options.height <= max_side, "height", options.height,
            "1..16384");
    require(std::isfinite(options.azimuth), "azimuth", options.azimuth, "a finite angle");
    require(options.elevation >= -90.0 && options.elevation <= 90.0, "elevation", options.elevation,
            "-90..90 degrees");
    if (!options.up.allFinite() || options.up.squaredNorm() == 0.0)
        throw InvalidInput("render option up: expected a finite non-zero vector");
    require(options.field_of_view > 0.0 && options.field_of_view < 170.0, "field_of_view",
            options.field_of_view, "0..170 degrees (exclusive)");
    require(options.margin >= 0.0 && options.margin < 0.9, "margin", options.margin, "[0, 0.9)");
    require(options.supersampling >= 1 && options.supersampling <= 8, "supersampling",
            options.supersampling, "1..8");
    require(options.ambient >= 0.0 && std::isfinite(options.ambient), "ambient", options.ambient,
            ">= 0");
    require(options.key_light >= 0.0 && std::isfinite(options.key_light), "key_light",
            options.key_light, ">= 0");
    require(options.headlight >= 0.0 && std::isfinite(options.headlight), "headlight",
            options.headlight, ">= 0");
    require(options.line_width > 0.0 && std::isfinite(options.line_width), "line_width",
            options.line_width, "> 0 pixels");
    require(options.line_opacity >= 0.0 && options.line_opacity <= 1.0, "line_opacity",
            options.line_opacity, "[0, 1]");
    require(options.splat_radius >= 0.0 && std::isfinite(options.splat_radius), "splat_radius",
            options.splat_radius, ">= 0 (0 = automatic)");
    require(!options.frame || (options.frame->min.allFinite() && options.frame->max.allFinite() &&
                               !options.frame->is_empty()),
            "frame", options.frame ? options.frame->diagonal() : 0.0,
            "a finite box with min <= max");
    require(options.splat_scale > 0.0 && std::isfinite(options.splat_scale), "splat_scale",
            options.splat_scale, "> 0");
}

namespace detail {

std::vector<Vec3f> box_corners(const Aabb& box)
{
    std::vector<Vec3f> corners;
    const Vec3d half = 0.5 * (box.max - box.min);
    for (int k = 0; k < 8; ++k)
        corners.push_back(Vec3d((k & 1) != 0 ? half.x() : -half.x(),
                                (k & 2) != 0 ? half.y() : -half.y(),
                                (k & 4) != 0 ? half.z() : -half.z())
                              .cast<float>());
    return corners;
}

Camera fit_camera(std::span<const Vec3f> points, const RenderOptions& options)
{
    Camera camera;
    camera.projection = options.projection;
    camera.width = options.width;
    camera.height = options.height;

    // Orbit: the direction from the centre to the camera.
    const Vec3d up = options.up.normalized();
    const Vec3d reference = std::abs(up.z()) < 0.9 ? Vec3d::UnitZ() : Vec3d(-Vec3d::UnitY());
    const Vec3d front = (reference - reference.dot(up) * up).normalized();
    const double azimuth = radians(options.azimuth);
    const double elevation = radians(options.elevation);
    const Vec3d horizontal = std::cos(azimuth) * front + std::sin(azimuth) * up.cross(front);
    const Vec3d towards_camera = std::cos(elevation) * horizontal + std::sin(elevation) * up;
    camera.forward = -towards_camera;
    camera.right = (-horizontal).cross(up).normalized(); // defined even looking straight down
    camera.up = camera.right.cross(camera.forward).normalized();
    camera.key_light =
        (-0.45 * camera.right + 0.65 * camera.up + 0.6 * towards_camera).normalized();

    // Extents of the points in the camera's frame, about the centre of rotation.
    const double aspect = static_cast<double>(options.width) / options.height;
    const double fill = 1.0 - options.margin;
    double extent = 0.0; // largest distance from the centre
    for (const Vec3f& p : points)
        extent = std::max(extent, p.cast<double>().norm());
    if (extent == 0.0)
        extent = 1.0;

    if (options.projection == Projection::Orthographic)
    {
        double x_min = 0.0, x_max = 0.0, y_min = 0.0, y_max = 0.0;
        if (!points.empty())
        {
            x_min = y_min = std::numeric_limits<double>::infinity();
            x_max = y_max = -std::numeric_limits<double>::infinity();
        }
        for (const Vec3f& pf : points)
        {
            const Vec3d p = pf.cast<double>();
            x_min = std::min(x_min, p.dot(camera.right));
            x_max = std::max(x_max, p.dot(camera.right));
            y_min = std::min(y_min, p.dot(camera.up));
            y_max = std::max(y_max, p.dot(camera.up));
        }
        double half_y = std::max(0.5 * (y_max - y_min), 0.5 * (x_max - x_min) / aspect) / fill;
        if (!(half_y > 0.0))
            half_y = extent;
        camera.half_y = half_y;
        camera.half_x = half_y * aspect;
        camera.eye = 0.5 * (x_min + x_max) * camera.right + 0.5 * (y_min + y_max) * camera.up -
                     2.0 * extent * camera.forward;
        return camera;
    }

    // Perspective: the shorter side spans the field of view.
    const double tan_half = std::tan(0.5 * radians(options.field_of_view));
    camera.half_y = aspect >= 1.0 ? tan_half : tan_half / aspect;
    camera.half_x = camera.half_y * aspect;
    // A point (x, y, z) in the camera frame (z along forward, about the centre) is inside the
    // shrunken frustum of a camera at distance d, shifted by s across the view, iff
    // |x − s| ≤ (d + z)·T. The smallest d for which some s fits every point is
    // (max(x − zT) − min(x + zT)) / 2T, and s is the middle of that interval.
    const double tx = camera.half_x * fill;
    const double ty = camera.half_y * fill;
    double ax = -std::numeric_limits<double>::infinity(), bx = -ax, ay = ax, by = bx;
    double z_min = 0.0;
    for (const Vec3f& pf : points)
    {
        const Vec3d p = pf.cast<double>();
        const double x = p.dot(camera.right);
        const double y = p.dot(camera.up);
        const double z = p.dot(camera.forward);
        ax = std::max(ax, x - z * tx);
        bx = std::min(bx, x + z * tx);
        ay = std::max(ay, y - z * ty);
        by = std::min(by, y + z * ty);
        z_min = std::min(z_min, z);
    }
    double distance = extent / std::tan(0.5 * radians(options.field_of_view)); // empty input
    double shift_x = 0.0, shift_y = 0.0;
    if (!points.empty())
    {
        distance = std::max((ax - bx) / (2.0 * tx), (ay - by) / (2.0 * ty));
        // Keep every point well in front of the eye.
        distance = std::max(distance, -z_min + 0.05 * extent);
        shift_x = 0.5 * (ax + bx);
        shift_y = 0.5 * (ay + by);
    }
    camera.eye = shift_x * camera.right + shift_y * camera.up - distance * camera.forward;
    return camera;
}

void store_pixel(Image& image, int x, int y, const Vec3d& sum, int count)
{
    const std::size_t i = (static_cast<std::size_t>(y) * static_cast<std::size_t>(image.width) +
                           static_cast<std::size_t>(x)) *
                          3;
    for (int c = 0; c < 3; ++c)
    {
        const double value = std::round(sum[c] / count);
        image.rgb[i + static_cast<std::size_t>(c)] =
            static_cast<std::uint8_t>(std::clamp(value, 0.0, 255.0));
    }
}

Image make_image(const RenderOptions& options)
{
    Image image;
    image.width = options.width;
    image.height = options.height;
    image.rgb.assign(
        static_cast<std::size_t>(options.width) * static_cast<std::size_t>(options.height) * 3, 0);
    return image;
}

} // namespace detail
} // namespace pointform
