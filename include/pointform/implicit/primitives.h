// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include "pointform/implicit/field.h"

#include <memory>

namespace pointform {

/// \brief Analytic primitives (§4.2: users model with these next to scans).
///
/// Every primitive gives the exact Euclidean signed distance (negative inside) and its exact
/// gradient, a unit vector pointing outwards; where the gradient is not unique (the centre of a
/// sphere, the medial axis of a box) one of the one-sided gradients is returned. Samples are
/// always defined. bounds() is tight (exact for spheres, boxes and tori, the box of the two end
/// disks for cylinders and cones); append_seeds() appends a few points on the surface, at least
/// one per connected piece, so sparse marching cubes finds it. Constructors throw InvalidInput
/// for non-finite input, a negative or zero radius or size, or a degenerate axis.

/// \brief A ball: f(p) = ‖p − c‖ − r.
class SphereField final : public Field
{
public:
    /// \param radius > 0, in input units
    SphereField(const Vec3d& center, double radius);

    [[nodiscard]] FieldSample evaluate(const Vec3d& p) const override;
    using Field::evaluate;
    [[nodiscard]] Aabb bounds() const override;
    void append_seeds(std::vector<Vec3d>& seeds) const override;

    [[nodiscard]] const Vec3d& center() const { return center_; }
    [[nodiscard]] double radius() const { return radius_; }

private:
    Vec3d center_;
    double radius_;
};

/// \brief A box, axis-aligned or oriented, optionally with its edges and corners rounded.
///
/// The box spans center ± half_extents along the columns of `rotation` (its local x, y, z axes).
/// With rounding r > 0 the box keeps its outer extent and its edges and corners become quarter
/// cylinders and spheres of radius r: f = sd_box(q, half_extents − r) − r, still exact.
class BoxField final : public Field
{
public:
    /// \brief An axis-aligned box.
    /// \param rounding in [0, half the smallest side]
    explicit BoxField(const Aabb& box, double rounding = 0.0);
    /// \param half_extents each > 0
    /// \param rotation orthonormal with determinant +1 (columns: the box's axes in world space)
    /// \param rounding in [0, min(half_extents)]
    BoxField(const Vec3d& center, const Vec3d& half_extents, const Mat3d& rotation,
             double rounding = 0.0);

    [[nodiscard]] FieldSample evaluate(const Vec3d& p) const override;
    using Field::evaluate;
    [[nodiscard]] Aabb bounds() const override;
    void append_seeds(std::vector<Vec3d>& seeds) const override;

    [[nodiscard]] const Vec3d& center() const { return center_; }
    [[nodiscard]] const Vec3d& half_extents() const { return half_extents_; }
    [[nodiscard]] const Mat3d& rotation() const { return rotation_; }
    [[nodiscard]] double rounding() const { return rounding_; }

private:
    Vec3d center_;
    Vec3d half_extents_;
    Mat3d rotation_;
    double rounding_;
};

/// \brief A capped cone (frustum) from end point a (radius ra) to end point b (radius rb), flat
/// caps; a cylinder when ra = rb, a cone with its apex at b when rb = 0.
///
/// Exact: the distance in the meridian half-plane (distance along the axis, distance from the
/// axis) to the trapezoid the solid sweeps.
class CappedConeField final : public Field
{
public:
    /// \param radius_a, radius_b ≥ 0, not both 0
    /// \throw InvalidInput also if a = b
    CappedConeField(const Vec3d& a, const Vec3d& b, double radius_a, double radius_b);

    [[nodiscard]] FieldSample evaluate(const Vec3d& p) const override;
    using Field::evaluate;
    [[nodiscard]] Aabb bounds() const override;
    void append_seeds(std::vector<Vec3d>& seeds) const override;

    [[nodiscard]] const Vec3d& a() const { return a_; }
    [[nodiscard]] const Vec3d& b() const { return b_; }
    [[nodiscard]] double radius_a() const { return radius_a_; }
    [[nodiscard]] double radius_b() const { return radius_b_; }

private:
    Vec3d a_;
    Vec3d b_;
    double radius_a_;
    double radius_b_;
    Vec3d axis_;         // unit, a → b
    double half_height_; // ‖b − a‖ / 2
};

/// \brief A torus: the points within `minor_radius` of the circle of radius `major_radius` around
/// `axis` through `center`; f = ‖(ρ − R, h)‖ − r with ρ the distance from the axis and h the
/// height along it. Exact also for a self-intersecting (spindle) torus, r > R.
class TorusField final : public Field
{
public:
    /// \param axis non-zero (normalised here)
    /// \param major_radius ≥ 0; \param minor_radius > 0
    TorusField(const Vec3d& center, const Vec3d& axis, double major_radius, double minor_radius);

    [[nodiscard]] FieldSample evaluate(const Vec3d& p) const override;
    using Field::evaluate;
    [[nodiscard]] Aabb bounds() const override;
    void append_seeds(std::vector<Vec3d>& seeds) const override;

    [[nodiscard]] const Vec3d& center() const { return center_; }
    [[nodiscard]] const Vec3d& axis() const { return axis_; }
    [[nodiscard]] double major_radius() const { return major_radius_; }
    [[nodiscard]] double minor_radius() const { return minor_radius_; }

private:
    Vec3d center_;
    Vec3d axis_;
    double major_radius_;
    double minor_radius_;
};

/// \brief The half-space behind a plane: f(p) = (p − point)·n, n the outward unit normal.
///
/// Unbounded: bounds() is infinite, except that a normal along ±x, ±y or ±z bounds that one
/// axis from one side. Polygonize it only intersected with something bounded (an intersection
/// or a difference whose first member is bounded: their bounds() are then finite), or lay the
/// grid over the scene's box yourself: grid_over() rejects an infinite box. Its one seed is
/// `point`; marching cubes follows the plane from there across the grid.
class HalfSpaceField final : public Field
{
public:
    /// \param normal non-zero, pointing out of the solid (normalised here)
    HalfSpaceField(const Vec3d& point, const Vec3d& normal);

    [[nodiscard]] FieldSample evaluate(const Vec3d& p) const override;
    using Field::evaluate;
    [[nodiscard]] Aabb bounds() const override;
    void append_seeds(std::vector<Vec3d>& seeds) const override;

    [[nodiscard]] const Vec3d& point() const { return point_; }
    [[nodiscard]] const Vec3d& normal() const { return normal_; }

private:
    Vec3d point_;
    Vec3d normal_;
};

/// \name Factories (the same validation as the constructors)
/// @{
[[nodiscard]] std::shared_ptr<const Field> make_sphere(const Vec3d& center, double radius);
/// \brief Axis-aligned box from its two opposite corners (any order), edges rounded by `rounding`.
[[nodiscard]] std::shared_ptr<const Field> make_box(const Vec3d& corner_a, const Vec3d& corner_b,
                                                    double rounding = 0.0);
[[nodiscard]] std::shared_ptr<const Field> make_oriented_box(const Vec3d& center,
                                                             const Vec3d& half_extents,
                                                             const Mat3d& rotation,
                                                             double rounding = 0.0);
/// \brief Cylinder of radius `radius` from a to b, flat caps.
[[nodiscard]] std::shared_ptr<const Field> make_cylinder(const Vec3d& a, const Vec3d& b,
                                                         double radius);
[[nodiscard]] std::shared_ptr<const Field> make_cone(const Vec3d& a, const Vec3d& b,
                                                     double radius_a, double radius_b);
[[nodiscard]] std::shared_ptr<const Field> make_torus(const Vec3d& center, const Vec3d& axis,
                                                      double major_radius, double minor_radius);
[[nodiscard]] std::shared_ptr<const Field> make_half_space(const Vec3d& point, const Vec3d& normal);
/// @}

} // namespace pointform
