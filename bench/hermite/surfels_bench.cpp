// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// Level 1 -> 2 throughput together with quality: points per second of compute_surfels, and the
// fraction of normals oriented like the exact outward normals, on clean and noisy shapes.

#include "pointform/geometry/shapes.h"
#include "pointform/hermite/surfels.h"

#include <benchmark/benchmark.h>

namespace pointform {
namespace {

void surfels(benchmark::State& state, Shape shape, double noise, std::size_t holes)
{
    const PointCloud truth = sample_shape(shape, {.count = static_cast<std::size_t>(state.range(0)),
                                                  .seed = 1,
                                                  .noise = noise,
                                                  .holes = holes});
    PointCloud input = truth;
    input.normals.clear();
    double oriented = 0.0;
    for (auto _ : state)
    {
        const SurfelResult result = compute_surfels(input);
        std::size_t good = 0;
        for (std::size_t i = 0; i < truth.size(); ++i)
            if (result.surfels.normals[i].dot(truth.normals[i]) > 0.0F)
                ++good;
        oriented = static_cast<double>(good) / static_cast<double>(truth.size());
    }
    state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(truth.size()));
    state.counters["oriented_pct"] = 100.0 * oriented;
}

BENCHMARK_CAPTURE(surfels, sphere_clean, Shape::Sphere, 0.0, 0)
    ->Arg(100000)
    ->Arg(1000000)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(surfels, torus_noisy_holes, Shape::Torus, 0.002, 8)
    ->Arg(100000)
    ->Arg(1000000)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(surfels, two_spheres_clean, Shape::TwoSpheres, 0.0, 0)
    ->Arg(100000)
    ->Unit(benchmark::kMillisecond);

} // namespace
} // namespace pointform
