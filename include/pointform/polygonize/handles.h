// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include "pointform/geometry/tri_mesh.h"
#include "pointform/implicit/point_field.h"

#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

namespace pointform {

/// \brief A closed loop of mesh edges: its vertices in order (the last joins the first).
struct MeshLoop
{
    std::vector<std::uint32_t> vertices;
    double length = 0.0; ///< the sum of its edges' lengths
};

/// \brief The shortest non-separating loop of `mesh` no longer than `max_length`: a loop of edges
/// that cutting the surface along does not split it, so one that goes round a handle (the
/// meridian of a torus's tube), or nothing when the mesh has no handle or every loop round one is
/// longer. The rims of holes count as capped: a loop round a hole is not a handle.
///
/// Each vertex away from the boundary is the start of a Dijkstra search to max_length / 2; the
/// shortest loop through it is two of its shortest paths joined by an edge (Erickson and
/// Har-Peled 2004), and whether a loop separates is its class in the surface's Z/2 homology,
/// read off a tree-cotree basis (Eppstein 2003). O(V (max_length / h)² log) for edge length h.
/// \pre `mesh` is an oriented 2-manifold (analyze_topology().is_oriented_manifold())
/// \return an empty loop (no vertices) when there is none
[[nodiscard]] MeshLoop shortest_handle_loop(const TriMesh& mesh, double max_length);

/// \brief What cut_short_handles() did.
struct HandleCutReport
{
    std::size_t genus_before = 0; ///< handles of the mesh before (summed over its components)
    std::size_t genus_after = 0;  ///< and after
    std::size_t cuts = 0;         ///< loops cut (each removes one handle)
    double longest_cut = 0.0;     ///< the length of the longest loop cut
    std::vector<double> lengths;  ///< every cut loop's length, in the order cut
    /// Rounds that cut (each cuts up to 64 independent loops, then the basis is made again); at
    /// most 16, so at most 1,024 cuts, after which genus_after counts the handles left.
    std::size_t rounds = 0;
    /// The mesh was not an oriented 2-manifold, and nothing was cut.
    bool skipped_not_manifold = false;
    double max_length = 0.0; ///< the longest loop that could be cut
};

/// \brief Topological noise removal (Guskov and Wood 2001): cuts `mesh` along its short
/// non-separating loops, shortest first, and caps both sides with a fan (a vertex at the loop's
/// centroid, moved a tenth of the loop's mean radius to its own side), until no handle has a
/// loop round it of at most `max_length`. Handles are tunnels and bridges far smaller than the
/// shape: where fits of two sheets meet past their samples (a sharp rim under noise, a step of
/// a scan) the field's zero set joins them with a tube that a surface of the scanned object does
/// not have. Loops through boundary vertices are not cut. The searches run in parallel; the
/// result is the same whatever the thread count.
/// A mesh that is not an oriented 2-manifold is left as it is (HandleCutReport::
/// skipped_not_manifold).
HandleCutReport cut_short_handles(TriMesh& mesh, double max_length);

/// \brief The handles of `mesh` (summed over its components) where it is a sponge, 0 where it
/// is not: at least 64 handles, and one for every 500 vertices or fewer. A point field whose
/// fits follow the noise of dense noisy samples makes one (PointFieldOptions::noise_scale): the
/// noisy 1M thin plate of bench/peers (its faces 3.4 noise deviations apart) made genus 7,355
/// in 150,038 vertices (one handle per 20), while the noisy inputs of bench/peers at 100k and
/// 1M and the simulated scans made at most 16. A surface with many real handles (a grille, a
/// perforated sheet) has several hundred vertices a handle, and is not taken for one.
[[nodiscard]] std::size_t sponge_genus(const TriMesh& mesh);

/// \brief Where a sponge's handles are: the cells of a grid of 8 influence radii (`radius`; world
/// coordinates) whose
/// vertices' angle defects (2π less the angles round an interior vertex; discrete Gauss-Bonnet:
/// they add up to 2π χ) add up to -8π or less, two handles' worth, and the cells round them
/// (one cell each way). A smooth sheet's cell adds up to about its integral of Gaussian
/// curvature, a small part of 4π for cells of a few influence radii.
[[nodiscard]] NoiseScaleRegion spongy_cells(const TriMesh& mesh, double radius);

/// \brief A field to make again (SpongeRefit::options) where marching cubes of `field` made
/// `mesh` a sponge (SpongeRefit::genus, sponge_genus()): `field`'s options with
/// PointFieldOptions::noise_scale on in the spongy_cells() of `mesh`. Nullopt where `field` is
/// not a noisy cloud's quadric field or `mesh` is no sponge. What reconstruct() and `pointform
/// mc` do with their marching-cubes mesh.
struct SpongeRefit
{
    std::size_t genus = 0;
    PointFieldOptions options;
};
[[nodiscard]] std::optional<SpongeRefit> sponge_refit(const PointField& field, const TriMesh& mesh);

} // namespace pointform
