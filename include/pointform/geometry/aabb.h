// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include "pointform/core/types.h"

#include <limits>
#include <span>

namespace pointform {

/// \brief Axis-aligned bounding box in double precision. Empty when min > max.
struct Aabb
{
    Vec3d min = Vec3d::Constant(std::numeric_limits<double>::infinity());
    Vec3d max = Vec3d::Constant(-std::numeric_limits<double>::infinity());

    [[nodiscard]] bool is_empty() const { return (min.array() > max.array()).any(); }
    [[nodiscard]] Vec3d size() const { return is_empty() ? Vec3d::Zero() : Vec3d(max - min); }
    [[nodiscard]] Vec3d center() const { return 0.5 * (min + max); }
    [[nodiscard]] double diagonal() const { return size().norm(); }

    void extend(const Vec3d& p)
    {
        min = min.cwiseMin(p);
        max = max.cwiseMax(p);
    }
    [[nodiscard]] bool contains(const Vec3d& p) const
    {
        return (p.array() >= min.array()).all() && (p.array() <= max.array()).all();
    }
};

/// \brief Bounding box of float positions, offset by `origin` (so the box is in world units).
[[nodiscard]] Aabb bounding_box(std::span<const Vec3f> positions,
                                const Vec3d& origin = Vec3d::Zero());

} // namespace pointform
