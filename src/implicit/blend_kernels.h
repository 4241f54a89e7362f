// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// The point field's per-sample data and the blend of several samples' surfaces at a query
// (PointField, PlaneFit::Blend and Quadric): private to the implicit module, in a header of its
// own so that tests can compare the vectorized paths with each other and with the formula.

#pragma once

#include "pointform/core/types.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>

namespace pointform::detail {

/// What the field reads of one sample, packed in the grid's order so that the samples a query
/// meets are next to each other in memory.
///
/// Each sample carries a local surface: in the frame (t1, t2, n) at the sample, the height
/// h(u, v) = a + b u + c v + d u² + e uv + f v² over its tangent plane. The paper's plane is
/// h = 0 (Raw), Hoppe's centroid plane h = a (Centroid, Blend), and the local quadric fit all
/// six (Quadric).
struct alignas(64) PackedSurfel
{
    Vec3f position;
    float radius;
    Vec3f normal;
    float a; ///< height of the surface over the sample along the normal
    Vec3f tangent;
    float b;
    float c, d, e, f;

    /// Signed distance of `p` (relative to the cloud origin) to the sample's surface, measured
    /// along the normal, and its gradient.
    [[nodiscard]] double distance(const Vec3d& p, Vec3d* gradient) const
    {
        const Vec3d x = p - position.cast<double>();
        const Vec3d n = normal.cast<double>();
        const Vec3d t1 = tangent.cast<double>();
        const Vec3d t2 = n.cross(t1);
        const double u = x.dot(t1);
        const double v = x.dot(t2);
        const auto coef = [](float value) {
            return static_cast<double>(value);
        };
        const double height = coef(a) + coef(b) * u + coef(c) * v + coef(d) * u * u +
                              coef(e) * u * v + coef(f) * v * v;
        if (gradient != nullptr)
        {
            *gradient = n - (coef(b) + 2.0 * coef(d) * u + coef(e) * v) * t1 -
                        (coef(c) + coef(e) * u + 2.0 * coef(f) * v) * t2;
        }
        return x.dot(n) - height;
    }
};

static_assert(sizeof(PackedSurfel) == 16 * sizeof(float), "the blend reads surfels as 16 floats");

/// Σ over the blended samples of what the blend adds up (see PointField::Impl::evaluate_with).
struct BlendSums
{
    double weight = 0.0;
    double value = 0.0;
    Vec3d normal = Vec3d::Zero();
    Vec3d weighted_gradient = Vec3d::Zero();
    Vec3d gradient = Vec3d::Zero();
};

/// Which code adds up the blend: the baseline vectors (four samples at a time in the
/// baseline target's registers), AVX2 registers (the same operations in the same order, so the
/// same sums bit for bit), or whichever the CPU runs fastest.
enum class BlendPath
{
    automatic,
    baseline,
    avx2, ///< only where blend_has_avx2()
};

/// Whether this build has the AVX2 path and the CPU runs it.
[[nodiscard]] bool blend_has_avx2();

/// The blend sums of samples `slot[0, used)` (indices into `packed`, `dist2` their squared
/// distances to `p`) at `p`, relative to the cloud origin, with weights of support 1 / inv_h
/// (Wendland's C² kernel of the distance): Σ w_i, Σ w_i d_i, Σ w_i ∇d_i, Σ d_i ∇w_i and Σ ∇w_i
/// with d_i the signed distance to sample i's surface.
[[nodiscard]] BlendSums blend_sums(const PackedSurfel* packed, const std::uint32_t* slot,
                                   const float* dist2, std::size_t used, const Vec3d& p,
                                   double inv_h, BlendPath path = BlendPath::automatic);

/// The blend sums one sample at a time, with `distance(j, &gradient, &factor)` the signed
/// distance to the surface of sample slot[j] at `p` and its gradient, and optionally a factor
/// on its weight (left at 1 by blend_sums_reference(): the samples' own surfaces).
template <typename Distance>
[[nodiscard]] BlendSums blend_sums_of(const PackedSurfel* packed, const std::uint32_t* slot,
                                      const float* dist2, std::size_t used, const Vec3d& p,
                                      double inv_h, Distance distance)
{
    BlendSums sums;
    for (std::size_t j = 0; j < used; ++j)
    {
        const Vec3d offset = p - packed[slot[j]].position.template cast<double>();
        const double t = std::sqrt(static_cast<double>(dist2[j])) * inv_h;
        const double u = std::max(0.0, 1.0 - t);
        const double u3 = u * u * u;
        const double wendland = u3 * u * (4.0 * t + 1.0);
        const Vec3d wendland_gradient = ((-20.0 * inv_h * inv_h) * u3) * offset;
        Vec3d normal;
        double factor = 1.0;
        const double value = distance(j, &normal, &factor);
        const double weight = factor * wendland;
        const Vec3d weight_gradient = factor * wendland_gradient;
        sums.weight += weight;
        sums.value += weight * value;
        sums.normal += weight * normal;
        sums.weighted_gradient += value * weight_gradient;
        sums.gradient += weight_gradient;
    }
    return sums;
}

/// blend_sums() one sample at a time, as the formula reads (a compiler without GCC's vector
/// extension runs this); the same sums up to rounding.
[[nodiscard]] BlendSums blend_sums_reference(const PackedSurfel* packed, const std::uint32_t* slot,
                                             const float* dist2, std::size_t used, const Vec3d& p,
                                             double inv_h);

} // namespace pointform::detail
