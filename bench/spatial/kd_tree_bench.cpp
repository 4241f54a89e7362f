// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// k-nearest-neighbour throughput on N samples of a sphere, queried in random and Morton order.

#include "pointform/geometry/shapes.h"
#include "pointform/spatial/kd_tree.h"
#include "pointform/spatial/spatial_sort.h"

#include <benchmark/benchmark.h>

namespace pointform {
namespace {

const PointCloud& sphere(std::size_t n)
{
    static std::size_t cached_n = 0;
    static PointCloud cloud;
    if (cached_n != n)
    {
        cloud = sample_shape(Shape::Sphere, {.count = n, .seed = 1});
        cached_n = n;
    }
    return cloud;
}

void knn_random_order(benchmark::State& state)
{
    const auto& cloud = sphere(static_cast<std::size_t>(state.range(0)));
    const KdTree tree(cloud.positions);
    for (auto _ : state)
        benchmark::DoNotOptimize(knn_batch(tree, cloud.positions, 16));
    state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(cloud.size()));
}

void knn_morton_order(benchmark::State& state)
{
    const auto& cloud = sphere(static_cast<std::size_t>(state.range(0)));
    const auto order = spatial_order(cloud.positions);
    std::vector<Vec3f> sorted;
    sorted.reserve(order.size());
    for (const auto i : order)
        sorted.push_back(cloud.positions[i]);
    const KdTree tree(sorted);
    for (auto _ : state)
        benchmark::DoNotOptimize(knn_batch(tree, sorted, 16));
    state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(cloud.size()));
}

void build_tree(benchmark::State& state)
{
    const auto& cloud = sphere(static_cast<std::size_t>(state.range(0)));
    for (auto _ : state)
    {
        const KdTree tree(cloud.positions);
        benchmark::DoNotOptimize(tree.size());
    }
    state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(cloud.size()));
}

BENCHMARK(build_tree)->Arg(10000)->Arg(100000)->Arg(1000000)->Unit(benchmark::kMillisecond);
BENCHMARK(knn_random_order)->Arg(10000)->Arg(100000)->Arg(1000000)->Unit(benchmark::kMillisecond);
BENCHMARK(knn_morton_order)->Arg(10000)->Arg(100000)->Arg(1000000)->Unit(benchmark::kMillisecond);

} // namespace
} // namespace pointform
