// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "blend_kernels.h"

#include "pointform/core/error.h"

#include <algorithm>
#include <array>
#include <cmath>

// PF_FIELD_AVX2=0 from the command line builds without the AVX2 path (tests then compare the
// baseline path with the formula only).
#if !defined(PF_FIELD_AVX2)
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define PF_FIELD_AVX2 1
#else
#define PF_FIELD_AVX2 0
#endif
#endif
#if PF_FIELD_AVX2
#include <immintrin.h>
#endif

namespace pointform::detail {

namespace {

#if defined(__GNUC__) || defined(__clang__)

/// Four doubles, one blended sample each (GCC's vector extension). The blend runs on four
/// samples at a time with the same operations in the same order, whether compiled for AVX2
/// registers or for the baseline target's (which splits them), so that both paths give the same
/// sums bit for bit; neither target has fused multiply-adds to round differently.
using Lanes = double __attribute__((vector_size(32)));
using LaneMask = long long __attribute__((vector_size(32)));
#define PF_FIELD_INLINE inline __attribute__((always_inline))

constexpr std::size_t blend_sum_count = 11;

/// The blend's terms for up to four samples, added into the lanes of `sums` (weight, value,
/// normal (3), weighted gradient (3), gradient (3)). `field[f]` holds the f-th float of the
/// samples' PackedSurfel, `distance` their distances (the roots of their squared distances)
/// and `valid` is all ones in the lanes that hold a sample (the others add zeros).
PF_FIELD_INLINE void blend_terms(const Lanes* field, const Lanes& distance, const LaneMask& valid,
                                 const Lanes* p, double inv_h, Lanes* sums)
{
    const Lanes zero = {0.0, 0.0, 0.0, 0.0};
    const Lanes one = zero + 1.0;
    const Lanes ox = p[0] - field[0];
    const Lanes oy = p[1] - field[1];
    const Lanes oz = p[2] - field[2];
    const Lanes t = distance * inv_h;
    Lanes u = one - t;
    u = (Lanes)((LaneMask)u & (u > zero)); // std::max(0.0, u): 0 < u ? u : 0
    const Lanes u3 = u * u * u;
    // Wendland's C² kernel (1 − t)⁴(4t + 1); d/dp of it with t = ‖p − s_i‖/h is
    // −20 (1 − t)³ (p − s_i)/h².
    const Lanes weight = (Lanes)((LaneMask)(u3 * u * (4.0 * t + one)) & valid);
    const Lanes slope = (Lanes)((LaneMask)((-20.0 * inv_h * inv_h) * u3) & valid);
    // The sample's frame (t1, t2, n): n = floats 4–6, t1 = floats 8–10, t2 = n × t1.
    const Lanes& nx = field[4];
    const Lanes& ny = field[5];
    const Lanes& nz = field[6];
    const Lanes& t1x = field[8];
    const Lanes& t1y = field[9];
    const Lanes& t1z = field[10];
    const Lanes t2x = ny * t1z - nz * t1y;
    const Lanes t2y = nz * t1x - nx * t1z;
    const Lanes t2z = nx * t1y - ny * t1x;
    const Lanes& a = field[7];
    const Lanes& b = field[11];
    const Lanes& c = field[12];
    const Lanes& d = field[13];
    const Lanes& e = field[14];
    const Lanes& f = field[15];
    const Lanes uu = ox * t1x + oy * t1y + oz * t1z;
    const Lanes vv = ox * t2x + oy * t2y + oz * t2z;
    const Lanes height = a + b * uu + c * vv + d * uu * uu + e * uu * vv + f * vv * vv;
    const Lanes plane = (ox * nx + oy * ny + oz * nz) - height;
    const Lanes du = b + 2.0 * d * uu + e * vv;
    const Lanes dv = c + e * uu + 2.0 * f * vv;
    sums[0] += weight;
    sums[1] += weight * plane;
    sums[2] += weight * (nx - du * t1x - dv * t2x);
    sums[3] += weight * (ny - du * t1y - dv * t2y);
    sums[4] += weight * (nz - du * t1z - dv * t2z);
    const Lanes gx = slope * ox;
    const Lanes gy = slope * oy;
    const Lanes gz = slope * oz;
    sums[5] += plane * gx;
    sums[6] += plane * gy;
    sums[7] += plane * gz;
    sums[8] += gx;
    sums[9] += gy;
    sums[10] += gz;
}

/// The lanes' totals, added the same way on both paths.
PF_FIELD_INLINE BlendSums total_of(const Lanes* sums)
{
    std::array<double, blend_sum_count> total{};
    for (std::size_t s = 0; s < blend_sum_count; ++s)
    {
        total[s] = (sums[s][0] + sums[s][1]) + (sums[s][2] + sums[s][3]);
    }
    BlendSums out;
    out.weight = total[0];
    out.value = total[1];
    out.normal = Vec3d(total[2], total[3], total[4]);
    out.weighted_gradient = Vec3d(total[5], total[6], total[7]);
    out.gradient = Vec3d(total[8], total[9], total[10]);
    return out;
}

/// The blend sums of samples `slot[0, used)` at `p`, four at a time, on the baseline target.
BlendSums blend_sums_scalar(const PackedSurfel* packed, const std::uint32_t* slot,
                            const float* dist2, std::size_t used, const Vec3d& p, double inv_h)
{
    Lanes sums[blend_sum_count]; // NOLINT(*-avoid-c-arrays): std::array drops vector attributes
    for (Lanes& sum : sums)
    {
        sum = Lanes{0.0, 0.0, 0.0, 0.0};
    }
    const Lanes query[3] = {Lanes{} + p.x(), Lanes{} + p.y(), Lanes{} + p.z()}; // NOLINT
    for (std::size_t j = 0; j < used; j += 4)
    {
        Lanes field[16]; // NOLINT(*-avoid-c-arrays)
        Lanes distance{};
        LaneMask valid{};
        for (std::size_t l = 0; l < 4; ++l)
        {
            // Lanes past the last sample repeat the first, and add nothing.
            const std::size_t at = j + l < used ? j + l : j;
            const auto* values = reinterpret_cast<const float*>(&packed[slot[at]]);
            for (std::size_t f = 0; f < 16; ++f)
            {
                field[f][l] = static_cast<double>(values[f]);
            }
            distance[l] = std::sqrt(static_cast<double>(dist2[at]));
            valid[l] = j + l < used ? -1 : 0;
        }
        blend_terms(field, distance, valid, query, inv_h, sums);
    }
    return total_of(sums);
}

#if PF_FIELD_AVX2

bool has_avx2()
{
    static const bool supported = [] {
        __builtin_cpu_init();
        return __builtin_cpu_supports("avx2") != 0;
    }();
    return supported;
}

/// blend_sums_scalar() on AVX2 registers: the same sums.
__attribute__((target("avx2"))) BlendSums blend_sums_avx2(const PackedSurfel* packed,
                                                          const std::uint32_t* slot,
                                                          const float* dist2, std::size_t used,
                                                          const Vec3d& p, double inv_h)
{
    Lanes sums[blend_sum_count]; // NOLINT(*-avoid-c-arrays)
    for (Lanes& sum : sums)
    {
        sum = Lanes{0.0, 0.0, 0.0, 0.0};
    }
    const Lanes query[3] = {Lanes{} + p.x(), Lanes{} + p.y(), Lanes{} + p.z()}; // NOLINT
    for (std::size_t j = 0; j < used; j += 4)
    {
        const std::size_t count = std::min<std::size_t>(4, used - j);
        std::array<const float*, 4> rows{};
        alignas(16) std::array<float, 4> d2{};
        for (std::size_t l = 0; l < 4; ++l)
        {
            // Lanes past the last sample repeat the first, and add nothing.
            const std::size_t at = l < count ? j + l : j;
            rows[l] = reinterpret_cast<const float*>(&packed[slot[at]]);
            d2[l] = dist2[at];
        }
        Lanes field[16]; // NOLINT(*-avoid-c-arrays)
        for (std::size_t quad = 0; quad < 4; ++quad)
        {
            __m128 r0 = _mm_loadu_ps(rows[0] + 4 * quad);
            __m128 r1 = _mm_loadu_ps(rows[1] + 4 * quad);
            __m128 r2 = _mm_loadu_ps(rows[2] + 4 * quad);
            __m128 r3 = _mm_loadu_ps(rows[3] + 4 * quad);
            _MM_TRANSPOSE4_PS(r0, r1, r2, r3);
            field[4 * quad] = _mm256_cvtps_pd(r0);
            field[4 * quad + 1] = _mm256_cvtps_pd(r1);
            field[4 * quad + 2] = _mm256_cvtps_pd(r2);
            field[4 * quad + 3] = _mm256_cvtps_pd(r3);
        }
        const Lanes distance = _mm256_sqrt_pd(_mm256_cvtps_pd(_mm_load_ps(d2.data())));
        const LaneMask valid = (LaneMask{0, 1, 2, 3} < static_cast<long long>(count));
        blend_terms(field, distance, valid, query, inv_h, sums);
    }
    return total_of(sums);
}

#endif // PF_FIELD_AVX2

#endif // __GNUC__ || __clang__

} // namespace

BlendSums blend_sums_reference(const PackedSurfel* packed, const std::uint32_t* slot,
                               const float* dist2, std::size_t used, const Vec3d& p, double inv_h)
{
    return blend_sums_of(packed, slot, dist2, used, p, inv_h,
                         [&](std::size_t j, Vec3d* gradient, double* /*factor*/) {
                             return packed[slot[j]].distance(p, gradient);
                         });
}

bool blend_has_avx2()
{
#if PF_FIELD_AVX2
    return has_avx2();
#else
    return false;
#endif
}

BlendSums blend_sums(const PackedSurfel* packed, const std::uint32_t* slot, const float* dist2,
                     std::size_t used, const Vec3d& p, double inv_h, BlendPath path)
{
#if PF_FIELD_AVX2
    if (path == BlendPath::automatic ? has_avx2() : path == BlendPath::avx2)
    {
        PF_ASSERT(has_avx2());
        return blend_sums_avx2(packed, slot, dist2, used, p, inv_h);
    }
#endif
#if defined(__GNUC__) || defined(__clang__)
    return blend_sums_scalar(packed, slot, dist2, used, p, inv_h);
#else
    return blend_sums_reference(packed, slot, dist2, used, p, inv_h);
#endif
}

} // namespace pointform::detail
