// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include "pointform/core/progress.h"
#include "pointform/geometry/tri_mesh.h"
#include "pointform/implicit/field.h"

#include <array>
#include <cstddef>
#include <cstdint>

namespace pointform {

/// \brief A regular grid of cubic cells: cell (i, j, k) spans origin + cell·[i, i+1] × … .
struct CellGrid
{
    Vec3d origin = Vec3d::Zero();
    double cell = 0.0;
    std::array<std::int64_t, 3> cells = {0, 0, 0};
};

/// \brief Lays a grid of cells of size `cell` over `box`, with one cell of margin on every side.
/// \throw InvalidInput if the box is empty or not finite, the cell is not positive, or the grid
///        would exceed 2²⁰ cells along an axis
[[nodiscard]] CellGrid grid_over(const Aabb& box, double cell);

/// \brief The cell size that puts `resolution` cells along the longest side of `box`.
/// \throw InvalidInput if resolution < 2 or the box is empty
[[nodiscard]] double cell_for_resolution(const Aabb& box, int resolution);

class PointField;

/// \brief The default cell size for polygonizing a point field: small enough that the corners
/// of every cell the surface crosses lie within the influence radius of their nearest sample
/// (0.4 of the median radius), so a clean scan comes out closed.
[[nodiscard]] double default_cell_size(const PointField& field);

/// \brief The cell of marching cubes on a point field: `resolution` cells along the longest side
/// of `bounds` when `resolution` > 0, else `cell` when > 0, else default_cell_size(field).
[[nodiscard]] double choose_cell_size(const PointField& field, const Aabb& bounds, int resolution,
                                      double cell);

/// \brief About how many bytes marching cubes needs on a point field at this cell size (the
/// cells on a surface of the field's estimated area, with their corner values, triangles and
/// vertices).
[[nodiscard]] double estimate_marching_cubes_bytes(const PointField& field, double cell);

/// \brief About how many bytes marching cubes needs on a surface of `surface_area` (units²) at
/// this cell size (about 600 bytes per cell of side `cell` per cell² of area).
[[nodiscard]] double estimate_marching_cubes_bytes(double surface_area, double cell);

/// \brief About how many triangles marching cubes makes of a surface of `surface_area` at this
/// cell size: 3 A / h² (a surface crosses about 1.5 A / h² cells, the mean of |nx| + |ny| + |nz|
/// over directions, and each crossed cell makes about two triangles).
[[nodiscard]] double estimate_marching_cubes_faces(double surface_area, double cell);

/// Intermediate faces above which the grid of the automatic base mesh's marching cubes is
/// coarsened (intermediate_grid()): 4 times the largest default base-face target
/// (max_default_base_faces), so that the decimation to the base mesh costs the same from about
/// 200k samples up. 8 times before: on ten 1M-sample inputs (the five analytic shapes of
/// bench/peers, clean and with 0.2% noise and 8 holes) the whole run took 0.4-6.8 s less (15-27
/// s before, a slow hour) with 30-120 MiB less peak; Hausdorff to the truth fell on all ten (the
/// clean plate 0.447 -> 0.207% of the diagonal) and the share of triangles under 20° on nine;
/// Chamfer rose on the clean part (0.00026 -> 0.00032%, 7% fewer vertices) and the noisy sphere
/// and torus (2-3%); the noisy ones' spurious handles went (Euler characteristic -8, -6, -22, -4
/// -> the truth's 2, 0, 2, 0). Four simulated scans of 490k-570k samples: 14-25% faster, Chamfer
/// and F@0.5% within 0.6%, handles fewer on two, more on one (the coarse grid's cells join gaps
/// wider than the fine one's), as on table_scene_mug (Euler characteristic -9 -> -17).
inline constexpr double max_intermediate_faces = 320000.0;

/// \brief The grid of the intermediate (marching-cubes) mesh that an automatic base mesh is
/// simplified from (§5.1, Fig. 5).
struct IntermediateGrid
{
    double cell = 0.0;            ///< the grid's cell
    double coarsening = 1.0;      ///< cell over the field's cell; 1 keeps the field's own grid
    int min_defined_corners = 8;  ///< for MarchingCubesOptions: 1 on a coarsened grid
    double estimated_faces = 0.0; ///< faces at the field's cell (estimate_marching_cubes_faces)
};

/// \brief The field's cell (`cell`, e.g. default_cell_size) where its marching cubes would have
/// at most `max_faces` triangles; else a cell coarser by √(estimated faces / max_faces), whose
/// mesh has about max_faces, with cells that make triangles from one defined corner up (the
/// corners of a coarse cell lie beyond the influence radii; holes wider than a cell stay open).
/// The base mesh only needs the intermediate mesh's shape and topology at the base mesh's
/// scale, and refinement projects every finer vertex onto the field itself, so the fine
/// marching-cubes mesh is never built (on a clean 1M-sample blobby, whose field's mesh has
/// 1.68M faces: marching cubes, debris and decimation 20.1 s → 8.4 s, and closed where the
/// field's own grid left 2 pinholes at concave creases).
/// \throw InvalidInput if the cell or max_faces is not positive and finite
[[nodiscard]] IntermediateGrid intermediate_grid(const PointField& field, double cell,
                                                 double max_faces = max_intermediate_faces);

/// \brief Refuses, before anything is allocated, a cell size whose marching cubes would need
/// more memory than this process may use (check_memory(): the cgroup limit or MemAvailable).
/// \throw InvalidInput saying how much it would need and how much there is
void check_marching_cubes_memory(const PointField& field, double cell);

struct MarchingCubesOptions
{
    /// Refine each vertex by regula falsi on the field along its grid edge (evaluations per
    /// vertex); 0 keeps the linear interpolation of the corner values.
    int refine_steps = 3;
    /// Store the normalised field gradient at each vertex as its normal.
    bool vertex_normals = true;
    /// A cell the zero set crosses makes triangles when at least this many of its corners are
    /// defined (1 to 8); its undefined corners count by their sign (for a PointField, the side of
    /// the nearest sample's surface). 8, the default: holes in the samples stay open as the
    /// field has them. A grid coarser than the samples' influence radii (an intermediate mesh
    /// for the base mesh) has undefined corners next to the surface everywhere; below 8, the
    /// cells make triangles from that many defined corners up, and the triangles with a vertex
    /// where the field is undefined are dropped (MarchingCubesStats::undefined_triangles), so
    /// the surface is closed where the samples are and holes stay open where they are not.
    int min_defined_corners = 8;
    ProgressCallback progress;
};

struct MarchingCubesStats
{
    std::size_t cells_visited = 0;     ///< cells whose corners were evaluated
    std::size_t surface_cells = 0;     ///< cells that made triangles
    std::size_t undefined_cells = 0;   ///< cells with a sign change but an undefined corner
    std::size_t field_evaluations = 0; ///< corners plus vertex refinement
    /// Triangles of (next to) zero area on the stored float32 positions (possible only where
    /// rounding crushes a tiny triangle at a corner). Each is made whole by flipping its long
    /// edge with the neighbour across it, which keeps the surface closed and unchanged.
    std::size_t degenerate_triangles = 0;
    /// Those of degenerate_triangles that no flip could mend; kept, so the surface stays closed.
    std::size_t degenerate_kept = 0;
    std::size_t split_vertices = 0; ///< copies made where two sheets touched at a vertex
    /// Vertices inside a cell: where a tunnel through an ambiguous face leaves no way to cut the
    /// cell's loop into triangles without a chord that the neighbouring cell may draw too, the
    /// loop is fanned around a vertex of its own, on the zero crossing of a diagonal of the cell.
    std::size_t cell_vertices = 0;
    /// With min_defined_corners below 8: triangles dropped because the field is undefined at one
    /// of their vertices (past a hole's rim), so holes stay open as the field has them.
    std::size_t undefined_triangles = 0;
    bool dense = false; ///< the field gave no seeds, so every cell of the grid was visited
};

struct MarchingCubesResult
{
    TriMesh mesh;
    MarchingCubesStats stats;
};

/// \brief Marching cubes over the sparse set of cells the surface passes through (Fig. 4, §5.1).
///
/// Starts from the cells that contain the field's seeds (Field::append_seeds) and follows the
/// surface from cell to cell through faces that the zero set crosses, so only cells near the
/// surface are evaluated: a 1M-sample scan at 512 cells along its longest side needs a few
/// million field evaluations, not 512³. A field without seeds is swept densely.
///
/// Inside is f < 0 (a corner with f = 0 counts as outside). A cell with an undefined corner makes
/// no triangles (see MarchingCubesOptions::min_defined_corners), so holes in the samples stay
/// open. Each cell's surface is built from the
/// segments the zero set draws on its six faces; a face with two diagonal inside corners is
/// resolved by the asymptotic decider, which depends only on that face's four values, so the two
/// cells sharing the face always agree and the mesh is a 2-manifold (with boundary where the
/// field is undefined). Vertices are shared between cells; triangles are oriented with normals
/// towards f > 0 (outwards); the result is the same whatever the thread count. No triangle is
/// dropped (see MarchingCubesStats::degenerate_triangles).
[[nodiscard]] MarchingCubesResult marching_cubes(const Field& field, const CellGrid& grid,
                                                 const MarchingCubesOptions& options = {});

} // namespace pointform
