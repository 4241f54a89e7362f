// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/implicit/transform.h"

#include "pointform/core/error.h"
#include "pointform/core/parallel.h"

#include <Eigen/Geometry>
#include <Eigen/SVD>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

namespace pointform {

TransformedField::TransformedField(std::shared_ptr<const Field> member, const Mat3d& linear,
                                   const Vec3d& translation)
    : member_(std::move(member)), linear_(linear), translation_(translation)
{
    if (member_ == nullptr)
    {
        throw InvalidInput("transform: no field to transform");
    }
    if (!linear.allFinite() || !translation.allFinite())
    {
        throw InvalidInput("transform: the matrix and the translation must be finite");
    }
    const Eigen::JacobiSVD<Mat3d> svd(linear);
    const Vec3d sigma = svd.singularValues();
    if (!(sigma[2] > 0.0) || sigma[0] / sigma[2] > 1e12)
    {
        throw InvalidInput("transform: the matrix is singular");
    }
    value_scale_ = sigma[2];
    inverse_ = linear.inverse();
    gradient_map_ = value_scale_ * inverse_.transpose();
}

FieldSample TransformedField::evaluate(const Vec3d& p) const
{
    return evaluate_within(p, -std::numeric_limits<double>::infinity(),
                           std::numeric_limits<double>::infinity());
}

// value = value_scale · f (value_scale > 0): f within [lo, hi] / value_scale, widened by a few
// rounding errors so that rounding cannot move a value across.
std::pair<double, double> TransformedField::member_range(double lo, double hi) const
{
    const auto scaled = [this](double x, double direction) {
        const double y = x / value_scale_;
        return std::isfinite(y)
                   ? y + direction * 8.0 * std::numeric_limits<double>::epsilon() * std::abs(y)
                   : y;
    };
    return {scaled(lo, -1.0), scaled(hi, 1.0)};
}

FieldSample TransformedField::transformed(FieldSample s) const
{
    s.value *= value_scale_;
    s.gradient = gradient_map_ * s.gradient;
    return s;
}

FieldSample TransformedField::evaluate_within(const Vec3d& p, double lo, double hi) const
{
    const auto [member_lo, member_hi] = member_range(lo, hi);
    return transformed(
        member_->evaluate_within(inverse_ * (p - translation_), member_lo, member_hi));
}

void TransformedField::evaluate_within(std::span<const Vec3d> points, std::span<const double> lo,
                                       std::span<const double> hi, std::span<FieldSample> out) const
{
    check_within_sizes("TransformedField::evaluate_within", points.size(), lo.size(), hi.size(),
                       out.size());
    parallel_blocks(points.size(), 1024, [&](std::size_t begin, std::size_t end) {
        const std::size_t n = end - begin;
        std::vector<Vec3d> local(n);
        std::vector<double> member_lo(n);
        std::vector<double> member_hi(n);
        std::vector<FieldSample> samples(n);
        for (std::size_t j = 0; j < n; ++j)
        {
            local[j] = inverse_ * (points[begin + j] - translation_);
            std::tie(member_lo[j], member_hi[j]) = member_range(lo[begin + j], hi[begin + j]);
        }
        member_->evaluate_within(local, member_lo, member_hi, samples);
        for (std::size_t j = 0; j < n; ++j)
        {
            out[begin + j] = transformed(samples[j]);
        }
    });
}

double TransformedField::cost() const
{
    return 1.0 + member_->cost();
}

Aabb TransformedField::bounds() const
{
    const Aabb box = member_->bounds();
    if (box.is_empty())
    {
        return box;
    }
    Aabb out;
    constexpr double inf = std::numeric_limits<double>::infinity();
    for (int corner = 0; corner < 8; ++corner)
    {
        Vec3d q;
        for (int j = 0; j < 3; ++j)
        {
            q[j] = ((corner >> j) & 1) != 0 ? box.max[j] : box.min[j];
        }
        for (int i = 0; i < 3; ++i)
        {
            // Skip zero coefficients so that an infinite side only spreads where it maps to.
            double x = translation_[i];
            for (int j = 0; j < 3; ++j)
            {
                if (linear_(i, j) != 0.0)
                {
                    x += linear_(i, j) * q[j];
                }
            }
            if (std::isnan(x))
            {
                out.min[i] = -inf;
                out.max[i] = inf;
            }
            else
            {
                out.min[i] = std::min(out.min[i], x);
                out.max[i] = std::max(out.max[i], x);
            }
        }
    }
    return out;
}

void TransformedField::append_seeds(std::vector<Vec3d>& seeds) const
{
    const std::size_t first = seeds.size();
    member_->append_seeds(seeds);
    for (std::size_t i = first; i < seeds.size(); ++i)
    {
        seeds[i] = linear_ * seeds[i] + translation_;
    }
}

std::shared_ptr<const Field> transform(std::shared_ptr<const Field> field, const Mat3d& linear,
                                       const Vec3d& translation)
{
    return std::make_shared<const TransformedField>(std::move(field), linear, translation);
}

std::shared_ptr<const Field> translate(std::shared_ptr<const Field> field, const Vec3d& offset)
{
    return transform(std::move(field), Mat3d::Identity(), offset);
}

std::shared_ptr<const Field> rotate(std::shared_ptr<const Field> field, const Mat3d& rotation,
                                    const Vec3d& center)
{
    if (!rotation.allFinite() ||
        (rotation.transpose() * rotation - Mat3d::Identity()).cwiseAbs().maxCoeff() > 1e-6 ||
        !(rotation.determinant() > 0.0))
    {
        throw InvalidInput("rotate: the matrix is not a rotation (orthonormal, determinant +1)");
    }
    if (!center.allFinite())
    {
        throw InvalidInput("rotate: the centre must be finite");
    }
    return transform(std::move(field), rotation, center - rotation * center);
}

std::shared_ptr<const Field> rotate(std::shared_ptr<const Field> field, const Vec3d& axis,
                                    double angle, const Vec3d& center)
{
    if (!axis.allFinite() || !(axis.norm() > 0.0) || !std::isfinite(angle))
    {
        throw InvalidInput("rotate: the axis must be non-zero and the angle finite");
    }
    const Mat3d r = Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
    return rotate(std::move(field), r, center);
}

std::shared_ptr<const Field> scale(std::shared_ptr<const Field> field, const Vec3d& factors,
                                   const Vec3d& center)
{
    for (int i = 0; i < 3; ++i)
    {
        if (!(factors[i] > 0.0) || !std::isfinite(factors[i]))
        {
            throw InvalidInput("scale: factors must be positive and finite, got " +
                               std::to_string(factors[i]));
        }
    }
    if (!center.allFinite())
    {
        throw InvalidInput("scale: the centre must be finite");
    }
    const Mat3d l = factors.asDiagonal();
    return transform(std::move(field), l, center - l * center);
}

std::shared_ptr<const Field> scale(std::shared_ptr<const Field> field, double factor,
                                   const Vec3d& center)
{
    return scale(std::move(field), Vec3d::Constant(factor), center);
}

} // namespace pointform
