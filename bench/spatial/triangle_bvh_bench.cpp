// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// TriangleBvh on a real mesh (data/meshes/bunny_uniform.off, 17,804 triangles): build time and
// the throughput of 1M exact closest-point queries, near the surface (samples moved off it by up
// to 1% of the diagonal, the case of measuring a reconstruction) and anywhere in the bounding
// box (harder: far from the surface more boxes are within reach). Arg = threads (0 = all).

#include "pointform/core/parallel.h"
#include "pointform/io/io.h"
#include "pointform/metrics/surface_sampling.h"
#include "pointform/spatial/triangle_bvh.h"

#include <benchmark/benchmark.h>

#include <random>

namespace pointform {
namespace {

constexpr std::size_t query_count = 1000000;

const TriMesh& bunny()
{
    static const TriMesh mesh = read_mesh(PF_DATA_DIR "/meshes/bunny_uniform.off");
    return mesh;
}

/// Area-uniform samples of the bunny, each moved along a random direction by up to 1% of the
/// diagonal.
const PointCloud& near_queries()
{
    static const PointCloud cloud = [] {
        PointCloud c = sample_surface(bunny(), {.count = query_count, .seed = 1});
        const double step = 0.01 * bunny().vertices.bounds().diagonal();
        std::mt19937_64 rng(2);
        std::uniform_real_distribution<float> uni(-1.0F, 1.0F);
        for (auto& p : c.positions)
            p += Vec3f(uni(rng), uni(rng), uni(rng)) * static_cast<float>(step / std::sqrt(3.0));
        return c;
    }();
    return cloud;
}

/// Uniform points in the bounding box grown by 10% on every side.
const PointCloud& box_queries()
{
    static const PointCloud cloud = [] {
        const Aabb box = bunny().vertices.bounds();
        const Vec3d lo = box.min - 0.1 * box.size();
        const Vec3d size = 1.2 * box.size();
        PointCloud c;
        c.origin = bunny().vertices.origin;
        std::mt19937_64 rng(3);
        std::uniform_real_distribution<double> uni(0.0, 1.0);
        c.positions.resize(query_count);
        for (auto& p : c.positions)
            p = (lo + Vec3d(uni(rng) * size.x(), uni(rng) * size.y(), uni(rng) * size.z()) -
                 c.origin)
                    .cast<float>();
        return c;
    }();
    return cloud;
}

void bvh_build(benchmark::State& state)
{
    const TriMesh& mesh = bunny();
    for (auto _ : state)
    {
        const TriangleBvh bvh(mesh);
        benchmark::DoNotOptimize(bvh.node_count());
    }
    state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(mesh.face_count()));
}

void query(benchmark::State& state, const PointCloud& queries)
{
    const TriangleBvh bvh(bunny());
    set_thread_count(static_cast<int>(state.range(0)));
    for (auto _ : state)
        benchmark::DoNotOptimize(distances_to_mesh(bvh, queries));
    set_thread_count(0);
    state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(queries.size()));
}

void bvh_query_near_surface(benchmark::State& state)
{
    query(state, near_queries());
}

void bvh_query_in_box(benchmark::State& state)
{
    query(state, box_queries());
}

BENCHMARK(bvh_build)->Unit(benchmark::kMillisecond);
BENCHMARK(bvh_query_near_surface)->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(bvh_query_in_box)->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond)->UseRealTime();

} // namespace
} // namespace pointform
