// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

// Keeps a product apart from the sum it goes into: where the compiler may fuse multiplies and
// adds (a target with FMA), squared distances are then rounded the same on every path that
// computes them (the point grid's scalar and vector loops, the kd-tree's metric), so that any
// of them gives the bits the others give.
// Without FMA instructions (the default x86-64 target) nothing can be fused and the barrier
// is left out: it costs the kd-tree's search a few percent.
#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__)) && defined(__FMA__)
#define PF_UNFUSED(value) asm("" : "+x"(value))
#elif defined(__GNUC__) && defined(__aarch64__)
#define PF_UNFUSED(value) asm("" : "+w"(value))
#else
#define PF_UNFUSED(value) static_cast<void>(value)
#endif

namespace pointform::detail {

/// (a − b)² summed over x, y, z in that order, each square rounded on its own: the squared
/// distance as the point grid and the kd-tree compute it.
[[nodiscard]] inline float unfused_squared_distance(float ax, float ay, float az, float bx,
                                                    float by, float bz)
{
    const float dx = ax - bx;
    const float dy = ay - by;
    const float dz = az - bz;
    float xx = dx * dx;
    float yy = dy * dy;
    float zz = dz * dz;
    PF_UNFUSED(xx);
    PF_UNFUSED(yy);
    PF_UNFUSED(zz);
    return xx + yy + zz;
}

} // namespace pointform::detail
