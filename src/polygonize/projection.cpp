// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/polygonize/projection.h"

#include "pointform/core/error.h"

#include <cmath>
#include <limits>
#include <optional>

namespace pointform {

namespace {

/// One sample of the field restricted to the line: g(t) = f(p + t·d).
struct LineSample
{
    double t = 0.0;
    double value = 0.0;
    bool defined = false;
    double slope = 0.0; ///< the gradient along the line, d·∇f (0 where not finite)
};

class Line
{
public:
    Line(const Field& field, const Vec3d& p, const Vec3d& d) : field_(field), p_(p), d_(d) {}

    [[nodiscard]] LineSample at(double t) const { return of(t, field_.evaluate(point(t))); }
    [[nodiscard]] LineSample of(double t, const FieldSample& s) const
    {
        if (!std::isfinite(s.value))
            return {t, std::numeric_limits<double>::quiet_NaN(), false, 0.0};
        const double slope = s.gradient.dot(d_);
        return {t, s.value, s.defined, std::isfinite(slope) ? slope : 0.0};
    }
    [[nodiscard]] Vec3d point(double t) const { return p_ + t * d_; }

private:
    const Field& field_;
    Vec3d p_;
    Vec3d d_;
};

/// Refines a bracket lo.t < hi.t, lo.value < 0 <= hi.value, by Illinois regula falsi. Returns
/// the parameter of the crossing, or nullopt if the located point is not a defined sample.
std::optional<double> refine_bracket(const Line& line, LineSample lo, LineSample hi,
                                     double tolerance, int max_iterations)
{
    if (hi.value == 0.0 && hi.defined)
        return hi.t;
    double flo = lo.value;
    double fhi = hi.value;
    int side = 0; // which end was replaced last time: -1 lo, +1 hi
    for (int it = 0; it < max_iterations && hi.t - lo.t > tolerance; ++it)
    {
        double t = (lo.t * fhi - hi.t * flo) / (fhi - flo);
        // Rounding can put the secant point on an end: bisect instead.
        if (!(t > lo.t && t < hi.t))
            t = 0.5 * (lo.t + hi.t);
        const LineSample s = line.at(t);
        if (std::isnan(s.value))
            return std::nullopt;
        // Undefined samples still carry the sign (field.h), which keeps the bracket valid; the
        // final point must be defined. Values are distance-like, so |f| below the tolerance is
        // as good as a small interval.
        if (std::abs(s.value) <= tolerance)
        {
            if (s.defined)
                return t;
        }
        if (s.value < 0.0)
        {
            lo = s;
            flo = s.value;
            if (side == -1)
                fhi *= 0.5;
            side = -1;
        }
        else
        {
            hi = s;
            fhi = s.value;
            if (side == +1)
                flo *= 0.5;
            side = +1;
        }
    }
    // The interval is small: report its end nearer to zero. Where one end is undefined the
    // crossing is real only if the defined end is itself (almost) on the zero set; otherwise the
    // sign change is the rim of a hole (the surface ends there), not a crossing.
    const LineSample& a = std::abs(lo.value) <= std::abs(hi.value) ? lo : hi;
    const LineSample& b = (&a == &lo) ? hi : lo;
    if (a.defined && (b.defined || std::abs(a.value) <= 16.0 * tolerance))
        return a.t;
    if (b.defined && std::abs(b.value) <= 16.0 * tolerance)
        return b.t;
    return std::nullopt;
}

} // namespace

namespace {

/// project_to_zero(), with the field's sample at p if the caller has it.
std::optional<Vec3d> project_from(const Field& field, const FieldSample* at_p, const Vec3d& p,
                                  const Vec3d& direction, double max_distance,
                                  const ProjectionOptions& options)
{
    if (options.steps < 1 || options.max_iterations < 1 ||
        !(options.relative_tolerance > 0.0 && std::isfinite(options.relative_tolerance)))
        throw InvalidInput(
            "project_to_zero: steps and max_iterations must be >= 1 and the "
            "tolerance positive and finite");
    const double length = direction.norm();
    if (!(length > 0.0) || !std::isfinite(length) || !(max_distance > 0.0) ||
        !std::isfinite(max_distance) || !p.allFinite())
        return std::nullopt;

    const Line line(field, p, direction / length);
    const double h = max_distance / options.steps;
    const double tolerance = options.relative_tolerance * max_distance;

    // p + 0·d is p, bit for bit: the caller's sample is the line's at 0.
    const LineSample centre = at_p != nullptr ? line.of(0.0, *at_p) : line.at(0.0);
    if (centre.defined && std::abs(centre.value) <= tolerance)
    {
        // On the surface (as near as a located crossing is): accept if the field grows along
        // the direction.
        if (centre.slope > 0.0)
            return p;
    }

    LineSample pos_prev = centre; // innermost sample of the positive side
    LineSample neg_prev = centre; // innermost sample of the negative side

    // The first sample on the side the sign at p points to, at twice the distance where the
    // field's slope at p puts the surface (a Newton step), where that lies within the first step:
    // a point near the surface (a relaxed or predicted vertex, most of them) then brackets its
    // crossing tightly, which regula falsi closes in an evaluation or two instead of the three
    // to five that a bracket of a whole step takes. Any sign change it finds lies within the
    // first step on that side, as the march's would (the other side cannot close a bracket
    // there). Otherwise, or if the sign does not change, the march goes on as it would.
    if (centre.defined && centre.slope > 0.0)
    {
        const double guess = -2.0 * centre.value / centre.slope;
        if (std::abs(guess) < h && guess != 0.0)
        {
            const LineSample probe = line.at(guess);
            std::optional<double> found;
            if (guess > 0.0 && probe.value >= 0.0)
                found = refine_bracket(line, centre, probe, tolerance, options.max_iterations);
            else if (guess < 0.0 && probe.value < 0.0)
                found = refine_bracket(line, probe, centre, tolerance, options.max_iterations);
            if (found)
                return line.point(*found);
            (guess > 0.0 ? pos_prev : neg_prev) = probe;
        }
    }
    for (int k = 1; k <= options.steps; ++k)
    {
        const double r = k == options.steps ? max_distance : k * h;
        // A side can close a bracket in this step only from an inner sample of the right sign;
        // the other side's sample is taken only if the march goes on (at the first step one
        // side alone can, by the sign at p: a crossing there costs one evaluation fewer).
        std::optional<LineSample> pos;
        std::optional<LineSample> neg;
        std::optional<double> best;
        // Positive side: interval [pos_prev.t, pos.t], crossing when pos_prev < 0 <= pos.
        // Undefined samples still carry the sign (field.h), so a band of definition thinner than
        // a step is not jumped over; the located point must be defined.
        if (pos_prev.value < 0.0)
        {
            pos = line.at(r);
            if (pos->value >= 0.0)
                best = refine_bracket(line, pos_prev, *pos, tolerance, options.max_iterations);
        }
        // Negative side: interval [neg.t, neg_prev.t], crossing when neg < 0 <= neg_prev.
        if (neg_prev.value >= 0.0)
        {
            neg = line.at(-r);
            if (neg->value < 0.0)
            {
                const std::optional<double> t =
                    refine_bracket(line, *neg, neg_prev, tolerance, options.max_iterations);
                if (t && (!best || std::abs(*t) < std::abs(*best)))
                    best = t;
            }
        }
        if (best)
            return line.point(*best);
        pos_prev = pos ? *pos : line.at(r);
        neg_prev = neg ? *neg : line.at(-r);
    }
    return std::nullopt;
}

} // namespace

std::optional<Vec3d> project_to_zero(const Field& field, const Vec3d& p, const Vec3d& direction,
                                     double max_distance)
{
    return project_from(field, nullptr, p, direction, max_distance, ProjectionOptions{});
}

std::optional<Vec3d> project_to_zero(const Field& field, const Vec3d& p, const Vec3d& direction,
                                     double max_distance, const ProjectionOptions& options)
{
    return project_from(field, nullptr, p, direction, max_distance, options);
}

std::optional<Vec3d> project_to_zero(const Field& field, const FieldSample& at_p, const Vec3d& p,
                                     const Vec3d& direction, double max_distance)
{
    return project_from(field, &at_p, p, direction, max_distance, ProjectionOptions{});
}

std::optional<Vec3d> newton_to_zero(const Field& field, const Vec3d& p, double max_distance)
{
    if (!p.allFinite() || !(max_distance > 0.0) || !std::isfinite(max_distance))
        return std::nullopt;
    const double tolerance = 1e-7 * max_distance;
    Vec3d q = p;
    for (int step = 0; step < 16; ++step)
    {
        const FieldSample s = field.evaluate(q);
        if (!std::isfinite(s.value) || !s.gradient.allFinite())
            return std::nullopt;
        if (s.defined && std::abs(s.value) <= tolerance)
            return q;
        const double g2 = s.gradient.squaredNorm();
        if (!(g2 > 0.0))
            return std::nullopt;
        q -= (s.value / g2) * s.gradient;
        if ((q - p).norm() > max_distance)
            return std::nullopt;
    }
    return std::nullopt;
}

} // namespace pointform
