// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

// Private to the render module: the camera and the shading model that the mesh ray caster and
// the point splatter share.

#include "pointform/core/types.h"
#include "pointform/render/render.h"

#include <cmath>
#include <cstddef>
#include <span>

namespace pointform::detail {

/// A camera in "local" coordinates: world minus the object's bounding-box centre, which is also
/// the centre of rotation. Image coordinates are continuous output pixels: x in [0, width) to
/// the right, y in [0, height) downwards.
struct Camera
{
    Projection projection = Projection::Perspective;
    Vec3d right = Vec3d::UnitX();
    Vec3d up = Vec3d::UnitY();
    Vec3d forward = -Vec3d::UnitZ(); ///< viewing direction
    /// Perspective: the eye. Orthographic: the point behind the object that the centre ray
    /// starts from (every ray starts on the plane through it perpendicular to `forward`).
    Vec3d eye = Vec3d::Zero();
    /// Perspective: tangents of the half opening angles; orthographic: half extents of the view
    /// in local units.
    double half_x = 1.0;
    double half_y = 1.0;
    double width = 1.0;               ///< pixels
    double height = 1.0;              ///< pixels
    Vec3d key_light = Vec3d::UnitZ(); ///< unit, towards the light

    /// Ray through image point (x, y): unit direction; origin on the image plane (orthographic)
    /// or at the eye (perspective).
    void ray(double x, double y, Vec3d& origin, Vec3d& direction) const
    {
        const double u = (2.0 * x / width - 1.0) * half_x;
        const double v = (1.0 - 2.0 * y / height) * half_y;
        if (projection == Projection::Orthographic)
        {
            origin = eye + u * right + v * up;
            direction = forward;
        }
        else
        {
            origin = eye;
            direction = (forward + u * right + v * up).normalized();
        }
    }

    /// Image position (x, y) of a local point and its depth along `forward` from the eye (or
    /// the orthographic image plane).
    [[nodiscard]] Vec3d project(const Vec3d& p) const
    {
        const Vec3d q = p - eye;
        const double depth = q.dot(forward);
        double u = q.dot(right);
        double v = q.dot(up);
        if (projection == Projection::Perspective)
        {
            u /= depth;
            v /= depth;
        }
        return {(u / half_x + 1.0) * 0.5 * width, (1.0 - v / half_y) * 0.5 * height, depth};
    }

    /// Pixels per local unit, across the view direction, at `depth`.
    [[nodiscard]] double pixels_per_unit(double depth) const
    {
        const double scale = 0.5 * height / half_y;
        return projection == Projection::Perspective ? scale / depth : scale;
    }
};

/// Frames `points` (local coordinates: world − centre, where centre is the centre of rotation)
/// as RenderOptions describes. `points` may be empty or all coincident: the view then spans one
/// unit around the centre.
[[nodiscard]] Camera fit_camera(std::span<const Vec3f> points, const RenderOptions& options);

/// The eight corners of `box` relative to its centre: what the camera fits to with
/// RenderOptions::frame.
[[nodiscard]] std::vector<Vec3f> box_corners(const Aabb& box);

/// Two-sided Lambert with ambient, key light and headlight. `normal` need not face the viewer;
/// `front` selects the colour.
[[nodiscard]] inline double shade_intensity(const Camera& camera, const RenderOptions& options,
                                            const Vec3d& normal, const Vec3d& ray_direction)
{
    return options.ambient + options.key_light * std::abs(normal.dot(camera.key_light)) +
           options.headlight * std::abs(normal.dot(ray_direction));
}

[[nodiscard]] inline Vec3d shade(const Camera& camera, const RenderOptions& options,
                                 const Vec3d& normal, const Vec3d& ray_direction, bool front)
{
    const Color c = front ? options.front_color : options.back_color;
    return Vec3d(c.r, c.g, c.b) * shade_intensity(camera, options, normal, ray_direction);
}

[[nodiscard]] inline Vec3d to_vec(const Color& c)
{
    return {static_cast<double>(c.r), static_cast<double>(c.g), static_cast<double>(c.b)};
}

/// Stores the average of `sum` over `count` samples into pixel (x, y), rounded and clamped.
void store_pixel(Image& image, int x, int y, const Vec3d& sum, int count);

/// A blank image of the options' size.
[[nodiscard]] Image make_image(const RenderOptions& options);

} // namespace pointform::detail
