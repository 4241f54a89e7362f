// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/spatial/spatial_sort.h"

#include "pointform/core/parallel.h"
#include "pointform/geometry/aabb.h"

#include <algorithm>
#include <cmath>

namespace pointform {
namespace {

/// Spreads the low 21 bits of x so that there are two zero bits between each.
std::uint64_t spread_bits(std::uint64_t x)
{
    x &= 0x1FFFFFU;
    x = (x | x << 32U) & 0x1F00000000FFFFULL;
    x = (x | x << 16U) & 0x1F0000FF0000FFULL;
    x = (x | x << 8U) & 0x100F00F00F00F00FULL;
    x = (x | x << 4U) & 0x10C30C30C30C30C3ULL;
    x = (x | x << 2U) & 0x1249249249249249ULL;
    return x;
}

} // namespace

std::vector<std::uint32_t> spatial_order(std::span<const Vec3f> positions)
{
    const Aabb box = bounding_box(positions);
    // (Morton key, index) pairs: sorting them orders by key, ties by original index.
    std::vector<std::pair<std::uint64_t, std::uint32_t>> keyed(positions.size());
    std::vector<std::uint32_t> order(positions.size());
    if (positions.empty())
        return order;
    const Vec3d extent = box.size();
    const double largest = std::max({extent.x(), extent.y(), extent.z()});
    const double scale = largest > 0.0 ? static_cast<double>((1U << 21U) - 1U) / largest : 0.0;
    parallel_blocks(positions.size(), 16384, [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i)
        {
            const Vec3d q = (positions[i].cast<double>() - box.min) * scale;
            // Non-finite coordinates (rejected elsewhere) must not poison the casts.
            const auto cell = [](double v) {
                return std::isfinite(v) ? static_cast<std::uint64_t>(
                                              std::clamp(v, 0.0, static_cast<double>(0x1FFFFF)))
                                        : std::uint64_t{0};
            };
            keyed[i] = {spread_bits(cell(q.x())) | spread_bits(cell(q.y())) << 1U |
                            spread_bits(cell(q.z())) << 2U,
                        static_cast<std::uint32_t>(i)};
        }
    });
    parallel_sort(keyed); // keys paired with their index: a strict order, std::sort's result
    for (std::size_t j = 0; j < keyed.size(); ++j)
        order[j] = keyed[j].second;
    return order;
}

} // namespace pointform
