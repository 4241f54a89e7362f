// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// The guided orientation's lane loops (src/hermite/orientation_lanes.h): the SSE2 forms that run
// on x86 against the scalar forms that run elsewhere, bit for bit, and both against sums in
// double precision.

#include "orientation_lanes.h"

#include <gtest/gtest.h>

#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

namespace pointform::detail {
namespace {

/// Moments of `n` random neighbourhoods, `spread` wide. Moments are 36 bytes and 4-byte aligned,
/// so the last covariance pair of every other one is not 8-byte aligned (the load that the
/// sanitizers' build caught reading it as a double).
std::vector<Moments> random_moments(std::mt19937& rng, std::size_t n, float spread)
{
    std::uniform_real_distribution<float> coordinate(-spread, spread);
    std::uniform_real_distribution<float> variance(0.0F, spread * spread);
    std::vector<Moments> moments(n);
    for (Moments& m : moments)
    {
        for (float& c : m.centroid)
            c = coordinate(rng);
        for (float& c : m.covariance)
            c = variance(rng);
    }
    return moments;
}

std::vector<std::uint32_t> random_row(std::mt19937& rng, std::size_t size, std::size_t n)
{
    std::uniform_int_distribution<std::uint32_t> index(0, static_cast<std::uint32_t>(n - 1));
    std::vector<std::uint32_t> row(size);
    for (std::uint32_t& j : row)
        j = index(rng);
    return row;
}

template <std::size_t N>
bool same_bits(const std::array<float, N>& a, const std::array<float, N>& b)
{
    for (std::size_t e = 0; e < N; ++e)
        if (std::bit_cast<std::uint32_t>(a[e]) != std::bit_cast<std::uint32_t>(b[e]))
            return false;
    return true;
}

TEST(RingSums, MatchTheMomentsOfTheRowInDoublePrecision)
{
    std::mt19937 rng(7);
    const std::vector<Moments> moments = random_moments(rng, 500, 2.0F);
    const std::vector<std::uint32_t> row = random_row(rng, 24, moments.size());
    const std::array<float, 3> centre{0.25F, -0.5F, 1.0F};
    std::array<float, 3> sum{};
    std::array<float, 6> outer{};
    ring_sums(moments.data(), row, centre, sum, outer);
    std::array<double, 3> want_sum{};
    std::array<double, 6> want_outer{};
    for (const std::uint32_t j : row)
    {
        std::array<double, 3> d{};
        for (std::size_t e = 0; e < 3; ++e)
        {
            d[e] = static_cast<double>(moments[j].centroid[e]) - static_cast<double>(centre[e]);
            want_sum[e] += d[e];
        }
        const std::array<double, 6> product{d[0] * d[0], d[0] * d[1], d[0] * d[2],
                                            d[1] * d[1], d[1] * d[2], d[2] * d[2]};
        for (std::size_t e = 0; e < 6; ++e)
            want_outer[e] += product[e] + static_cast<double>(moments[j].covariance[e]);
    }
    for (std::size_t e = 0; e < 3; ++e)
        EXPECT_NEAR(sum[e], want_sum[e], 1e-5 * 24 * 3.0);
    for (std::size_t e = 0; e < 6; ++e)
        EXPECT_NEAR(outer[e], want_outer[e], 1e-5 * 24 * 16.0);
}

TEST(RingSums, BothFormsGiveTheSameBits)
{
#if defined(__SSE2__)
    std::mt19937 rng(11);
    for (const float spread : {1e-12F, 1e-3F, 1.0F, 1e6F, 1e15F})
    {
        const std::vector<Moments> moments = random_moments(rng, 1000, spread);
        for (const std::size_t size : {0U, 1U, 5U, 16U, 40U})
            for (int trial = 0; trial < 20; ++trial)
            {
                const std::vector<std::uint32_t> row = random_row(rng, size, moments.size());
                const std::array<float, 3> centre = moments[row.empty() ? 0 : row[0]].centroid;
                std::array<float, 3> scalar_sum{};
                std::array<float, 6> scalar_outer{};
                std::array<float, 3> vector_sum{};
                std::array<float, 6> vector_outer{};
                ring_sums_scalar(moments.data(), row, centre, scalar_sum, scalar_outer);
                ring_sums_sse2(moments.data(), row, centre, vector_sum, vector_outer);
                ASSERT_TRUE(same_bits(scalar_sum, vector_sum)) << spread << " " << size;
                ASSERT_TRUE(same_bits(scalar_outer, vector_outer)) << spread << " " << size;
            }
    }
#else
    GTEST_SKIP() << "no SSE2 form on this target";
#endif
}

/// `groups` groups of random sources on a unit sphere (outward normals, areas of a 4π / count
/// share over 4π), each padded with zero-area sources to whole lanes.
WindingSources sphere_sources(std::mt19937& rng, std::size_t count, std::size_t groups)
{
    std::normal_distribution<float> gauss;
    WindingSources s;
    for (std::size_t g = 0; g < groups; ++g)
    {
        s.begin.push_back(s.size());
        for (std::size_t k = 0; k < count / groups; ++k)
        {
            Vec3f p(gauss(rng), gauss(rng), gauss(rng));
            p.normalize();
            s.push(p, p, 1.0F / static_cast<float>(count));
        }
        while (s.size() % winding_lanes != 0)
            s.push(Vec3f::Zero(), Vec3f::UnitZ(), 0.0F);
    }
    s.begin.push_back(s.size());
    return s;
}

TEST(WindingGroupSum, IsTheWindingNumberOfASphere)
{
    std::mt19937 rng(3);
    const WindingSources s = sphere_sources(rng, 20000, 4);
    const auto winding = [&](const Vec3f& q, float excluded2) {
        double w = 0.0;
        for (std::size_t g = 0; g + 1 < s.begin.size(); ++g)
            w += winding_group_sum(s, s.begin[g], s.begin[g + 1], q, excluded2);
        return w;
    };
    EXPECT_NEAR(winding(Vec3f::Zero(), 0.0F), 1.0, 0.02);
    EXPECT_NEAR(winding(Vec3f(0.3F, -0.2F, 0.1F), 0.0F), 1.0, 0.05);
    EXPECT_NEAR(winding(Vec3f(3.0F, 0.0F, 0.0F), 0.0F), 0.0, 0.02);
    // On the surface, with the sources next to q left out: about a half.
    EXPECT_NEAR(winding(Vec3f(0.0F, 0.0F, 1.0F), 0.05F * 0.05F), 0.5, 0.05);
}

TEST(WindingGroupSum, BothFormsGiveTheSameBits)
{
#if defined(__SSE2__)
    std::mt19937 rng(5);
    const WindingSources s = sphere_sources(rng, 3001, 7);
    std::uniform_real_distribution<float> coordinate(-2.0F, 2.0F);
    for (int trial = 0; trial < 200; ++trial)
    {
        // Every tenth query sits on a source (d = 0: left out by the mask, not 0 / 0).
        const std::size_t on = static_cast<std::size_t>(trial) * 13 % s.size();
        const Vec3f q = trial % 10 == 0 ? Vec3f(s.x[on], s.y[on], s.z[on])
                                        : Vec3f(coordinate(rng), coordinate(rng), coordinate(rng));
        const float excluded2 = trial % 3 == 0 ? 0.0F : 0.01F * static_cast<float>(trial % 7);
        for (std::size_t g = 0; g + 1 < s.begin.size(); ++g)
        {
            const double scalar =
                winding_group_sum_scalar(s, s.begin[g], s.begin[g + 1], q, excluded2);
            const double vector =
                winding_group_sum_sse2(s, s.begin[g], s.begin[g + 1], q, excluded2);
            ASSERT_TRUE(std::isfinite(vector)) << trial;
            ASSERT_EQ(std::bit_cast<std::uint64_t>(scalar), std::bit_cast<std::uint64_t>(vector))
                << trial << " " << g;
        }
    }
#else
    GTEST_SKIP() << "no SSE2 form on this target";
#endif
}

} // namespace
} // namespace pointform::detail
