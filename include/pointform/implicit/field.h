// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include "pointform/core/types.h"
#include "pointform/geometry/aabb.h"

#include <span>
#include <vector>

namespace pointform {

/// \brief One evaluation of a field at a point.
///
/// Conventions (every field and operator keeps them): the value is a signed distance-like
/// quantity in the input's units, negative inside the solid, positive outside, zero on the
/// surface; the gradient points outwards. `defined` is false where the field is the paper's
/// f = ∞ (beyond every influence radius, §4): there `value` still carries the sign (inside or
/// outside) and a magnitude that grows with the distance from the surface, so that operators can
/// tell deep inside from far outside, and polygonization treats the point as "no surface here"
/// (how closely it follows the distance depends on the field: see PointField).
struct FieldSample
{
    double value = 0.0;
    Vec3d gradient = Vec3d::Zero();
    bool defined = false;
};

/// \brief A signed scalar field over R³ (Level 2): point fields, analytic primitives and the
/// operators over them all implement this interface.
///
/// Implementations are immutable after construction and safe to evaluate from many threads.
class Field
{
public:
    Field() = default;
    Field(const Field&) = delete;
    Field& operator=(const Field&) = delete;
    Field(Field&&) = delete;
    Field& operator=(Field&&) = delete;
    virtual ~Field();

    /// \brief Value and gradient at one world-space point.
    [[nodiscard]] virtual FieldSample evaluate(const Vec3d& p) const = 0;

    /// \brief Value and gradient at many points, in parallel; `out.size()` must equal
    /// `points.size()`. The result is the same as calling evaluate() per point, whatever the
    /// thread count.
    virtual void evaluate(std::span<const Vec3d> points, std::span<FieldSample> out) const;

    /// \brief A box that contains every point where the field is defined and near zero, i.e.
    /// where a surface can be. Polygonization grids are laid over it.
    [[nodiscard]] virtual Aabb bounds() const = 0;

    /// \brief Appends points on or near the zero set, at least one per connected piece of the
    /// surface when the field knows them (samples of a scan, points on a primitive). Sparse
    /// polygonization starts from these and follows the surface; a field that knows none
    /// appends nothing and is polygonized densely over bounds().
    virtual void append_seeds(std::vector<Vec3d>& seeds) const;
};

} // namespace pointform
