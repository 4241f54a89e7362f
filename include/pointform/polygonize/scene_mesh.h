// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// A scene's field (implicit/scene.h) to a mesh: the grid it is polygonized on, marching cubes,
// and optionally the semi-regular mesh of §5 refined exactly to a number of levels (what
// `pointform model` runs).

#pragma once

#include "pointform/core/progress.h"
#include "pointform/geometry/aabb.h"
#include "pointform/geometry/tri_mesh.h"
#include "pointform/implicit/field.h"
#include "pointform/implicit/scans.h"
#include "pointform/polygonize/marching_cubes.h"
#include "pointform/polygonize/reconstruct.h"

#include <cstddef>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace pointform {

/// \brief Where and how finely a scene is polygonized.
struct SceneGridOptions
{
    /// The box; unset = the field's bounds (which must then be bounded).
    std::optional<Aabb> bounds;
    /// The cell size (> 0), or else cells along the box's longest side (≥ 2), or else (both 0)
    /// 0.4 of the smallest median influence radius of the scans (default_cell_size()), or the
    /// longest side / 128 for a scene without scans.
    double cell = 0.0;
    int resolution = 0;
};

/// \brief The grid a scene is polygonized on.
struct SceneGrid
{
    Aabb box;
    double cell = 0.0;
    CellGrid grid;
};

/// \brief Lays the grid over options.bounds or else `field_bounds` (SceneGridOptions), and
/// refuses an unbounded or empty box, and a cell that would need more memory than there is.
/// \param scans  the scans the scene uses (their fields set the default cell and the memory)
/// \throw InvalidInput for an empty or unbounded box, or work that would not fit in memory
[[nodiscard]] SceneGrid choose_scene_grid(const Aabb& field_bounds, const SceneGridOptions& options,
                                          std::span<const LoadedScan> scans);

/// Refinement levels of a scene's semi-regular mesh when none are given: two levels give each
/// base face 16, so the output keeps the marching-cubes resolution.
inline constexpr std::size_t default_scene_levels = 2;
/// Marching-cubes faces per base face of a scene's semi-regular mesh: coarser base meshes lose
/// the sharp edges of Booleans (on the README's bunny cut, 1/64 of the faces tore the cut face
/// of the head; 1/16 keeps it).
inline constexpr std::size_t default_scene_base_share = 16;

/// \brief Options of scene_mesh().
struct SceneMeshOptions
{
    SceneGridOptions grid;
    /// Set: the semi-regular mesh of §5 (the marching-cubes mesh simplified to a base mesh,
    /// default_scene_base_share faces per base face unless base_faces is given, refined exactly
    /// to `levels`, default default_scene_levels: no samples cover a modeled surface for the
    /// §5.2.4 stop). Unset: the marching-cubes mesh.
    std::optional<SemiRegularOptions> semi_regular;
    ProgressCallback progress;
};

/// \brief What scene_mesh() made and every figure of how.
struct SceneMeshReport
{
    SceneGrid grid;
    /// The marching-cubes mesh and its statistics (the output without semi_regular).
    MarchingCubesResult marching_cubes;
    /// The semi-regular mesh, when asked for, its finest level, and |f| at that level's
    /// vertices (how near the scene's zero set they lie).
    std::optional<SemiRegularReport> semi_regular;
    TriMesh finest;
    VertexResidual residual;
    /// Wall-clock seconds by stage, in order: "marching cubes", then with semi_regular
    /// "base mesh" and "refinement".
    std::vector<std::pair<std::string, double>> stage_seconds;

    /// The output: the semi-regular mesh's finest level, or the marching-cubes mesh.
    [[nodiscard]] const TriMesh& mesh() const
    {
        return semi_regular ? finest : marching_cubes.mesh;
    }
};

/// \brief Polygonizes a scene's field: choose_scene_grid(), marching cubes, and with
/// options.semi_regular semi_regular_mesh() refined exactly to its levels.
/// \throw InvalidInput as choose_scene_grid() and semi_regular_mesh(); Error when marching
///        cubes makes no triangle; Cancelled if the progress callback asks to stop
[[nodiscard]] SceneMeshReport scene_mesh(const Field& field, std::span<const LoadedScan> scans,
                                         const SceneMeshOptions& options = {});

} // namespace pointform
