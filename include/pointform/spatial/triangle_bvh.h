// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include "pointform/core/progress.h"
#include "pointform/core/types.h"
#include "pointform/geometry/aabb.h"
#include "pointform/geometry/tri_mesh.h"

#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <string_view>
#include <vector>

namespace pointform {

/// \brief Options for building a TriangleBvh.
struct TriangleBvhOptions
{
    /// Most triangles in a leaf. 2 to 8 suits closest-point queries (on the bunny, 4 and 8 query
    /// equally fast and 10% faster than 1); 0 = 4.
    std::size_t leaf_size = 4;
    /// Triangles taken in consecutive groups of this many, each group in one leaf: the four
    /// children of a face after a 1-to-4 split (triangles 4f ... 4f + 3), which tile their
    /// parent, so the build sorts a quarter as many boxes. The triangle count must be a
    /// multiple (else InvalidInput); 0 or 1 = every triangle on its own.
    std::size_t group_size = 1;
    /// The build bins, partitions and boxes the groups in blocks of this many, fixed so that
    /// the tree is the same for any thread count; a range of at least four blocks is split in
    /// parallel blocks, also inside the subtrees that are built at once. The default suits
    /// every size; a small block makes a small mesh take the large meshes' paths (tests of
    /// the parallel build). 0 = default_build_block.
    std::size_t build_block = default_build_block;

    static constexpr std::size_t default_build_block = 16384;
};

/// \brief Options for batch closest-point queries.
struct ClosestPointOptions
{
    /// Only triangles closer than this (world units) are found; farther queries get a Hit with
    /// an invalid face and an infinite distance. Infinity (the default) always finds one.
    double max_distance = std::numeric_limits<double>::infinity();
    /// Optional progress report, called from one thread.
    ProgressCallback progress;
    /// Optional spatial_order() of the query points, for a caller that measures the same
    /// points again (each pass would sort them anew); empty, or a permutation of the queries
    /// (anything else is refused: InvalidInput).
    /// The order only decides which queries a search runs beside: the results are the same.
    std::span<const std::uint32_t> order;
};

/// \brief Exact closest points on a triangle mesh, accelerated by a bounding-volume hierarchy.
///
/// The hierarchy is built over the triangles with a binned surface-area heuristic and stored
/// flat (depth-first order, 32-byte nodes). A query visits the nearer child first and prunes every
/// box farther than the best triangle so far; the closest point on a triangle is found exactly
/// by classifying the query into the triangle's vertex, edge or face region (Ericson, Real-Time
/// Collision Detection §5.1.5), in double precision. Degenerate triangles (zero area, needles,
/// repeated vertices) are measured as the segments or the point they are.
///
/// The BVH copies the triangles (in double precision, relative to the mesh's origin), so the
/// mesh need not outlive it. Queries are const and may run concurrently; results do not depend
/// on the thread count. Ties between equally distant triangles go to the one met first in the
/// hierarchy's fixed traversal order.
class TriangleBvh
{
public:
    /// \brief The closest point of the mesh to a query.
    struct Hit
    {
        /// Euclidean distance from the query to `point`, in world units; infinity if none found.
        double distance = std::numeric_limits<double>::infinity();
        /// The triangle on which `point` lies (index into TriMesh::triangles); invalid if none.
        FaceId face;
        /// The closest point, in world coordinates.
        Vec3d point = Vec3d::Zero();
        /// Weights of the triangle's three vertices: point = b[0] v0 + b[1] v1 + b[2] v2, each in
        /// [0, 1], summing to 1.
        Vec3d barycentric = Vec3d::Zero();

        [[nodiscard]] bool found() const { return face.is_valid(); }
    };

    /// \param mesh  V vertices and F >= 1 triangles; degenerate triangles are allowed.
    /// \throw InvalidInput if the mesh has no triangles, a vertex index is out of range, a
    ///        position is not finite, or F exceeds 2^32 - 2.
    explicit TriangleBvh(const TriMesh& mesh, const TriangleBvhOptions& options = {});

    /// \brief The closest point of the mesh to `world_point`.
    /// \param max_distance  only points closer than this are found (see ClosestPointOptions)
    [[nodiscard]] Hit closest(const Vec3d& world_point,
                              double max_distance = std::numeric_limits<double>::infinity()) const;

    /// \brief Whether some triangle lies closer than `distance` (strictly) to `world_point`. The
    /// search stops at the first such triangle, so where one is near it costs a descent to a
    /// leaf, far less than closest(). False for a non-finite point or a distance that is not
    /// positive.
    [[nodiscard]] bool any_within(const Vec3d& world_point, double distance) const;

    /// \brief Distance from `world_point` to the mesh; shorthand for closest(p).distance.
    [[nodiscard]] double distance(const Vec3d& world_point) const;

    [[nodiscard]] std::size_t face_count() const { return face_count_; }
    [[nodiscard]] std::size_t node_count() const { return nodes_.size(); }
    /// \brief Bounding box of the triangles, in world units.
    [[nodiscard]] Aabb bounds() const;
    /// \brief The mesh's origin; stored triangles are relative to it.
    [[nodiscard]] const Vec3d& origin() const { return origin_; }

private:
    /// A node: its box (float, rounded outwards, relative to origin_), and either two children
    /// (count == 0: left child is the next node, right child is `index`) or a leaf of `count`
    /// triangles starting at `index` in the reordered triangle arrays.
    struct Node
    {
        std::array<float, 3> lo;
        std::array<float, 3> hi;
        std::uint32_t index;
        std::uint32_t count;
    };

    /// A triangle's corners relative to origin_, as the mesh holds them (the queries work in
    /// double precision from these floats, which convert exactly; half the memory of doubles).
    struct Corners
    {
        Vec3f a;
        Vec3f b;
        Vec3f c;

        /// The corners in double precision, as the queries use them.
        [[nodiscard]] std::array<Vec3d, 3> widened() const
        {
            return {a.cast<double>(), b.cast<double>(), c.cast<double>()};
        }
    };

    Vec3d origin_ = Vec3d::Zero();
    std::size_t face_count_ = 0;
    std::vector<Node> nodes_;
    std::vector<Corners> corners_;        ///< F, in leaf order
    std::vector<std::uint32_t> face_ids_; ///< F, leaf order → index in the input mesh
};

/// \brief Closest points on the mesh of every query, in parallel.
/// \param queries  M points in world coordinates
/// \return M hits, in the order of the queries
[[nodiscard]] std::vector<TriangleBvh::Hit> closest_points(const TriangleBvh& bvh,
                                                           std::span<const Vec3d> queries,
                                                           const ClosestPointOptions& options = {});

/// \brief Distance from every point of `points` (world = origin + position) to the mesh, in
/// parallel, in world units.
/// \return points.size() distances, in the order of the points
[[nodiscard]] std::vector<double> distances_to_mesh(const TriangleBvh& bvh,
                                                    const PointCloudView& points,
                                                    const ClosestPointOptions& options = {});

/// \brief Distances from points to a mesh with each point's closest triangle.
struct NearestTriangles
{
    std::vector<double> distances;    ///< per point, in world units (infinity if none found)
    std::vector<std::uint32_t> faces; ///< per point, the closest triangle (or UINT32_MAX)
};

/// \brief distances_to_mesh() with the closest triangles, and optional per-point upper bounds
/// on the distances that prune the searches (the distance to a triangle known to be near the
/// point, e.g. a child of the point's closest triangle on a coarser level of a subdivision).
/// A bound only prunes: each distance and triangle is the one an unbounded search finds, and a
/// bound below the true distance (or not finite) falls back to the unbounded search.
/// \param upper_bounds  empty, or points.size() bounds in world units
/// \throw InvalidInput if upper_bounds is neither empty nor of points.size()
[[nodiscard]] NearestTriangles nearest_triangles(const TriangleBvh& bvh,
                                                 const PointCloudView& points,
                                                 std::span<const double> upper_bounds = {},
                                                 const ClosestPointOptions& options = {});

/// \brief How many triangles' bounding boxes a random line through the mesh's bounding box
/// crosses, on average: the sum of the triangles' box surface areas over the mesh box's (Cauchy-
/// Crofton). No hierarchy of axis-aligned boxes can answer a ray or closest-point query on the
/// mesh with fewer triangle tests, on average, than this. Well-shaped meshes give 2 to 12 (the
/// Stanford bunny 3.5, a 512-sided cylinder with fan caps 11); a polygon of F + 2 vertices on a
/// circle, fan-triangulated from a corner, F / (2π). A mesh whose box is a point or a segment (zero
/// area) gives its face count. \throw InvalidInput if a vertex index is out of range
[[nodiscard]] double triangle_box_depth(const TriMesh& mesh);

/// \brief Refuses, before any work, a batch of `queries` ray or closest-point queries on a mesh
/// whose triangles' boxes overlap so much (triangle_box_depth above 64, as in a fan of long
/// slivers: one polygon of many vertices triangulated from a corner) that the batch would cost
/// more than `work_limit` triangle tests. Well-shaped meshes are never refused.
/// \param what        the operation, for the message ("point-to-mesh distance")
/// \param work_limit  queries × depth allowed; the default, 1e9, is about 10 s of this class's
///                    closest-point queries on 2 cores (a 100,000-gon took 40 CPU-seconds for
///                    3.2e9); Embree's rays, which test several boxes at once, run ten times more
/// \throw InvalidInput with the estimate, naming the fix (remesh or retriangulate the polygon)
void check_query_work(const TriMesh& mesh, std::size_t queries, std::string_view what,
                      double work_limit = 1e9);

/// \brief Exact closest point on one triangle (a, b, c) to p, degenerate triangles included.
/// \return the weights (u, v, w) of a, b and c; the closest point is u a + v b + w c.
[[nodiscard]] Vec3d closest_point_barycentric(const Vec3d& p, const Vec3d& a, const Vec3d& b,
                                              const Vec3d& c);

} // namespace pointform
