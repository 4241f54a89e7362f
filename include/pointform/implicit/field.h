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
    /// thread count. By default the batch evaluate_within() over (−∞, ∞).
    /// \throw InvalidInput if the sizes differ (every implementation checks)
    virtual void evaluate(std::span<const Vec3d> points, std::span<FieldSample> out) const;

    /// \brief evaluate(p) where its value lies in [lo, hi]; elsewhere only the side is kept: a
    /// value below `lo` if the exact one is below it, above `hi` if the exact one is above it
    /// (either, where lo > hi), with any finite gradient and any `defined`.
    ///
    /// Operators ask their members this way, so that a costly member answers from a bound where
    /// another decides the result (a scan along a primitive that wins the min, far from the
    /// scan). Operators that use it give exactly evaluate()'s result where it lies in [lo, hi],
    /// the same member chosen on ties. The default evaluates exactly.
    [[nodiscard]] virtual FieldSample evaluate_within(const Vec3d& p, double lo, double hi) const;

    /// \brief evaluate_within() at many points, point i within [lo[i], hi[i]], in parallel (the
    /// same results as one by one, whatever the thread count). All spans have the same size.
    /// \throw InvalidInput if they do not (every implementation checks: check_within_sizes())
    virtual void evaluate_within(std::span<const Vec3d> points, std::span<const double> lo,
                                 std::span<const double> hi, std::span<FieldSample> out) const;

    /// \brief A rough relative cost of one evaluation (1: an analytic primitive). Operators ask
    /// cheaper members first, so that their values bound what the costlier ones must answer.
    [[nodiscard]] virtual double cost() const;

    /// \brief A box that contains every point where the field is defined and near zero, i.e.
    /// where a surface can be. Polygonization grids are laid over it.
    [[nodiscard]] virtual Aabb bounds() const = 0;

    /// \brief Appends points on or near the zero set, at least one per connected piece of the
    /// surface when the field knows them (samples of a scan, points on a primitive). Sparse
    /// polygonization starts from these and follows the surface; a field that knows none
    /// appends nothing and is polygonized densely over bounds().
    virtual void append_seeds(std::vector<Vec3d>& seeds) const;
};

/// \brief For the batch Field::evaluate_within() and its overrides: throws InvalidInput, naming
/// `function`, unless `lo`, `hi` and `out` hold one entry per point. Every implementation checks
/// once per call, in every build, so no caller's span is read or written past its end.
void check_within_sizes(const char* function, std::size_t points, std::size_t lo, std::size_t hi,
                        std::size_t out);

} // namespace pointform
