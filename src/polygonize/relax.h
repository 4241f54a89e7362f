// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include "pointform/core/types.h"
#include "pointform/geometry/tri_mesh.h"

#include <cstdint>
#include <span>

namespace pointform::detail {

/// Rounds of relax_tangentially() after a thin-plate fairing, the base mesh's and the finest
/// level's alike. Measured on three simulated scans of the fandisk (bench/peers/virtual_scan.py,
/// seeds 1-3), the finest level's triangles under 20° at the default: 3.03 / 4.42 / 3.30%
/// unrelaxed, 1.91 / 2.00 / 1.50% after 50 rounds.
constexpr int faired_relax_rounds = 50;

/// \brief Tangential relaxation of the `free` vertices (sorted, distinct) of a mesh: `rounds`
/// Jacobi steps in parallel blocks (the same positions whatever the thread count), each moving
/// a vertex towards the mean of its neighbours within its tangent plane (the area-weighted
/// normal of its faces); then each is put back on the surface the faces around the free
/// vertices had before (their closest point). Thin-plate fairing (thin_plate_fairing()) makes a
/// region smooth across, but where its rim is uneven (a hole's jagged edge, held vertices of
/// unequal spacing) it leaves vertices bunched along the surface, in thin triangles; this
/// spreads them out and keeps the shape. Projecting after every round instead of the last
/// measured the same shares of thin triangles for 0.3-0.7 s more on 60k-sample scans.
/// \param x  every vertex's position (only the free ones move)
/// \param faces  the mesh's triangles
/// \param ring_offsets, ring_adjacent  each vertex v's neighbours,
///        ring_adjacent[ring_offsets[v] .. ring_offsets[v + 1])
void relax_tangentially(std::span<Vec3d> x, std::span<const Triangle> faces,
                        std::span<const std::uint32_t> ring_offsets,
                        std::span<const std::uint32_t> ring_adjacent,
                        std::span<const std::uint32_t> free, int rounds);

} // namespace pointform::detail
