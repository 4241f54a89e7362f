// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// How far a semi-regular mesh's finest level lies from the unit sphere, for tests.

#pragma once

#include "pointform/geometry/multires_mesh.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace pointform::test {

/// The largest and the mean distance from the unit sphere over the finest level's vertices and
/// face centroids, among those no farther than `within` from `centre` (all of them by default).
struct SphereDeviation
{
    double worst = 0.0;
    double mean = 0.0;
};

inline SphereDeviation sphere_deviation(const MultiresMesh& mesh,
                                        const Vec3d& centre = Vec3d::Zero(),
                                        double within = std::numeric_limits<double>::infinity())
{
    SphereDeviation out;
    double sum = 0.0;
    std::size_t count = 0;
    for (const Triangle& t : mesh.faces(mesh.finest_level()))
    {
        const Vec3d a = mesh.world(t[0]);
        const Vec3d b = mesh.world(t[1]);
        const Vec3d c = mesh.world(t[2]);
        for (const Vec3d& p : {a, Vec3d((a + b + c) / 3.0)})
        {
            if ((p - centre).norm() > within)
                continue;
            const double d = std::abs(p.norm() - 1.0);
            out.worst = std::max(out.worst, d);
            sum += d;
            ++count;
        }
    }
    out.mean = count > 0 ? sum / static_cast<double>(count) : 0.0;
    return out;
}

} // namespace pointform::test
