// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include "pointform/core/types.h"
#include "pointform/geometry/tri_mesh.h"
#include "pointform/implicit/field.h"

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>

namespace pointform::detail {

/// Rounds of relax_tangentially() after a thin-plate fairing, the base mesh's and the finest
/// level's alike. Measured on three simulated scans of the fandisk (bench/peers/virtual_scan.py,
/// seeds 1-3), the finest level's triangles under 20° at the default: 3.03 / 4.42 / 3.30%
/// unrelaxed, 1.91 / 2.00 / 1.50% after 50 rounds.
constexpr int faired_relax_rounds = 50;

/// Where relax_tangentially() moves a vertex towards: the mean of its neighbours (uniform), or
/// the centroid of its faces' centroids weighted by their areas, which evens out the faces'
/// areas. A flat fill of a region whose connectivity was made for a bulging surface (a
/// membrane, RefineOptions::fair_unsupported) has more vertices than its area needs; the
/// neighbours' mean is the membrane's own fixed point and leaves them crowded in its middle, in
/// thin triangles, where the areas' centroids spread them: on the seventh simulated fandisk
/// scan (bench/peers/virtual_scan.py), whose largest membrane has nearly all of its faces 19
/// rings in under 20°, the finest level's triangles under 20° went 2.02% -> 1.62%, and over ten
/// such scans the most 2.02% -> 1.83%. On thin plates it did not help (over twenty scans the
/// most 1.83% -> 2.82%), so they keep the neighbours' mean.
enum class RelaxTarget
{
    neighbours_mean,
    face_centroids,
};

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
                        std::span<const std::uint32_t> free, int rounds,
                        RelaxTarget target = RelaxTarget::neighbours_mean);

/// \brief How deep a region lies, in rings: the largest distance along the rings' edges,
/// walking through the region only, from a vertex outside it to one inside (1: next to one
/// outside), over the vertices v with inside[v] != 0; 0 where none has a neighbour outside.
[[nodiscard]] std::size_t depth_in_rings(std::span<const std::uint32_t> ring_offsets,
                                         std::span<const std::uint32_t> ring_adjacent,
                                         std::span<const char> inside);

/// relax_membranes() relaxes in rounds of faired_relax_rounds for as long as a round leaves
/// more than this share of the faces around the relaxed vertices under 20° (the share the
/// finest level as a whole is held to) ...
constexpr double membrane_thin_share = 0.02;
/// ... and takes that share down by at least this fraction of itself.
constexpr double membrane_round_gain = 0.1;

/// \brief relax_tangentially() with RelaxTarget::face_centroids of a flat fill (a membrane,
/// RefineOptions::fair_unsupported) `depth` rings deep (1: every free vertex next to a held
/// one): faired_relax_rounds at first, then as many more, again and again, while
/// membrane_thin_share and membrane_round_gain say so and fewer than depth² rounds are made
/// (Jacobi steps spread a crowding over about the square root of their count in rings).
///
/// A membrane's first layout is Tutte's embedding of its connectivity (each vertex at its
/// neighbours' mean), and that connectivity was made for the surface the field had there,
/// which may bulge far out of the membrane's plane: a large one's middle is crowded. On the
/// fifteenth simulated fandisk scan (bench/peers/virtual_scan.py, seed 15), whose membranes of
/// 3,796 and 1,786 vertices lie up to 16 rings deep, 4.0% of the finest level's triangles were
/// under 20° after 50 rounds, nearly all of them 10 rings or more inside; after 300 rounds
/// (18% -> 4.4% of the faces around the membranes) 1.0%, with the same F@0.5% and Chamfer to
/// the truth. Fandisk, spot and teapot scans at seeds 11-15 (4-8 for the teapot): triangles
/// under 20° 0.67% -> 0.45% on average, 4.00% -> 1.85% at most; seeds 1-10 of the fandisk and
/// spot: 0.61% -> 0.56%, 1.99% at most either way; F@0.5% and Chamfer the same to 0.0003.
/// \return the rounds made
int relax_membranes(std::span<Vec3d> x, std::span<const Triangle> faces,
                    std::span<const std::uint32_t> ring_offsets,
                    std::span<const std::uint32_t> ring_adjacent,
                    std::span<const std::uint32_t> free, std::size_t depth);

/// \brief A vertex that stands `offset` off the plane of its neighbours, put back on the field
/// from their centroid `centre` (world coordinates): the projection of the centroid along the
/// gradient there, within `reach`; nullopt unless the field at the centroid is defined and
/// within a quarter of `offset` of zero (the neighbours lie on a smooth piece of the surface;
/// at a crease the centroid lies off it as the vertex does). despike() and the base mesh's
/// shape rounds both use it.
[[nodiscard]] std::optional<Vec3d> project_from_centroid(const Field& field, const Vec3d& centre,
                                                         double offset, double reach);

/// Puts back the finest level's isolated spikes and dents: vertices that stand off their
/// neighbours' plane (spike_offset, spike_isolation) while the field at their neighbours'
/// centroid is within a quarter of that offset of zero (the neighbours lie on a smooth piece
/// of the surface; at a crease the centroid lies off it as the vertex does) go to the
/// projection of the centroid along the gradient there, Jacobi style (every test on the same
/// positions). A new vertex can land on a narrow step of the field (the blend between two local
/// fits that disagree, at a concave crease: on the clean 1M blobby of bench/peers one stood
/// 0.16% of the diagonal off the truth, the output's largest distance, where marching cubes at
/// the same count measure 0.135%; 0.124% after). Boundary vertices stay. Returns how many
/// moved.
/// \param x  every vertex's position, relative to `origin` (the field's world is origin + x)
/// \param ring_offsets, ring_adjacent  each vertex v's neighbours,
///        ring_adjacent[ring_offsets[v] .. ring_offsets[v + 1])
/// \param boundary  per vertex, nonzero on the mesh's boundary
std::size_t despike(std::span<Vec3d> x, const Vec3d& origin, const Field& field,
                    std::span<const std::uint32_t> ring_offsets,
                    std::span<const std::uint32_t> ring_adjacent,
                    std::span<const std::uint8_t> boundary);

} // namespace pointform::detail
