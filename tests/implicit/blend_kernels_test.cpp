// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// The point field's blend: the AVX2 and baseline paths give the same sums bit for bit, and both
// the formula's sums up to rounding.

#include "blend_kernels.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <vector>

namespace pointform {
namespace {

using detail::BlendPath;
using detail::BlendSums;
using detail::PackedSurfel;

/// Samples near the unit sphere with their radial normals, tangents and random quadric
/// coefficients of the sizes a fit gives (heights a few thousandths, curvatures about 1).
std::vector<PackedSurfel> random_surfels(std::size_t count, std::uint64_t seed)
{
    std::mt19937_64 rng(seed);
    std::normal_distribution<float> gauss;
    std::uniform_real_distribution<float> coefficient(-1.0F, 1.0F);
    std::vector<PackedSurfel> surfels(count);
    for (PackedSurfel& s : surfels)
    {
        s.normal = Vec3f(gauss(rng), gauss(rng), gauss(rng)).normalized();
        s.position = s.normal * (1.0F + 0.01F * coefficient(rng));
        s.radius = 0.05F;
        s.tangent = s.normal.cross(Vec3f::UnitX()).normalized();
        s.a = 0.003F * coefficient(rng);
        s.b = 0.1F * coefficient(rng);
        s.c = 0.1F * coefficient(rng);
        s.d = coefficient(rng);
        s.e = coefficient(rng);
        s.f = coefficient(rng);
    }
    return surfels;
}

void expect_near(const BlendSums& a, const BlendSums& b, double tolerance)
{
    EXPECT_NEAR(a.weight, b.weight, tolerance);
    EXPECT_NEAR(a.value, b.value, tolerance);
    EXPECT_LT((a.normal - b.normal).norm(), tolerance);
    EXPECT_LT((a.weighted_gradient - b.weighted_gradient).norm(), tolerance);
    EXPECT_LT((a.gradient - b.gradient).norm(), tolerance);
}

void expect_identical(const BlendSums& a, const BlendSums& b)
{
    EXPECT_EQ(a.weight, b.weight);
    EXPECT_EQ(a.value, b.value);
    EXPECT_EQ(a.normal, b.normal);
    EXPECT_EQ(a.weighted_gradient, b.weighted_gradient);
    EXPECT_EQ(a.gradient, b.gradient);
}

TEST(BlendKernels, EveryPathAddsUpTheFormula)
{
    const std::vector<PackedSurfel> surfels = random_surfels(200, 1);
    std::mt19937_64 rng(2);
    std::normal_distribution<double> gauss;
    std::vector<std::uint32_t> order(surfels.size());
    std::iota(order.begin(), order.end(), 0U);
    int compared = 0;
    for (int round = 0; round < 300; ++round)
    {
        // 1 to 32 samples (every remainder of four), in random order, around a random query.
        const std::size_t used = 1 + static_cast<std::size_t>(round) % 32;
        std::shuffle(order.begin(), order.end(), rng);
        const Vec3d p = Vec3d(gauss(rng), gauss(rng), gauss(rng)).normalized() * 1.02;
        std::vector<std::uint32_t> slot(order.begin(),
                                        order.begin() + static_cast<std::ptrdiff_t>(used));
        std::vector<float> dist2(used);
        double farthest = 0.0;
        for (std::size_t j = 0; j < used; ++j)
        {
            dist2[j] = (p.cast<float>() - surfels[slot[j]].position).squaredNorm();
            farthest = std::max(farthest, std::sqrt(static_cast<double>(dist2[j])));
        }
        // Support just beyond the farthest, so that every weight is positive and some are tiny.
        const double inv_h = 1.0 / (1.1 * farthest);
        const BlendSums reference =
            detail::blend_sums_reference(surfels.data(), slot.data(), dist2.data(), used, p, inv_h);
        const BlendSums baseline = detail::blend_sums(surfels.data(), slot.data(), dist2.data(),
                                                      used, p, inv_h, BlendPath::baseline);
        ASSERT_GT(reference.weight, 0.0);
        // The sums are of terms of order 1 to inv_h² (weights' gradients times distances).
        expect_near(baseline, reference, 1e-12 * std::max(1.0, inv_h * inv_h));
        if (detail::blend_has_avx2())
        {
            const BlendSums avx2 = detail::blend_sums(surfels.data(), slot.data(), dist2.data(),
                                                      used, p, inv_h, BlendPath::avx2);
            expect_identical(avx2, baseline);
            ++compared;
        }
        expect_identical(
            detail::blend_sums(surfels.data(), slot.data(), dist2.data(), used, p, inv_h),
            detail::blend_has_avx2() ? detail::blend_sums(surfels.data(), slot.data(), dist2.data(),
                                                          used, p, inv_h, BlendPath::avx2)
                                     : baseline);
    }
    RecordProperty("avx2_compared", compared);
}

TEST(BlendKernels, SamplesAtTheSupportAddNothing)
{
    // A sample exactly at the support's edge has weight zero and a zero weight gradient, so it
    // adds nothing: the field is continuous where a sample enters or leaves the blend.
    const std::vector<PackedSurfel> surfels = random_surfels(2, 3);
    const Vec3d p = surfels[0].position.cast<double>() * 1.01;
    std::vector<std::uint32_t> slot = {0, 1};
    std::vector<float> dist2 = {(p.cast<float>() - surfels[0].position).squaredNorm(),
                                (p.cast<float>() - surfels[1].position).squaredNorm()};
    const double inv_h = 1.0 / std::sqrt(static_cast<double>(dist2[1]));
    const BlendSums both =
        detail::blend_sums(surfels.data(), slot.data(), dist2.data(), 2, p, inv_h);
    const BlendSums first =
        detail::blend_sums(surfels.data(), slot.data(), dist2.data(), 1, p, inv_h);
    expect_near(both, first, 1e-15);
}

} // namespace
} // namespace pointform
