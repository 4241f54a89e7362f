// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/implicit/primitives.h"

#include "pointform/core/error.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>

namespace pointform {
namespace {

using Vec2d = Eigen::Vector2d;

void require_finite(const Vec3d& v, const char* what)
{
    if (!v.allFinite())
    {
        throw InvalidInput(std::string(what) + " must be finite");
    }
}

void require_positive(double value, const char* what)
{
    if (!(value > 0.0) || !std::isfinite(value))
    {
        throw InvalidInput(std::string(what) + " must be positive and finite, got " +
                           std::to_string(value));
    }
}

void require_non_negative(double value, const char* what)
{
    if (!(value >= 0.0) || !std::isfinite(value))
    {
        throw InvalidInput(std::string(what) + " must be non-negative and finite, got " +
                           std::to_string(value));
    }
}

Vec3d unit_axis(const Vec3d& v, const char* what)
{
    require_finite(v, what);
    const double n = v.norm();
    if (!(n > 1e-300))
    {
        throw InvalidInput(std::string(what) + " must be non-zero");
    }
    return v / n;
}

/// A unit vector perpendicular to the unit vector u.
Vec3d any_perpendicular(const Vec3d& u)
{
    Vec3d::Index axis = 0;
    u.cwiseAbs().minCoeff(&axis);
    return u.cross(Vec3d::Unit(axis)).normalized();
}

/// Bounding box of a disk of radius r centred at c, normal u (unit).
void extend_by_disk(Aabb& box, const Vec3d& c, const Vec3d& u, double r)
{
    const Vec3d extent = (Vec3d::Ones() - u.cwiseAbs2()).cwiseMax(0.0).cwiseSqrt() * r;
    box.extend(c - extent);
    box.extend(c + extent);
}

/// Splits p − origin into the height h along the unit axis and the radial unit direction
/// (any perpendicular on the axis); returns the distance from the axis.
double meridian(const Vec3d& v, const Vec3d& axis, double& h, Vec3d& radial)
{
    h = v.dot(axis);
    const Vec3d w = v - h * axis;
    const double rho = w.norm();
    radial = rho > 1e-300 ? Vec3d(w / rho) : any_perpendicular(axis);
    return rho;
}

} // namespace

// ---------------------------------------------------------------------------------------------

SphereField::SphereField(const Vec3d& center, double radius) : center_(center), radius_(radius)
{
    require_finite(center, "sphere: centre");
    require_positive(radius, "sphere: radius");
}

FieldSample SphereField::evaluate(const Vec3d& p) const
{
    const Vec3d v = p - center_;
    const double d = v.norm();
    return {.value = d - radius_,
            .gradient = d > 1e-300 ? Vec3d(v / d) : Vec3d::UnitZ(),
            .defined = true};
}

Aabb SphereField::bounds() const
{
    return {.min = center_ - Vec3d::Constant(radius_), .max = center_ + Vec3d::Constant(radius_)};
}

void SphereField::append_seeds(std::vector<Vec3d>& seeds) const
{
    // The 6 axis points and the 8 octant diagonals: an operator keeps those on its result.
    for (int axis = 0; axis < 3; ++axis)
    {
        seeds.push_back(center_ + radius_ * Vec3d::Unit(axis));
        seeds.push_back(center_ - radius_ * Vec3d::Unit(axis));
    }
    for (int octant = 0; octant < 8; ++octant)
    {
        const Vec3d d((octant & 1) != 0 ? 1.0 : -1.0, (octant & 2) != 0 ? 1.0 : -1.0,
                      (octant & 4) != 0 ? 1.0 : -1.0);
        seeds.push_back(center_ + (radius_ / std::sqrt(3.0)) * d);
    }
}

// ---------------------------------------------------------------------------------------------

BoxField::BoxField(const Aabb& box, double rounding)
    : BoxField(box.center(), 0.5 * box.size(), Mat3d::Identity(), rounding)
{
    if (box.is_empty())
    {
        throw InvalidInput("box: empty box");
    }
}

BoxField::BoxField(const Vec3d& center, const Vec3d& half_extents, const Mat3d& rotation,
                   double rounding)
    : center_(center), half_extents_(half_extents), rotation_(rotation), rounding_(rounding)
{
    require_finite(center, "box: centre");
    for (int i = 0; i < 3; ++i)
    {
        require_positive(half_extents[i], "box: half extent");
    }
    if (!rotation.allFinite() ||
        !(rotation.transpose() * rotation).isApprox(Mat3d::Identity(), 1e-9) ||
        !(rotation.determinant() > 0.0))
    {
        throw InvalidInput("box: the rotation must be orthonormal with determinant +1");
    }
    require_non_negative(rounding, "box: rounding radius");
    if (rounding > half_extents.minCoeff())
    {
        throw InvalidInput("box: rounding radius " + std::to_string(rounding) +
                           " exceeds half the smallest side " +
                           std::to_string(half_extents.minCoeff()));
    }
}

FieldSample BoxField::evaluate(const Vec3d& p) const
{
    const Vec3d local = rotation_.transpose() * (p - center_);
    const Vec3d sign = local.unaryExpr([](double x) { return x < 0.0 ? -1.0 : 1.0; });
    const Vec3d d = local.cwiseAbs() - (half_extents_ - Vec3d::Constant(rounding_));
    const Vec3d outside = d.cwiseMax(0.0);
    const double outside_norm = outside.norm();
    FieldSample s;
    s.defined = true;
    if (outside_norm > 0.0)
    {
        s.value = outside_norm - rounding_;
        s.gradient = rotation_ * sign.cwiseProduct(outside / outside_norm);
    }
    else
    {
        Vec3d::Index axis = 0;
        const double m = d.maxCoeff(&axis);
        s.value = m - rounding_;
        s.gradient = rotation_ * (sign[axis] * Vec3d::Unit(axis));
    }
    return s;
}

Aabb BoxField::bounds() const
{
    const Vec3d extent = rotation_.cwiseAbs() * half_extents_;
    return {.min = center_ - extent, .max = center_ + extent};
}

void BoxField::append_seeds(std::vector<Vec3d>& seeds) const
{
    // The face centres, and the corners and edge midpoints (on the rounding where it is
    // rounded): an operator keeps those on its result.
    for (int axis = 0; axis < 3; ++axis)
    {
        const Vec3d offset = half_extents_[axis] * rotation_.col(axis);
        seeds.push_back(center_ + offset);
        seeds.push_back(center_ - offset);
    }
    const Vec3d inner = half_extents_ - Vec3d::Constant(rounding_);
    for (int x = -1; x <= 1; ++x)
    {
        for (int y = -1; y <= 1; ++y)
        {
            for (int z = -1; z <= 1; ++z)
            {
                const Vec3d d(x, y, z);
                const int nonzero = std::abs(x) + std::abs(y) + std::abs(z);
                if (nonzero < 2)
                {
                    continue; // the centre and the face centres
                }
                const Vec3d local =
                    inner.cwiseProduct(d) + (rounding_ / std::sqrt(double(nonzero))) * d;
                seeds.push_back(center_ + rotation_ * local);
            }
        }
    }
}

// ---------------------------------------------------------------------------------------------

CappedConeField::CappedConeField(const Vec3d& a, const Vec3d& b, double radius_a, double radius_b)
    : a_(a), b_(b), radius_a_(radius_a), radius_b_(radius_b)
{
    require_finite(a, "cone: end point a");
    require_finite(b, "cone: end point b");
    require_non_negative(radius_a, "cone: radius at a");
    require_non_negative(radius_b, "cone: radius at b");
    if (!(std::max(radius_a, radius_b) > 0.0))
    {
        throw InvalidInput("cone: at least one radius must be positive");
    }
    const double length = (b - a).norm();
    if (!(length > 0.0))
    {
        throw InvalidInput("cone: the two end points coincide");
    }
    axis_ = (b - a) / length;
    half_height_ = 0.5 * length;
}

FieldSample CappedConeField::evaluate(const Vec3d& p) const
{
    double h = 0.0;
    Vec3d radial;
    const double rho = meridian(p - 0.5 * (a_ + b_), axis_, h, radial);
    const double hh = half_height_;
    // The trapezoid in the meridian plane (ρ, h), counter-clockwise; symmetric in ρ so that
    // the nearest boundary point of a query with ρ ≥ 0 is the 3D nearest point.
    const std::array<Vec2d, 4> corners = {Vec2d(-radius_a_, -hh), Vec2d(radius_a_, -hh),
                                          Vec2d(radius_b_, hh), Vec2d(-radius_b_, hh)};
    const Vec2d q(rho, h);
    double best = std::numeric_limits<double>::infinity();
    Vec2d closest = q;
    Vec2d edge_normal(0.0, -1.0);
    for (std::size_t e = 0; e < 4; ++e)
    {
        const Vec2d& p0 = corners[e];
        const Vec2d edge = corners[(e + 1) % 4] - p0;
        const double length2 = edge.squaredNorm();
        if (length2 <= 0.0)
        {
            continue;
        }
        const double t = std::clamp((q - p0).dot(edge) / length2, 0.0, 1.0);
        const Vec2d c = p0 + t * edge;
        const double dist = (q - c).norm();
        if (dist < best)
        {
            best = dist;
            closest = c;
            edge_normal = Vec2d(edge.y(), -edge.x()) / std::sqrt(length2);
        }
    }
    const double radius_here = radius_a_ + (radius_b_ - radius_a_) * (h + hh) / (2.0 * hh);
    const bool inside = std::abs(h) <= hh && rho <= radius_here;
    Vec2d g = edge_normal;
    if (best > 1e-12 * (hh + std::max(radius_a_, radius_b_)))
    {
        g = inside ? Vec2d((closest - q) / best) : Vec2d((q - closest) / best);
    }
    return {.value = inside ? -best : best,
            .gradient = g.x() * radial + g.y() * axis_,
            .defined = true};
}

Aabb CappedConeField::bounds() const
{
    Aabb box;
    extend_by_disk(box, a_, axis_, radius_a_);
    extend_by_disk(box, b_, axis_, radius_b_);
    return box;
}

void CappedConeField::append_seeds(std::vector<Vec3d>& seeds) const
{
    const Vec3d mid = 0.5 * (a_ + b_);
    const double r = 0.5 * (radius_a_ + radius_b_);
    const Vec3d e1 = any_perpendicular(axis_);
    const Vec3d e2 = axis_.cross(e1);
    for (const Vec3d& e : {e1, e2, Vec3d(-e1), Vec3d(-e2)})
    {
        seeds.push_back(mid + r * e);
    }
    if (radius_a_ > 0.0)
    {
        seeds.push_back(a_);
    }
    if (radius_b_ > 0.0)
    {
        seeds.push_back(b_);
    }
}

// ---------------------------------------------------------------------------------------------

TorusField::TorusField(const Vec3d& center, const Vec3d& axis, double major_radius,
                       double minor_radius)
    : center_(center),
      axis_(unit_axis(axis, "torus: axis")),
      major_radius_(major_radius),
      minor_radius_(minor_radius)
{
    require_finite(center, "torus: centre");
    require_non_negative(major_radius, "torus: major radius");
    require_positive(minor_radius, "torus: minor radius");
}

FieldSample TorusField::evaluate(const Vec3d& p) const
{
    double h = 0.0;
    Vec3d radial;
    const double rho = meridian(p - center_, axis_, h, radial);
    const Vec2d q(rho - major_radius_, h);
    const double len = q.norm();
    return {.value = len - minor_radius_,
            .gradient = len > 1e-300 ? Vec3d((q.x() * radial + q.y() * axis_) / len) : radial,
            .defined = true};
}

Aabb TorusField::bounds() const
{
    Aabb box;
    extend_by_disk(box, center_, axis_, major_radius_);
    box.min -= Vec3d::Constant(minor_radius_);
    box.max += Vec3d::Constant(minor_radius_);
    return box;
}

void TorusField::append_seeds(std::vector<Vec3d>& seeds) const
{
    const Vec3d e1 = any_perpendicular(axis_);
    const Vec3d e2 = axis_.cross(e1);
    const double r = major_radius_ + minor_radius_;
    for (const Vec3d& e : {e1, e2, Vec3d(-e1), Vec3d(-e2)})
    {
        seeds.push_back(center_ + r * e);
    }
}

// ---------------------------------------------------------------------------------------------

HalfSpaceField::HalfSpaceField(const Vec3d& point, const Vec3d& normal)
    : point_(point), normal_(unit_axis(normal, "half-space: normal"))
{
    require_finite(point, "half-space: point");
}

FieldSample HalfSpaceField::evaluate(const Vec3d& p) const
{
    return {.value = (p - point_).dot(normal_), .gradient = normal_, .defined = true};
}

Aabb HalfSpaceField::bounds() const
{
    constexpr double inf = std::numeric_limits<double>::infinity();
    Aabb box{.min = Vec3d::Constant(-inf), .max = Vec3d::Constant(inf)};
    for (int axis = 0; axis < 3; ++axis)
    {
        if (std::abs(normal_[axis]) == 1.0)
        {
            // The solid lies on the side the normal points away from.
            if (normal_[axis] > 0.0)
            {
                box.max[axis] = point_[axis];
            }
            else
            {
                box.min[axis] = point_[axis];
            }
        }
    }
    return box;
}

void HalfSpaceField::append_seeds(std::vector<Vec3d>& seeds) const
{
    seeds.push_back(point_);
}

// ---------------------------------------------------------------------------------------------

std::shared_ptr<const Field> make_sphere(const Vec3d& center, double radius)
{
    return std::make_shared<const SphereField>(center, radius);
}

std::shared_ptr<const Field> make_box(const Vec3d& corner_a, const Vec3d& corner_b, double rounding)
{
    require_finite(corner_a, "box: corner");
    require_finite(corner_b, "box: corner");
    return std::make_shared<const BoxField>(
        Aabb{.min = corner_a.cwiseMin(corner_b), .max = corner_a.cwiseMax(corner_b)}, rounding);
}

std::shared_ptr<const Field> make_oriented_box(const Vec3d& center, const Vec3d& half_extents,
                                               const Mat3d& rotation, double rounding)
{
    return std::make_shared<const BoxField>(center, half_extents, rotation, rounding);
}

std::shared_ptr<const Field> make_cylinder(const Vec3d& a, const Vec3d& b, double radius)
{
    require_positive(radius, "cylinder: radius");
    return std::make_shared<const CappedConeField>(a, b, radius, radius);
}

std::shared_ptr<const Field> make_cone(const Vec3d& a, const Vec3d& b, double radius_a,
                                       double radius_b)
{
    return std::make_shared<const CappedConeField>(a, b, radius_a, radius_b);
}

std::shared_ptr<const Field> make_torus(const Vec3d& center, const Vec3d& axis, double major_radius,
                                        double minor_radius)
{
    return std::make_shared<const TorusField>(center, axis, major_radius, minor_radius);
}

std::shared_ptr<const Field> make_half_space(const Vec3d& point, const Vec3d& normal)
{
    return std::make_shared<const HalfSpaceField>(point, normal);
}

} // namespace pointform
