// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// Point-field evaluation and sparse marching cubes on a 1M-sample sphere (exact normals, radii
// 1.5 × the 16th neighbour's distance). Run single-threaded for per-core throughput:
//   OMP_NUM_THREADS=1 build/bench/bench/implicit/implicit_bench

#include "pointform/core/parallel.h"
#include "pointform/geometry/shapes.h"
#include "pointform/hermite/radius.h"
#include "pointform/implicit/operators.h"
#include "pointform/implicit/point_field.h"
#include "pointform/implicit/primitives.h"
#include "pointform/polygonize/marching_cubes.h"
#include "pointform/spatial/kd_tree.h"
#include "pointform/spatial/spatial_sort.h"

#include <benchmark/benchmark.h>

#include <memory>
#include <random>

namespace pointform {
namespace {

PointCloud million_surfels()
{
    PointCloud cloud = sample_shape(Shape::Sphere, {.count = 1000000, .seed = 1});
    cloud.normals.resize(cloud.size());
    for (std::size_t i = 0; i < cloud.size(); ++i)
    {
        cloud.normals[i] = cloud.positions[i].normalized();
    }
    const KdTree tree(cloud.positions);
    cloud.radii = influence_radii(knn_batch(tree, cloud.positions, 17), 1.5);
    return cloud;
}

const PointCloud& surfels()
{
    static const PointCloud cloud = million_surfels();
    return cloud;
}

/// Queries within ±`half_width` of the unit sphere, in Morton order when `coherent` (as
/// polygonization asks: cell by cell along the surface) or in random order.
std::vector<Vec3d> near_surface_queries(std::size_t n, bool coherent, double half_width)
{
    std::mt19937_64 rng(3);
    std::normal_distribution<double> gauss;
    std::uniform_real_distribution<double> shell(1.0 - half_width, 1.0 + half_width);
    std::vector<Vec3d> points(n);
    for (Vec3d& p : points)
    {
        p = Vec3d(gauss(rng), gauss(rng), gauss(rng)).normalized() * shell(rng);
    }
    if (!coherent)
    {
        return points;
    }
    std::vector<Vec3f> as_float(n);
    for (std::size_t i = 0; i < n; ++i)
    {
        as_float[i] = points[i].cast<float>();
    }
    std::vector<Vec3d> sorted(n);
    const std::vector<std::uint32_t> order = spatial_order(as_float);
    for (std::size_t i = 0; i < n; ++i)
    {
        sorted[i] = points[order[i]];
    }
    return sorted;
}

void BM_FieldEvaluate(benchmark::State& state)
{
    const auto fit = static_cast<PlaneFit>(state.range(0));
    const bool coherent = state.range(1) != 0;
    const bool one_cell = state.range(2) != 0;
    const PointField field(surfels(), {.fit = fit});
    // Either within one default marching-cubes cell of the surface (where polygonization and
    // projection evaluate), or within ±2% of the radius (about 6 sample spacings, mostly
    // beyond the influence radii).
    const double half_width = one_cell ? default_cell_size(field) : 0.02;
    const std::vector<Vec3d> points = near_surface_queries(1 << 20, coherent, half_width);
    std::vector<FieldSample> out(points.size());
    for (auto _ : state)
    {
        field.evaluate(points, out);
        benchmark::DoNotOptimize(out.data());
    }
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * points.size()));
    state.SetLabel(std::string(to_string(fit)) + (one_cell ? ", ±1 cell" : ", ±2%") +
                   (coherent ? ", Morton order, " : ", random order, ") +
                   std::to_string(thread_count()) + " thread(s)");
}
BENCHMARK(BM_FieldEvaluate)
    ->ArgsProduct({{static_cast<int>(PlaneFit::Raw), static_cast<int>(PlaneFit::Centroid),
                    static_cast<int>(PlaneFit::Blend), static_cast<int>(PlaneFit::Quadric)},
                   {1, 0},
                   {1, 0}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

/// BM_FieldEvaluate's queries one evaluate() call at a time (the same values as the batch, which
/// answers coherent queries near the samples together).
void BM_FieldEvaluateOneByOne(benchmark::State& state)
{
    const auto fit = static_cast<PlaneFit>(state.range(0));
    const PointField field(surfels(), {.fit = fit});
    const std::vector<Vec3d> points = near_surface_queries(1 << 20, true, default_cell_size(field));
    std::vector<FieldSample> out(points.size());
    for (auto _ : state)
    {
        for (std::size_t i = 0; i < points.size(); ++i)
        {
            out[i] = field.evaluate(points[i]);
        }
        benchmark::DoNotOptimize(out.data());
    }
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * points.size()));
    state.SetLabel(std::string(to_string(fit)) + ", ±1 cell, Morton order, one by one");
}
BENCHMARK(BM_FieldEvaluateOneByOne)
    ->Arg(static_cast<int>(PlaneFit::Raw))
    ->Arg(static_cast<int>(PlaneFit::Quadric))
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

/// The field's construction on the 1M-sample sphere: each sample's local surface from its
/// neighbours (16 for the centroid planes, 48 for the quadrics) and the point grid.
void BM_FieldBuild(benchmark::State& state)
{
    const auto fit = static_cast<PlaneFit>(state.range(0));
    const PointCloud& cloud = surfels();
    for (auto _ : state)
    {
        const PointField field(cloud, {.fit = fit});
        benchmark::DoNotOptimize(field.estimated_area());
    }
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * cloud.size()));
    state.SetLabel(std::string(to_string(fit)) + ", " + std::to_string(thread_count()) +
                   " thread(s)");
}
BENCHMARK(BM_FieldBuild)
    ->Arg(static_cast<int>(PlaneFit::Raw))
    ->Arg(static_cast<int>(PlaneFit::Blend))
    ->Arg(static_cast<int>(PlaneFit::Quadric))
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_MarchingCubes512(benchmark::State& state)
{
    const PointField field(surfels());
    const double cell = cell_for_resolution(surfels().bounds(), 512);
    std::size_t faces = 0;
    for (auto _ : state)
    {
        const auto result = marching_cubes(field, grid_over(field.bounds(), cell));
        faces = result.mesh.face_count();
        benchmark::DoNotOptimize(faces);
    }
    state.counters["faces"] = static_cast<double>(faces);
}
BENCHMARK(BM_MarchingCubes512)->Unit(benchmark::kSecond)->UseRealTime()->Iterations(1);

/// A sampled shape with exact normals and automatic radii, as an oriented scan would come in.
PointCloud scan_of(Shape shape, std::size_t count, const Vec3d& offset)
{
    PointCloud cloud = sample_shape(shape, {.count = count, .seed = 7});
    cloud.origin = offset;
    cloud.normals.resize(cloud.size());
    for (std::size_t i = 0; i < cloud.size(); ++i)
    {
        const Vec3f p = cloud.positions[i];
        // Sphere: radial; torus: away from the core circle.
        const Vec3f core =
            shape == Shape::Torus ? Vec3f(p.x(), p.y(), 0.0F).normalized() : Vec3f::Zero();
        cloud.normals[i] = (p - core).normalized();
    }
    const KdTree tree(cloud.positions);
    cloud.radii = influence_radii(knn_batch(tree, cloud.positions, 17), 1.5);
    return cloud;
}

/// Issue 4's scene: two 100k-sample scans (a sphere and a torus through it) and three
/// primitives, polygonized at 256 cells along the longest side. `with_fields` times the two
/// point fields' construction too (as `pointform model` runs it on scans that carry normals).
void BM_Scene256(benchmark::State& state)
{
    const bool with_fields = state.range(0) != 0;
    static const PointCloud sphere = scan_of(Shape::Sphere, 100000, Vec3d(0.0, 0.0, 0.0));
    static const PointCloud torus = scan_of(Shape::Torus, 100000, Vec3d(0.9, 0.0, 0.0));
    std::size_t faces = 0;
    auto scene = [&] {
        auto a = std::make_shared<const PointField>(sphere);
        auto b = std::make_shared<const PointField>(torus);
        return make_difference(
            make_union({make_smooth_union(a, b, 0.1), make_sphere(Vec3d(0.0, 0.0, 1.0), 0.3)}),
            make_union({make_box(Vec3d(-0.2, -1.5, 0.3), Vec3d(0.2, 1.5, 1.5)),
                        make_cylinder(Vec3d(-2.0, 0.0, 0.0), Vec3d(2.0, 0.0, 0.0), 0.15)}));
    };
    std::shared_ptr<const Field> prebuilt = with_fields ? nullptr : scene();
    for (auto _ : state)
    {
        const std::shared_ptr<const Field> field = with_fields ? scene() : prebuilt;
        const Aabb box = field->bounds();
        const auto result = marching_cubes(*field, grid_over(box, cell_for_resolution(box, 256)));
        faces = result.mesh.face_count();
        benchmark::DoNotOptimize(faces);
    }
    state.counters["faces"] = static_cast<double>(faces);
    state.SetLabel(std::string(with_fields ? "fields + " : "") + "marching cubes, " +
                   std::to_string(thread_count()) + " thread(s)");
}
BENCHMARK(BM_Scene256)->Arg(0)->Arg(1)->Unit(benchmark::kSecond)->UseRealTime()->Iterations(1);

} // namespace
} // namespace pointform
