// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/implicit/field.h"

#include "pointform/core/error.h"
#include "pointform/core/parallel.h"

#include <algorithm>
#include <limits>
#include <span>
#include <vector>

namespace pointform {

Field::~Field() = default;

void check_within_sizes(const char* function, std::size_t points, std::size_t lo, std::size_t hi,
                        std::size_t out)
{
    check_same_size(function, "lo", lo, points);
    check_same_size(function, "hi", hi, points);
    check_same_size(function, "out", out, points);
}

void Field::evaluate(std::span<const Vec3d> points, std::span<FieldSample> out) const
{
    // Through the batch evaluate_within(), which operators answer member by member, in runs
    // that share one unbounded range (no allocation per call).
    check_same_size("Field::evaluate", "out", out.size(), points.size());
    constexpr std::size_t run = std::size_t{1} << 16;
    static const std::vector<double> lo(run, -std::numeric_limits<double>::infinity());
    static const std::vector<double> hi(run, std::numeric_limits<double>::infinity());
    for (std::size_t begin = 0; begin < points.size(); begin += run)
    {
        const std::size_t count = std::min(run, points.size() - begin);
        evaluate_within(points.subspan(begin, count), std::span(lo).first(count),
                        std::span(hi).first(count), out.subspan(begin, count));
    }
}

FieldSample Field::evaluate_within(const Vec3d& p, double /*lo*/, double /*hi*/) const
{
    return evaluate(p);
}

void Field::evaluate_within(std::span<const Vec3d> points, std::span<const double> lo,
                            std::span<const double> hi, std::span<FieldSample> out) const
{
    check_within_sizes("Field::evaluate_within", points.size(), lo.size(), hi.size(), out.size());
    parallel_blocks(points.size(), 1024, [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i)
        {
            out[i] = evaluate_within(points[i], lo[i], hi[i]);
        }
    });
}

double Field::cost() const
{
    return 1.0;
}

void Field::append_seeds(std::vector<Vec3d>& /*seeds*/) const {}

} // namespace pointform
