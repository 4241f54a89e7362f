// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// Helpers shared by the field tests: random query points and finite-difference gradients.

#pragma once

#include "pointform/geometry/aabb.h"
#include "pointform/implicit/field.h"

#include <cstdint>
#include <random>
#include <vector>

namespace pointform::test {

/// `count` points uniformly distributed in `box`, the same for the same seed.
inline std::vector<Vec3d> random_points(const Aabb& box, int count, std::uint64_t seed)
{
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::vector<Vec3d> points;
    for (int i = 0; i < count; ++i)
    {
        const Vec3d t(u(rng), u(rng), u(rng));
        points.emplace_back(box.min + t.cwiseProduct(box.max - box.min));
    }
    return points;
}

/// Central differences of the field's value, to check an analytic gradient.
inline Vec3d numeric_gradient(const Field& f, const Vec3d& p, double h = 1e-6)
{
    Vec3d g;
    for (int i = 0; i < 3; ++i)
    {
        const Vec3d e = h * Vec3d::Unit(i);
        g[i] = (f.evaluate(p + e).value - f.evaluate(p - e).value) / (2.0 * h);
    }
    return g;
}

} // namespace pointform::test
