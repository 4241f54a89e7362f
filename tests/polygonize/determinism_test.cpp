// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// Same input, same output whatever the thread count: the stages of the pipeline run at 1, 2 and
// 3 threads on inputs large enough that every one of them splits its work into several parallel
// blocks (checked through parallel_stats()), and their results are compared bit for bit.

#include "pointform/core/parallel.h"
#include "pointform/geometry/multires_mesh.h"
#include "pointform/geometry/shapes.h"
#include "pointform/hermite/surfels.h"
#include "pointform/implicit/point_field.h"
#include "pointform/polygonize/base_mesh.h"
#include "pointform/polygonize/marching_cubes.h"
#include "pointform/polygonize/reconstruct.h"
#include "pointform/polygonize/refine.h"
#include "pointform/spatial/triangle_bvh.h"

#include "support/thread_counts.h"

#include <gtest/gtest.h>

#include <memory>
#include <random>
#include <vector>

namespace pointform {
namespace {

using test::at_thread_counts;

/// These runs have many long blocks: some must have run on more than one thread.
constexpr test::ParallelCheck several{.min_multi_block_loops = 3,
                                      .blocks_on_several_threads = true};

/// A sampled torus (genus 1, so the stages meet a non-trivial topology), its field and its
/// marching-cubes mesh, made once at the default thread count.
struct Torus
{
    PointCloud samples;
    std::unique_ptr<PointField> field;
    CellGrid grid;
    TriMesh mc;
    TriMesh base;
};

const Torus& torus()
{
    static const Torus scene = [] {
        Torus t;
        t.samples = sample_shape(Shape::Torus, {.count = 20000, .seed = 2});
        t.field = std::make_unique<PointField>(
            compute_surfels(t.samples, {.radius_scale = default_field_radius_scale}).surfels);
        t.grid = grid_over(t.field->bounds(), default_cell_size(*t.field));
        t.mc = marching_cubes(*t.field, t.grid).mesh;
        t.base = build_base_mesh(t.mc, *t.field, {.target_faces = 1500}).mesh;
        return t;
    }();
    return scene;
}

void expect_same_mesh(const TriMesh& a, const TriMesh& b, int threads)
{
    EXPECT_EQ(a.vertices.origin, b.vertices.origin) << threads << " threads";
    EXPECT_TRUE(a.vertices.positions == b.vertices.positions) << threads << " threads";
    EXPECT_TRUE(a.vertices.normals == b.vertices.normals) << threads << " threads";
    EXPECT_TRUE(a.triangles == b.triangles) << threads << " threads";
}

TEST(Determinism, MarchingCubes)
{
    const Torus& t = torus();
    const auto runs = at_thread_counts([&] { return marching_cubes(*t.field, t.grid); }, several);
    ASSERT_GT(runs[0].mesh.face_count(), 10000U);
    for (std::size_t i = 1; i < runs.size(); ++i)
    {
        const int threads = static_cast<int>(i) + 1;
        expect_same_mesh(runs[0].mesh, runs[i].mesh, threads);
        EXPECT_EQ(runs[0].stats.cells_visited, runs[i].stats.cells_visited) << threads;
        EXPECT_EQ(runs[0].stats.field_evaluations, runs[i].stats.field_evaluations) << threads;
        EXPECT_EQ(runs[0].stats.split_vertices, runs[i].stats.split_vertices) << threads;
    }
}

TEST(Determinism, BaseMesh)
{
    const Torus& t = torus();
    // Its shape rounds relax and project the base mesh's vertices in blocks of 256: 8000 faces
    // make about 16 blocks.
    const auto runs = at_thread_counts(
        [&] { return build_base_mesh(t.mc, *t.field, {.target_faces = 8000}); }, several);
    ASSERT_GT(runs[0].mesh.vertex_count(), 12 * 256U);
    for (std::size_t i = 1; i < runs.size(); ++i)
    {
        const int threads = static_cast<int>(i) + 1;
        expect_same_mesh(runs[0].mesh, runs[i].mesh, threads);
        EXPECT_EQ(runs[0].stats.flips, runs[i].stats.flips) << threads;
        EXPECT_EQ(runs[0].stats.smoothing_rounds, runs[i].stats.smoothing_rounds) << threads;
        EXPECT_EQ(runs[0].stats.unprojected, runs[i].stats.unprojected) << threads;
        EXPECT_EQ(runs[0].stats.max_vertex_move, runs[i].stats.max_vertex_move) << threads;
    }
}

TEST(Determinism, Refinement)
{
    const Torus& t = torus();
    struct Run
    {
        std::vector<Vec3d> positions;
        std::vector<Triangle> faces;
        RefineReport report;
    };
    const auto runs = at_thread_counts(
        [&] {
            MultiresMesh mesh(t.base);
            Run run;
            run.report = refine(mesh, *t.field, t.samples,
                                {.predictor = Predictor::Butterfly,
                                 .relax_iterations = 2,
                                 .max_level = 2,
                                 .sampling_density = 1e-9, // never reached: both levels are made
                                 .min_improvement = 0.0});
            run.positions.assign(mesh.positions().begin(), mesh.positions().end());
            const TriMesh finest = mesh.level_mesh(mesh.finest_level());
            run.faces = finest.triangles;
            return run;
        },
        several);
    ASSERT_EQ(runs[0].report.levels.size(), 2U);
    ASSERT_GT(runs[0].positions.size(), 4 * 512U); // prediction blocks of 512 new vertices
    for (std::size_t i = 1; i < runs.size(); ++i)
    {
        const int threads = static_cast<int>(i) + 1;
        EXPECT_TRUE(runs[0].positions == runs[i].positions) << threads << " threads";
        EXPECT_TRUE(runs[0].faces == runs[i].faces) << threads << " threads";
        EXPECT_EQ(runs[0].report.initial_hausdorff, runs[i].report.initial_hausdorff) << threads;
        ASSERT_EQ(runs[i].report.levels.size(), 2U);
        for (std::size_t l = 0; l < 2; ++l)
        {
            const RefineLevelStats& a = runs[0].report.levels[l];
            const RefineLevelStats& b = runs[i].report.levels[l];
            EXPECT_EQ(a.hausdorff, b.hausdorff) << threads << " threads, level " << l;
            EXPECT_EQ(a.mean_distance, b.mean_distance) << threads << " threads, level " << l;
            EXPECT_EQ(a.relaxed, b.relaxed) << threads << " threads, level " << l;
            EXPECT_EQ(a.relax_undone, b.relax_undone) << threads << " threads, level " << l;
            EXPECT_EQ(a.fold_vertices, b.fold_vertices) << threads << " threads, level " << l;
            EXPECT_EQ(a.unprojected, b.unprojected) << threads << " threads, level " << l;
        }
    }
}

TEST(Determinism, NoisyLevelSmoothing)
{
    // The whole reconstruction of a noisy sphere, which stops on noise and smooths its finest
    // level (RefineOptions::denoise_rounds, Jacobi rounds in blocks of 512 vertices).
    PointCloud raw;
    {
        const PointCloud drawn =
            sample_shape(Shape::Sphere, {.count = 20000, .seed = 4, .noise = 0.002});
        raw.origin = drawn.origin;
        raw.positions = drawn.positions;
    }
    const PointCloud samples = surfels_from_samples(raw).surfels;
    struct Run
    {
        std::vector<Vec3d> positions;
        RefineReport report;
    };
    const auto runs = at_thread_counts(
        [&] {
            ReconstructReport report = reconstruct(samples, {});
            const MultiresMesh& mesh = report.semi_regular.hierarchy;
            return Run{{mesh.positions().begin(), mesh.positions().end()},
                       report.semi_regular.refinement};
        },
        several);
    ASSERT_EQ(runs[0].report.stop, RefineStop::NoisyDetails);
    ASSERT_GT(runs[0].report.denoise_rounds, 0U);
    ASSERT_GT(runs[0].positions.size(), 4 * 512U);
    for (std::size_t i = 1; i < runs.size(); ++i)
    {
        const int threads = static_cast<int>(i) + 1;
        EXPECT_TRUE(runs[0].positions == runs[i].positions) << threads << " threads";
        EXPECT_EQ(runs[0].report.denoise_max_move, runs[i].report.denoise_max_move) << threads;
        EXPECT_EQ(runs[0].report.levels.back().mean_distance,
                  runs[i].report.levels.back().mean_distance)
            << threads;
    }
}

TEST(Determinism, TriangleBvhBuildAndQueries)
{
    const Torus& t = torus();
    // Finer than t.mc, for several of the build's blocks of 16384 faces.
    const TriMesh mesh =
        marching_cubes(*t.field, grid_over(t.field->bounds(), 0.6 * default_cell_size(*t.field)))
            .mesh;
    ASSERT_GT(mesh.face_count(), 4 * 16384U);
    // Queries at vertices are equally near every face around them: which face a hit names
    // follows the hierarchy's layout, so it shows a layout that changed with the thread count.
    std::vector<Vec3d> queries;
    for (std::size_t v = 0; v < mesh.vertex_count(); v += 3)
        queries.push_back(mesh.vertices.world(v));
    std::mt19937 random(7);
    std::uniform_real_distribution<double> coordinate(-1.8, 1.8);
    for (int i = 0; i < 20000; ++i)
        queries.emplace_back(coordinate(random), coordinate(random), 0.5 * coordinate(random));

    struct Run
    {
        ParallelStats build;
        std::size_t nodes = 0;
        std::vector<TriangleBvh::Hit> hits;
    };
    const auto runs = at_thread_counts(
        [&] {
            Run run;
            reset_parallel_stats();
            const TriangleBvh bvh(mesh);
            run.build = parallel_stats();
            run.nodes = bvh.node_count();
            run.hits = closest_points(bvh, queries);
            return run;
        },
        several);
    for (std::size_t i = 0; i < runs.size(); ++i)
    {
        const int threads = static_cast<int>(i) + 1;
        // The build itself ran several blocks, on more than one thread above one thread.
        EXPECT_GE(runs[i].build.multi_block_loops, 2U) << threads << " threads";
        EXPECT_EQ(runs[i].build.max_team_threads, threads);
        if (threads == 1)
        {
            EXPECT_EQ(runs[i].build.max_threads_per_loop, 1);
        }
        else
        {
            EXPECT_GT(runs[i].build.max_threads_per_loop, 1) << threads << " threads";
        }
        if (i == 0)
            continue;
        EXPECT_EQ(runs[0].nodes, runs[i].nodes) << threads << " threads";
        ASSERT_EQ(runs[0].hits.size(), runs[i].hits.size());
        std::size_t differ = 0;
        for (std::size_t q = 0; q < queries.size(); ++q)
        {
            const TriangleBvh::Hit& a = runs[0].hits[q];
            const TriangleBvh::Hit& b = runs[i].hits[q];
            if (a.face != b.face || a.distance != b.distance || a.point != b.point ||
                a.barycentric != b.barycentric)
                ++differ;
        }
        EXPECT_EQ(differ, 0U) << threads << " threads";
    }
}

} // namespace
} // namespace pointform
