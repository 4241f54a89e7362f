// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/polygonize/scene_mesh.h"

#include "pointform/core/error.h"
#include "pointform/geometry/mesh_topology.h"
#include "pointform/implicit/operators.h"
#include "pointform/implicit/primitives.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace pointform {
namespace {

TEST(SceneGrid, BoxAndCellFromTheOptionsOrTheScene)
{
    const auto sphere = make_sphere(Vec3d(1, 2, 3), 0.5);
    // No scans: the longest side / 128.
    const SceneGrid fallback = choose_scene_grid(sphere->bounds(), {}, {});
    EXPECT_NEAR(fallback.cell, 1.0 / 128.0, 1e-12);
    EXPECT_EQ(fallback.box.min, sphere->bounds().min);
    // A cell, a resolution, and a box of one's own.
    EXPECT_EQ(choose_scene_grid(sphere->bounds(), {.cell = 0.05}, {}).cell, 0.05);
    EXPECT_NEAR(choose_scene_grid(sphere->bounds(), {.resolution = 20}, {}).cell, 1.0 / 20.0,
                1e-12);
    Aabb box;
    box.min = Vec3d(0, 0, 0);
    box.max = Vec3d(4, 1, 1);
    const SceneGrid own = choose_scene_grid(sphere->bounds(), {.bounds = box}, {});
    EXPECT_EQ(own.box.max, box.max);
    EXPECT_NEAR(own.cell, 4.0 / 128.0, 1e-12);
}

TEST(SceneGrid, RefusesUnboundedEmptyAndOversizedScenes)
{
    const auto half = make_half_space(Vec3d::Zero(), Vec3d::UnitZ());
    EXPECT_THROW((void)choose_scene_grid(half->bounds(), {}, {}), InvalidInput);
    const auto apart =
        make_intersection({make_sphere(Vec3d(-5, 0, 0), 1.0), make_sphere(Vec3d(5, 0, 0), 1.0)});
    EXPECT_THROW((void)choose_scene_grid(apart->bounds(), {}, {}), InvalidInput);
    // A cell far too fine for the box's area.
    EXPECT_THROW(
        (void)choose_scene_grid(make_sphere(Vec3d::Zero(), 1000.0)->bounds(), {.cell = 1e-4}, {}),
        InvalidInput);
}

TEST(SceneMesh, MarchingCubesOrTheSemiRegularMeshOnTheZeroSet)
{
    // A cube minus a sphere through its corner region: sharp edges and a concave cut.
    const auto cut = make_difference(make_box(Vec3d(-1, -1, -1), Vec3d(1, 1, 1), 0.0),
                                     make_sphere(Vec3d(1, 1, 1), 0.8));
    const SceneMeshReport mc = scene_mesh(*cut, {}, {.grid = {.resolution = 40}});
    EXPECT_FALSE(mc.semi_regular.has_value());
    EXPECT_EQ(&mc.mesh(), &mc.marching_cubes.mesh);
    EXPECT_TRUE(analyze_topology(mc.mesh()).is_closed());
    ASSERT_EQ(mc.stage_seconds.size(), 1U);

    const SceneMeshReport semi =
        scene_mesh(*cut, {}, {.grid = {.resolution = 40}, .semi_regular = SemiRegularOptions{}});
    ASSERT_TRUE(semi.semi_regular.has_value());
    const MultiresMesh& hierarchy = semi.semi_regular->hierarchy;
    EXPECT_EQ(hierarchy.finest_level(), default_scene_levels);
    EXPECT_EQ(semi.mesh().face_count(), 16 * hierarchy.face_count(0));
    // The base mesh is about the marching-cubes faces / 16.
    EXPECT_NEAR(static_cast<double>(semi.semi_regular->base->target_faces),
                static_cast<double>(mc.marching_cubes.mesh.face_count()) /
                    static_cast<double>(default_scene_base_share),
                1.0);
    const MeshTopology topo = analyze_topology(semi.mesh());
    EXPECT_TRUE(topo.is_closed());
    EXPECT_EQ(topo.euler_characteristic, 2);
    // Vertices lie on the zero set (up to those left off it at the sharp edges).
    EXPECT_LT(semi.residual.mean, 0.05 * semi.grid.cell);
    ASSERT_EQ(semi.stage_seconds.size(), 3U);
    EXPECT_EQ(semi.stage_seconds[1].first, "base mesh");

    // A surface the box misses makes no triangles.
    EXPECT_THROW((void)scene_mesh(*make_sphere(Vec3d(10, 0, 0), 1.0), {},
                                  {.grid = {.bounds = Aabb{Vec3d(-1, -1, -1), Vec3d(1, 1, 1)}}}),
                 Error);
}

} // namespace
} // namespace pointform
