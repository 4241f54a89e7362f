// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

// The guided orientation's two inner loops written for SIMD lanes (orientation.cpp): each has a
// scalar form and, where SSE2 is there, a vector form that adds every term in the same order,
// so the two give the same bits and `normals` the same bytes whichever form runs. Both forms are
// compiled on x86 so that orientation_lanes_test can hold them to that; only the vector one runs
// there. (A compiler that fuses multiplies and adds, say with -march=native or on ARM, rounds
// the scalar form differently: the promise is per build, like the thread count's.)

#include "pointform/core/types.h"

#if defined(__SSE2__)
#include <immintrin.h>
#endif

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <type_traits>
#include <vector>

namespace pointform::detail {

/// A neighbourhood's centroid and covariance (upper triangle: xx xy xz yy yz zz), in float: the
/// guide needs a direction, not digits.
struct Moments
{
    std::array<float, 3> centroid;
    std::array<float, 6> covariance;
};

/// Adds d = (x, y, z) to the sums of d and of d dᵀ (upper triangle: xx xy xz yy yz zz).
inline void add_moment(std::array<float, 3>& sum, std::array<float, 6>& outer, float x, float y,
                       float z)
{
    sum[0] += x;
    sum[1] += y;
    sum[2] += z;
    outer[0] += x * x;
    outer[1] += x * y;
    outer[2] += x * z;
    outer[3] += y * y;
    outer[4] += y * z;
    outer[5] += z * z;
}

/// One ring's sums of a sample from its neighbours' moments (guide_normals() in
/// orientation.cpp): `sum` gets Σ d and `outer` Σ d dᵀ + Σ C (upper triangle), d each neighbour's
/// centroid less `centre` and C its covariance, over the neighbours `row` (indices into
/// `moments`). Each entry is added up in the row's order, and the covariances apart from the
/// products.
inline void ring_sums_scalar(const Moments* moments, std::span<const std::uint32_t> row,
                             const std::array<float, 3>& centre, std::array<float, 3>& sum,
                             std::array<float, 6>& outer)
{
    std::array<float, 3> d_sum{};
    std::array<float, 6> products{};
    std::array<float, 6> within{};
    for (const std::uint32_t j : row)
    {
        const Moments& m = moments[j];
        add_moment(d_sum, products, m.centroid[0] - centre[0], m.centroid[1] - centre[1],
                   m.centroid[2] - centre[2]);
        for (std::size_t e = 0; e < 6; ++e)
            within[e] += m.covariance[e];
    }
    sum = d_sum;
    for (std::size_t e = 0; e < 6; ++e)
        outer[e] = products[e] + within[e];
}

#if defined(__SSE2__)
/// ring_sums_scalar() in SSE2 lanes: the same bits (the scalar loop spilled its fifteen sums to
/// the stack; 1M noisy sphere's `normals` 6% faster).
inline void ring_sums_sse2(const Moments* moments, std::span<const std::uint32_t> row,
                           const std::array<float, 3>& centre, std::array<float, 3>& sum,
                           std::array<float, 6>& outer)
{
    static_assert(sizeof(Moments) == 9 * sizeof(float) && std::is_standard_layout_v<Moments>);
    // Lanes: d = (x, y, z, -), products (xx, xy, xz, yy) and (yz, zz, -, -), covariance entries
    // 0-3 and 4-5: the last lanes of d and of the second products are never read.
    const __m128 c = _mm_setr_ps(centre[0], centre[1], centre[2], 0.0F);
    __m128 d_sum = _mm_setzero_ps();
    __m128 products_low = _mm_setzero_ps();
    __m128 products_high = _mm_setzero_ps();
    __m128 within_low = _mm_setzero_ps();
    __m128 within_high = _mm_setzero_ps();
    for (const std::uint32_t j : row)
    {
        const auto* m = reinterpret_cast<const float*>(moments + j);
        const __m128 d = _mm_sub_ps(_mm_loadu_ps(m), c);
        d_sum = _mm_add_ps(d_sum, d);
        products_low =
            _mm_add_ps(products_low, _mm_mul_ps(_mm_shuffle_ps(d, d, _MM_SHUFFLE(1, 0, 0, 0)),
                                                _mm_shuffle_ps(d, d, _MM_SHUFFLE(1, 2, 1, 0))));
        products_high =
            _mm_add_ps(products_high, _mm_mul_ps(_mm_shuffle_ps(d, d, _MM_SHUFFLE(2, 2, 2, 1)),
                                                 _mm_shuffle_ps(d, d, _MM_SHUFFLE(2, 2, 2, 2))));
        within_low = _mm_add_ps(within_low, _mm_loadu_ps(m + 3));
        // m + 7 is only 4-byte aligned: _mm_loadu_si64 reads the pair through an unaligned type.
        within_high = _mm_add_ps(within_high, _mm_castsi128_ps(_mm_loadu_si64(m + 7)));
    }
    std::array<float, 4> lanes{};
    _mm_storeu_ps(lanes.data(), d_sum);
    std::copy_n(lanes.begin(), 3, sum.begin());
    _mm_storeu_ps(lanes.data(), _mm_add_ps(products_low, within_low));
    std::copy_n(lanes.begin(), 4, outer.begin());
    _mm_storeu_ps(lanes.data(), _mm_add_ps(products_high, within_high));
    std::copy_n(lanes.begin(), 2, outer.begin() + 4);
}
#endif

/// ring_sums_scalar(), in SSE2 lanes where there are any.
inline void ring_sums(const Moments* moments, std::span<const std::uint32_t> row,
                      const std::array<float, 3>& centre, std::array<float, 3>& sum,
                      std::array<float, 6>& outer)
{
#if defined(__SSE2__)
    ring_sums_sse2(moments, row, centre, sum, outer);
#else
    ring_sums_scalar(moments, row, centre, sum, outer);
#endif
}

/// The winding check's sums run in this many float lanes (turn_regions_by_winding() in
/// orientation.cpp): each lane adds every winding_lanes-th term of a group, then the lanes are
/// added in a fixed order, so a sum is the same bits with or without vector instructions and on
/// any thread count.
inline constexpr std::size_t winding_lanes = 8;

/// The winding check's sources, as float columns in groups padded to whole lanes: positions
/// relative to `origin` times `scale`, unit normals, and each source's area over 4π in the
/// scaled units.
struct WindingSources
{
    Vec3f origin = Vec3f::Zero();
    float scale = 1.0F;
    std::vector<float> x, y, z, nx, ny, nz, area;
    /// Where each group starts, and the end.
    std::vector<std::size_t> begin;

    [[nodiscard]] std::size_t size() const { return x.size(); }
    [[nodiscard]] Vec3f local(const Vec3f& p) const { return (p - origin) * scale; }
    void push(const Vec3f& p, const Vec3f& n, float a)
    {
        x.push_back(p.x());
        y.push_back(p.y());
        z.push_back(p.z());
        nx.push_back(n.x());
        ny.push_back(n.y());
        nz.push_back(n.z());
        area.push_back(a);
    }
};

/// The lanes' sum, added in lane order.
inline double add_lanes(const std::array<float, winding_lanes>& lane)
{
    double total = 0.0;
    for (const float v : lane)
        total += static_cast<double>(v);
    return total;
}

/// Σ area · n·d / |d|³ (d from q to the source) over the sources [from, to) farther than
/// sqrt(excluded2) from q, in winding_lanes lanes. \pre to − from a whole number of lanes
inline double winding_group_sum_scalar(const WindingSources& s, std::size_t from, std::size_t to,
                                       const Vec3f& q, float excluded2)
{
    std::array<float, winding_lanes> lane{};
    for (std::size_t b = from; b < to; b += winding_lanes)
        for (std::size_t l = 0; l < winding_lanes; ++l)
        {
            const std::size_t i = b + l;
            const float dx = s.x[i] - q.x();
            const float dy = s.y[i] - q.y();
            const float dz = s.z[i] - q.z();
            const float d2 = (dx * dx + dy * dy) + dz * dz;
            const float flux = (s.nx[i] * dx + s.ny[i] * dy) + s.nz[i] * dz;
            const float term = s.area[i] * flux / (d2 * std::sqrt(d2));
            lane[l] += d2 > excluded2 ? term : 0.0F;
        }
    return add_lanes(lane);
}

#if defined(__SSE2__)
/// winding_group_sum_scalar() in two SSE2 registers of four lanes: the same bits (fandisk scan
/// 2: the sums' share of `normals` CPU 18% -> 3%).
inline double winding_group_sum_sse2(const WindingSources& s, std::size_t from, std::size_t to,
                                     const Vec3f& q, float excluded2)
{
    static_assert(winding_lanes == 8);
    const __m128 qx = _mm_set1_ps(q.x());
    const __m128 qy = _mm_set1_ps(q.y());
    const __m128 qz = _mm_set1_ps(q.z());
    const __m128 limit = _mm_set1_ps(excluded2);
    __m128 sum[2] = {_mm_setzero_ps(), _mm_setzero_ps()};
    for (std::size_t b = from; b < to; b += winding_lanes)
        for (std::size_t h = 0; h < 2; ++h)
        {
            const std::size_t i = b + 4 * h;
            const __m128 dx = _mm_sub_ps(_mm_loadu_ps(&s.x[i]), qx);
            const __m128 dy = _mm_sub_ps(_mm_loadu_ps(&s.y[i]), qy);
            const __m128 dz = _mm_sub_ps(_mm_loadu_ps(&s.z[i]), qz);
            const __m128 d2 =
                _mm_add_ps(_mm_add_ps(_mm_mul_ps(dx, dx), _mm_mul_ps(dy, dy)), _mm_mul_ps(dz, dz));
            const __m128 flux = _mm_add_ps(_mm_add_ps(_mm_mul_ps(_mm_loadu_ps(&s.nx[i]), dx),
                                                      _mm_mul_ps(_mm_loadu_ps(&s.ny[i]), dy)),
                                           _mm_mul_ps(_mm_loadu_ps(&s.nz[i]), dz));
            const __m128 term = _mm_div_ps(_mm_mul_ps(_mm_loadu_ps(&s.area[i]), flux),
                                           _mm_mul_ps(d2, _mm_sqrt_ps(d2)));
            // The mask also drops what a source at q itself makes of 0 / 0.
            sum[h] = _mm_add_ps(sum[h], _mm_and_ps(_mm_cmpgt_ps(d2, limit), term));
        }
    std::array<float, winding_lanes> lane{};
    _mm_storeu_ps(lane.data(), sum[0]);
    _mm_storeu_ps(lane.data() + 4, sum[1]);
    return add_lanes(lane);
}
#endif

/// winding_group_sum_scalar(), in SSE2 lanes where there are any.
inline double winding_group_sum(const WindingSources& s, std::size_t from, std::size_t to,
                                const Vec3f& q, float excluded2)
{
#if defined(__SSE2__)
    return winding_group_sum_sse2(s, from, to, q, excluded2);
#else
    return winding_group_sum_scalar(s, from, to, q, excluded2);
#endif
}

} // namespace pointform::detail
