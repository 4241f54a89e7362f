// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include "pointform/core/progress.h"
#include "pointform/geometry/mesh_topology.h"
#include "pointform/geometry/tri_mesh.h"
#include "pointform/implicit/field.h"

#include <algorithm>
#include <cstddef>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace pointform {

/// \brief Options of build_base_mesh().
struct BaseMeshOptions
{
    /// Faces of the base mesh, >= 1; unset = default_base_faces(intermediate). The result stays
    /// above the target where no collapse is left that keeps the topology and the normal bound.
    std::optional<std::size_t> target_faces;
    /// A collapse is refused when it turns any remaining face's normal by more than this,
    /// degrees, in [1, 180) (OpenMesh's ModNormalFlippingT): no fold-overs.
    double max_normal_deviation_degrees = 45.0;
    /// How far, world units, the base mesh's boundary may pass from a rim vertex of the
    /// intermediate mesh that decimation removes, on the mesh's side (where the hole would
    /// grow); on the hole's side four times as far (a chord that shrinks the hole by a flat
    /// piece). Unset = half the median edge length of the intermediate mesh (half a
    /// marching-cubes cell: the precision of the marching-cubes rim itself); must be finite and
    /// >= 0. Measured on a 100k-sample sphere with 8 holes and 0.2% noise, refined to level 3:
    /// the largest distance from the true sphere to the mesh went from 0.0855 to 0.0776 (marching
    /// cubes at the same vertex count: 0.0791), the triangles under 20° from 0.15% to 0.37%.
    std::optional<double> boundary_tolerance;
    /// Triangle-shape target, degrees, in [0, 60): after decimation, rounds of shape improvement
    /// (edge flips that raise the minimum angle, then a tangential umbrella relaxation of every
    /// interior vertex and a relaxation of every boundary vertex along its loop, then the
    /// projection of every vertex onto f = 0) go on, at least two, until no triangle away from
    /// the boundary has a smaller angle, max_smoothing_rounds is reached, or (when
    /// min_round_gain is set) a round removes less than that share of those left. Triangles at
    /// a small boundary loop (a hole narrower than the base edges) cannot all meet it.
    double min_angle_degrees = 30.0;
    /// Cap on the shape rounds; 0 = none (no flips, no relaxation: the decimated marching-cubes
    /// vertices are only projected).
    int max_smoothing_rounds = 8;
    /// The shape rounds stop (after two) once a round leaves at least 1 − min_round_gain of the
    /// triangles under min_angle_degrees that it found, in [0, 1); 0 = they run to
    /// max_smoothing_rounds unless none is left. The counts flatten after four or five rounds
    /// (1M noisy sphere: 4,133, 1,381, 961, 784, 754, 715, 675; noisy thin plate: 4,945, 1,749,
    /// 1,302, 1,132, 1,062, 1,014, 967; clean blobby: 716, 197, 94, 87, 75, 70, 69 of 75k
    /// faces), each round a field projection of every vertex (0.3-0.4 s at 1M), but the last
    /// rounds still even out creases: 0.1 stops the 1M noisy sphere and plate after 5 rounds
    /// and the clean blobby after 4 (about 2 s of 20 at 1M), and doubles the output's triangles
    /// under 20° on the clean part and plate of bench/peers at 100k (0.53% -> 1.00%, 0.62% ->
    /// 1.22%), so the default waits. Until the thirty-seventh session 0 still stopped at the
    /// first round that removed none, which a count going up by one can trigger: on simulated
    /// fandisk scans (bench/peers/virtual_scan.py, seeds 3 and 4), whose counts still fell by
    /// 3-10% a round at the eighth, that stop came after 6 and 5 rounds, with 1.51% and 1.02% of
    /// the output's triangles under 20°; 8 rounds give 0.99% and 0.86%.
    double min_round_gain = 0.0;
    /// Flips only between triangles whose normals differ by at most this, degrees, in [0, 90):
    /// a flip must not cut across a crease.
    double max_flip_dihedral_degrees = 40.0;
    /// After the shape rounds, split at most this share of the faces' count of the longest edges
    /// where the surface curves, in [0, 0.5]; 0 = none. Quadric-error decimation leaves
    /// triangles long along a direction where the surface is flat (a torus's top and bottom
    /// circles, where its normal curvature along the circle is 0: base edges twice the median
    /// length there), and refinement's 1-to-4 splits keep those proportions, so the chords of
    /// those faces set the largest distance of the finest level from the surface. An edge is
    /// split at its midpoint projected onto f = 0 when it is longer than 1.5 times the median
    /// edge, its faces meet at under 10° (not a crease) and one of them has its centroid more
    /// than twice as far off f = 0 as the median face, the farthest first; a split whose new
    /// triangles would get an angle under 20° (or under the two faces' own smallest) or turn
    /// over is skipped. Measured on the 100k clean inputs of bench/peers at two seeds (largest
    /// distance to the truth, % of the diagonal): torus 0.0090 -> 0.0065 and 0.0092 -> 0.0073,
    /// sphere 0.0028 -> 0.0024 and 0.0026 -> 0.0023; Chamfer of the clean part 11-13% lower;
    /// the noisy inputs (which stop at level 1) within 0.6%. The face count grows by two per split.
    double chord_split_share = 0.05;
    /// Holes filled: a boundary loop of the decimated mesh is closed by a patch (rings of
    /// triangles at the loop's edge length, its inner vertices faired to the smoothest surface
    /// that continues the mesh around the rim: thin-plate fairing, Σ ‖L x‖² least over the patch
    /// and its rim with L the uniform Laplacian, so the patch meets the rim with the slope of
    /// the ring outside it and follows the curvature around the hole; a membrane, each vertex
    /// the mean of its neighbours, would lie flat across it: 0.034 off a unit sphere over holes
    /// of radius 0.28, against 0.010, tests/polygonize/hole_fill_test.cpp) when the area its
    /// rim encloses (the loop's vector area) is at most this fraction of its component's
    /// surface area and the fan of triangles from the rim's centroid at most twice that (a rim
    /// that turns round the object has a small vector area and a large fan), in [0, 1); 0 = no
    /// hole filled. Scans leave holes where the
    /// scanner saw nothing (occlusion, dark or shiny spots, the side an object stood on); the
    /// default closes those, as the peers' Poisson does, but not the rim of a partial scan (a
    /// single range image, a terrain), whose loop encloses about as much as the surface
    /// itself. Filled vertices take the field's zero set where it is defined (near the rim) and
    /// stay on the faired patch where it is not (the point field ends soon after a rim:
    /// PointFieldOptions::rim_reach). reconstruct() fills by default
    /// (ReconstructOptions::fill_holes); remeshing keeps the input's holes.
    double fill_holes = 0.0;
    /// Move every vertex onto f = 0 along the field gradient (§5.1 criterion 2); false keeps the
    /// decimated marching-cubes positions (and skips the relaxation, which needs projection).
    bool project = true;
    /// Intermediate meshes of at least this many faces (and at least four times the target)
    /// are first decimated in decimation_blocks blocks at once, each block's shared vertices
    /// locked, down to block_decimation_faces_left(), then as a whole (which coarsens the faces
    /// at the blocks' cuts and places the last collapses by the whole mesh's quadric error); 0 =
    /// always as a whole. The default takes clouds from about 20k samples up in blocks.
    std::size_t block_decimation_faces = 32768;
    /// Optional progress report (stages "base mesh: decimate in blocks", "base mesh: decimate",
    /// "base mesh: shape and projection").
    ProgressCallback progress;
};

/// \brief What build_base_mesh() did.
struct BaseMeshStats
{
    std::size_t input_faces = 0;      ///< faces of the intermediate mesh
    bool decimated_in_blocks = false; ///< BaseMeshOptions::block_decimation_faces applied
    std::size_t target_faces = 0;     ///< the target actually used (options or default)
    std::size_t faces = 0;            ///< faces of the base mesh
    std::size_t vertices = 0;         ///< vertices of the base mesh
    int smoothing_rounds = 0;         ///< shape rounds done
    std::size_t flips = 0;            ///< edge flips made to improve triangle shape
    std::size_t chord_splits = 0;     ///< long edges split (BaseMeshOptions::chord_split_share)
    double boundary_tolerance = 0.0;  ///< the boundary tolerance used (options or default)
    /// Vertices left off f = 0: no zero crossing within their mean edge length along the
    /// gradient (or the normal), the field undefined there, or a move that would fold a face.
    std::size_t unprojected = 0;
    double max_vertex_move = 0.0;        ///< farthest a vertex moved after decimation, world units
    double min_angle_degrees = 0.0;      ///< smallest angle of any triangle of the base mesh
    double mean_min_angle_degrees = 0.0; ///< mean over triangles of their smallest angle
    double share_below_20_degrees = 0.0; ///< fraction of triangles with a min angle below 20°
    /// The same among triangles with no vertex on the boundary (holes force thin triangles).
    double share_below_20_degrees_off_boundary = 0.0;
    /// Holes filled (BaseMeshOptions::fill_holes): loops closed, vertices added, and the area of
    /// the patches over the base mesh's.
    std::size_t holes_filled = 0;
    std::size_t hole_vertices = 0;
    double hole_area_share = 0.0;
    MeshTopology topology_before; ///< of the intermediate mesh
    MeshTopology topology_after;  ///< of the base mesh
    /// Same Euler characteristic, boundary loops and components as the intermediate mesh (each
    /// filled hole counted: one loop fewer, χ one higher), and an oriented manifold.
    bool topology_kept = false;
    /// Empty when topology_kept; otherwise what changed, in words, for the caller to print.
    std::string topology_change;
    double seconds = 0.0; ///< wall-clock time of build_base_mesh
};

/// \brief A base mesh and its report.
struct BaseMeshResult
{
    TriMesh mesh; ///< same origin as the intermediate mesh; no vertex attributes
    BaseMeshStats stats;
};

/// Blocks of a large intermediate mesh decimated at once (BaseMeshOptions::block_decimation_faces):
/// a fixed number, so that the base mesh does not depend on the thread count.
inline constexpr std::size_t decimation_blocks = 8;

/// \brief The faces the blocks of BaseMeshOptions::block_decimation_faces leave, besides those
/// at their cuts, for the pass over the whole mesh to take to `target`: three times the target,
/// but at most 32768 more than it (the whole pass is serial). Blocks that went all the way to
/// their share of the target spread the base mesh's faces evenly over the blocks; the whole
/// pass's last collapses put them where the shape needs them (on 100k-sample shapes of
/// bench/peers, clean and noisy, two seeds: Hausdorff to the truth 3% above decimating as a
/// whole when the blocks went all the way, 3% below with three times the target left, Chamfer
/// within 0.5% either way; the 1M blobby's base mesh takes 1 s more with 3× left than 1×).
[[nodiscard]] constexpr std::size_t block_decimation_faces_left(std::size_t target)
{
    return std::min(3 * target, target + 32768);
}

/// Intermediate faces per base face by default (default_base_faces()).
inline constexpr std::size_t default_base_share = 16;
/// The most faces of a default base mesh (default_base_faces()).
inline constexpr std::size_t max_default_base_faces = 80000;

/// \brief The default base-face target for an intermediate mesh: its face count over `share`
/// (by default 4²: two 1-to-4 refinement levels bring the semi-regular mesh back to the
/// intermediate mesh's resolution), clamped to [max(8·components, 200), max_default_base_faces]
/// and to the mesh's own face count. \pre share >= 1
/// Measured on the sampled bunny (121.8k marching-cubes faces), distance from the samples to M⁰
/// in % of the bounding-box diagonal, mean (max): faces/16 → 0.06 (0.96), faces/64 → 0.18
/// (2.3), faces/256 → 0.61 (8.8); /256 reduces the ears to a few triangles. With a vertex
/// budget (fit_base_faces_to_budget()) the finest level has about as many vertices either way,
/// one level shallower from /16 than from /64; on the default inputs of bench/peers (100k
/// samples, clean and noisy with holes, and the shipped bunny scan) /16 is as accurate or more
/// on every input (Chamfer to the truth: bunny 0.084% → 0.068% of the diagonal, the clean
/// blobby 0.0076% → 0.0072%, Hausdorff 0.32% → 0.25%; its ears were cut, and the shape
/// rounds' tangential relaxation of a coarse base slides vertices off thin tips), and has fewer
/// thin triangles (noisy thin plate 2.6% → 0.4% under 20°), for 0.1–0.3 s more at 100k and
/// 0.8 s at 1M. An intermediate mesh made on a grid coarser than the field's by `coarsening`
/// (intermediate_grid()) counts as coarsening² times its faces.
[[nodiscard]] std::size_t default_base_faces(const TriMesh& intermediate,
                                             std::size_t share = default_base_share,
                                             double coarsening = 1.0);

/// \brief default_base_faces() of an intermediate mesh of `faces` faces in `components`
/// connected pieces (for one not built yet, from an estimate of its faces).
[[nodiscard]] std::size_t default_base_faces(std::size_t faces, std::size_t components,
                                             std::size_t share = default_base_share,
                                             double coarsening = 1.0);

/// The share of a vertex budget that a base mesh's refinement levels are planned to reach
/// (fit_base_faces_to_budget()).
inline constexpr double default_budget_fill = 0.6;

/// How far fit_base_faces_to_budget() leans toward the smaller base mesh, in levels (log₄ of
/// the base faces): J = ⌈log₄(2·fill·budget / target) − bias⌉, so that the fitted base has
/// between 4^−(1−bias) and 4^bias times the target's faces (between 0.35 and 1.41 of it) where
/// the nearest level would take between 0.5 and 2. The two errors do not cost the same: a base
/// mesh twice as large doubles the marching cubes of the intermediate mesh and its decimation
/// (the intermediate has intermediate_faces_per_base_face times the base's faces, and the two
/// are most of a scan's time), where one more refinement level over a smaller base costs a
/// fraction of that and lands at the same vertex budget.
inline constexpr double smaller_base_bias = 0.25;

/// \brief Moves a base-face target by at most a factor of 2.83 down or 1.41 up so that some
/// refinement level of it has about `fill` of a vertex budget: the level J of
/// smaller_base_bias, and F0 = 2·fill·budget / 4^J (a closed mesh of F faces has about F / 2
/// vertices). With a
/// budget on the finest level's vertices (StopRule::Automatic), the deepest level that fits
/// then has between fill and 4·fill of the budget, whatever the base mesh's own estimate; a
/// target that alone would exceed the budget is returned as it is.
/// \pre 0 < fill <= 1
[[nodiscard]] std::size_t fit_base_faces_to_budget(std::size_t target, std::size_t vertex_budget,
                                                   double fill = default_budget_fill);

/// Most triangles around one vertex that build_base_mesh() takes. The decimation re-ranks every
/// collapse around a vertex whenever its neighbourhood changes, and each test walks the vertex's
/// one-ring (OpenMesh), so a vertex of valence d costs O(d³). Measured on a flat polygon
/// fan-triangulated from one vertex (release build): valence 1000 takes 2.1 s to decimate,
/// valence 3000 takes 49 s.
inline constexpr std::size_t max_intermediate_valence = 1000;

/// \brief Checks that build_base_mesh() can take `intermediate`: at least one face, an oriented
/// 2-manifold without degenerate faces, no vertex in more than max_intermediate_valence
/// triangles. O(F log F) whatever the valences.
/// \return its topology
/// \throw InvalidInput saying what is wrong (for a valence too high: the vertex, its triangle
///        count and the limit)
MeshTopology check_intermediate_mesh(const TriMesh& intermediate);

/// \brief Automatic base mesh M⁰ (§5.1, Fig. 5): the intermediate (marching-cubes) mesh
/// simplified by topology-safe edge collapses to a target face count, its triangles shaped, and
/// every vertex moved onto f = 0.
///
/// 1. Collapses in the order of OpenMesh's Decimater (the same collapses, by a loop of our own
///    on its heap and halfedge mesh): priority by quadric error, refused when they break the
///    link condition (so genus, components and boundary loops stay) or turn a face by more than
///    max_normal_deviation_degrees. A collapse
///    keeps the surviving vertex's position. Boundary loops (holes in the samples) are kept: a
///    boundary vertex only collapses along its boundary, a loop never shrinks below three
///    edges, and the boundary stays within boundary_tolerance of the removed rim vertices (so
///    holes do not grow).
/// 2. Shape rounds (see BaseMeshOptions::min_angle_degrees): flips, tangential relaxation and
///    projection. Measured on the sampled bunny at its default target: 24% of the triangles
///    have a minimum angle under 20° after decimation alone, 0.6% after the rounds (0.05% away
///    from its holes). A minimum-angle test inside the decimation instead was measured worse
///    (the collapses stall) and three times slower.
/// 3. Projection searches the segment along the normalised field gradient (the vertex normal
///    where the gradient is undefined), within the vertex's mean edge length
///    (project_to_zero); a vertex with no crossing keeps its position and is counted; a move
///    that would fold a face is undone.
///
/// Orientation is the intermediate mesh's (outwards for marching_cubes); no collapse, flip or
/// move makes a triangle of zero area. The topology before and after is compared and reported,
/// never thrown. Deterministic: the same input gives the same mesh whatever the thread count.
/// \param intermediate  an oriented 2-manifold mesh (with or without boundary), e.g.
///                      marching_cubes(field, ...).mesh
/// \throw InvalidInput if check_intermediate_mesh() refuses the intermediate mesh, if the target is
/// 0 or larger than its face count, or if an option is
///        out of range
/// \throw Cancelled if the progress callback asks to stop
[[nodiscard]] BaseMeshResult build_base_mesh(const TriMesh& intermediate, const Field& field,
                                             const BaseMeshOptions& options = {});

/// \brief What fill_mesh_holes() did.
struct HoleFillStats
{
    std::size_t holes_filled = 0;  ///< boundary loops closed
    std::size_t hole_vertices = 0; ///< vertices added
    double hole_area_share = 0.0;  ///< the patches' area (their rims' vector areas) over the mesh's
    /// The mesh is not an oriented 2-manifold, so no hole was filled.
    bool skipped_not_manifold = false;
};

/// \brief Closes the holes of a mesh as the base mesh's are (BaseMeshOptions::fill_holes): each
/// boundary loop whose rim encloses at most `max_share` of its component's area gets a patch of
/// rings at the loop's edge length, faired to the smoothest surface that continues the mesh
/// around it (thin-plate fairing, the rest of the mesh held). Loops that pinch, share a vertex
/// with another loop, or have more than 1000 edges stay open. The mesh keeps its vertices and
/// triangles in place; the patches' vertices and triangles follow them, with normals from
/// their faces and colours and radii spread from the rim. A mesh that is not an oriented
/// 2-manifold is left as it is (reported). For a marching-cubes mesh of a scan, whose field
/// ends soon after the rims of the holes where the scanner saw nothing (PointFieldOptions::
/// rim_reach), this closes them as the peers' Poisson reconstruction does.
/// \throw InvalidInput for max_share outside [0, 1)
HoleFillStats fill_mesh_holes(TriMesh& mesh, double max_share);

/// \brief A base mesh picked by a user over sample indices (§5.1, Fig. 6).
struct PickedBaseMesh
{
    /// Vertices are the picked samples' positions (in the samples' origin), in order of first
    /// use; triangles consistently oriented, each component facing outwards (along ∇f).
    TriMesh mesh;
    std::vector<PointId> samples;     ///< the sample index of every vertex
    std::size_t reoriented_faces = 0; ///< triangles whose vertex order was reversed
    double max_snap_distance = 0.0;   ///< OBJ input: farthest vertex from its sample (world)
    MeshTopology topology;
};

/// \brief Builds and validates a base mesh from triangles over sample indices.
///
/// Triangles may come in any orientation: they are oriented consistently across each
/// edge-connected component, and a component is reversed when its area-weighted normals point
/// against the field gradient at its vertices (the sample normal where the field is undefined).
/// \param triangles  #F by 3 sample indices
/// \param samples    the samples (e.g. PointField::surfels()); normals optional
/// \param source     how errors name the input (a file name, "picked triangles")
/// \param lines      empty, or the 1-based line of each triangle in `source`, for messages
/// \throw InvalidInput naming the triangle (and line): an index out of range, a triangle that
///        repeats a sample, two triangles over the same three samples, an edge with more than two
///        triangles, a vertex whose triangles form several fans, a non-orientable component, or
///        no triangles at all
[[nodiscard]] PickedBaseMesh base_mesh_from_samples(std::span<const Triangle> triangles,
                                                    const PointCloud& samples, const Field& field,
                                                    const std::string& source = "picked triangles",
                                                    std::span<const std::size_t> lines = {});

/// \brief A base mesh picked as points: vertex positions (world coordinates) and triangles over
/// them, each used vertex to be snapped to its nearest sample (snap_picked_base_mesh()). What an
/// OBJ given to read_picked_base_mesh() holds, and what `pointform view` sends when a user picks
/// samples on its page.
struct PickedVertices
{
    std::vector<Vec3d> vertices;
    std::vector<Triangle> triangles;
    /// How messages name the input (a file name, "the viewer's picked triangles").
    std::string source = "picked triangles";

    [[nodiscard]] bool empty() const noexcept { return triangles.empty(); }
};

/// \brief Triangles over indices of `samples` (what a user picks on a point cloud, before any
/// surfels exist) as PickedVertices: the picked samples' world positions in order of first use
/// and the triangles over them, so that they snap back to those samples in
/// snap_picked_base_mesh() even if samples are dropped or reordered on the way to the surfels.
/// \throw InvalidInput naming `source`: an index out of range
[[nodiscard]] PickedVertices picked_vertices_from_samples(std::span<const Triangle> triangles,
                                                          const PointCloudView& samples,
                                                          const std::string& source);

/// \brief Snaps every vertex used by picked.triangles to its nearest sample, then
/// base_mesh_from_samples(); PickedBaseMesh::max_snap_distance is the farthest snap.
/// \throw InvalidInput naming picked.source: no samples or no triangles, a vertex index out of
///        range, a vertex that is not finite, two vertices that snap to the same sample, and
///        every condition of base_mesh_from_samples()
[[nodiscard]] PickedBaseMesh snap_picked_base_mesh(const PickedVertices& picked,
                                                   const PointCloud& samples, const Field& field);

/// \brief Reads a picked base mesh: an OBJ (".obj") whose vertices are snapped to their nearest
/// samples, or any other file as text, one triangle a line as three sample indices "i j k"
/// (0-based; '#' starts a comment; blank lines are skipped). Then base_mesh_from_samples().
/// \throw IoError if the file is missing or unreadable (or, for OBJ, malformed as io reads it)
/// \throw InvalidInput naming the file and line: a line that is not three non-negative integers,
///        an index that names no sample, two OBJ vertices that snap to the same sample, and every
///        condition of base_mesh_from_samples()
[[nodiscard]] PickedBaseMesh read_picked_base_mesh(const std::filesystem::path& path,
                                                   const PointCloud& samples, const Field& field);

} // namespace pointform
