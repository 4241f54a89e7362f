// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/polygonize/components.h"

#include "pointform/core/disjoint_sets.h"
#include "pointform/geometry/mesh_topology.h"
#include "pointform/geometry/shapes.h"
#include "pointform/hermite/surfels.h"
#include "pointform/implicit/point_field.h"
#include "pointform/polygonize/marching_cubes.h"
#include "pointform/spatial/triangle_bvh.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <vector>

namespace pointform {
namespace {

/// 20k samples of the unit sphere plus six clusters of 10 to 30 stray points 2 to 2.5 from its
/// centre (clear of the sphere's field): raw points, as a scanner's stray returns come.
PointCloud sphere_with_stray_clusters()
{
    PointCloud cloud = sample_shape(Shape::Sphere, {.count = 20000, .seed = 2});
    cloud.normals.clear();
    std::mt19937_64 rng(7);
    std::normal_distribution<double> gauss(0.0, 1.0);
    std::uniform_real_distribution<double> uni(0.0, 1.0);
    for (int c = 0; c < 6; ++c)
    {
        Vec3d d(gauss(rng), gauss(rng), gauss(rng));
        const Vec3d centre = d.normalized() * (2.0 + 0.5 * uni(rng));
        for (int i = 0; i < 10 + 4 * c; ++i)
            cloud.positions.emplace_back(
                (centre + 0.04 * Vec3d(gauss(rng), gauss(rng), gauss(rng))).cast<float>());
    }
    return cloud;
}

TEST(Components, StrayClustersLeaveDebrisThatIsRemoved)
{
    const PointCloud raw = sphere_with_stray_clusters();
    const PointField field(compute_surfels(raw, {.radius_scale = 1.5}).surfels);
    TriMesh mesh = marching_cubes(field, grid_over(field.bounds(), default_cell_size(field))).mesh;
    const MeshTopology before = analyze_topology(mesh);
    ASSERT_GT(before.components, 1U) << "the strays make no debris: the test tests nothing";
    const ComponentFilterReport report = remove_unsupported_components(
        mesh, field.surfels(), default_min_component_samples(raw.size()));
    EXPECT_EQ(report.components, before.components);
    EXPECT_EQ(report.min_samples, 32U);
    EXPECT_GT(report.removed_components, 0U);
    EXPECT_GT(report.removed_faces, 0U);
    // Left: the sphere alone, closed.
    const MeshTopology after = analyze_topology(mesh);
    EXPECT_EQ(after.components, 1U);
    EXPECT_EQ(report.removed_components, before.components - 1);
    EXPECT_TRUE(after.is_closed());
    EXPECT_EQ(after.euler_characteristic, 2);
    for (std::size_t v = 0; v < mesh.vertex_count(); ++v)
        ASSERT_NEAR(mesh.vertices.world(v).norm(), 1.0, 0.02);
    for (const Triangle& t : mesh.triangles)
        for (const std::uint32_t v : t)
            ASSERT_LT(v, mesh.vertex_count());
    for (const Triangle& t : mesh.triangles)
        for (const std::uint32_t v : t)
            ASSERT_LT(v, mesh.vertex_count());
}

TEST(Components, SupportIsTheNearestTrianglesCount)
{
    // Each component's support counted by exact closest points on the whole mesh: a threshold
    // at a component's support keeps it, one above removes it, every other component alike.
    const PointCloud raw = sphere_with_stray_clusters();
    const PointField field(compute_surfels(raw, {.radius_scale = 1.5}).surfels);
    const TriMesh mesh =
        marching_cubes(field, grid_over(field.bounds(), default_cell_size(field))).mesh;
    const PointCloud& samples = field.surfels();
    DisjointSets sets(mesh.vertex_count());
    for (const Triangle& t : mesh.triangles)
    {
        sets.unite(t[0], t[1]);
        sets.unite(t[0], t[2]);
    }
    std::map<std::size_t, std::size_t> support; // by root
    for (const Triangle& t : mesh.triangles)
        support[sets.find(t[0])] += 0;
    std::vector<Vec3d> queries;
    for (std::size_t i = 0; i < samples.size(); ++i)
        queries.push_back(samples.world(i));
    for (const TriangleBvh::Hit& hit : closest_points(TriangleBvh(mesh), queries))
        ++support[sets.find(mesh.triangles[hit.face.value][0])];
    ASSERT_GT(support.size(), 2U);
    std::size_t best = 0;
    for (const auto& [root, count] : support)
        best = std::max(best, count);
    for (const auto& [root, count] : support)
    {
        if (count == best)
            continue;
        for (const std::size_t threshold : {count, count + 1})
        {
            std::size_t below = 0;
            for (const auto& [other, other_count] : support)
                below += other_count < threshold && other_count != best ? 1 : 0;
            TriMesh copy = mesh;
            EXPECT_EQ(remove_unsupported_components(copy, samples, threshold).removed_components,
                      below)
                << "threshold " << threshold;
        }
    }
}

TEST(Components, SupportedComponentsStay)
{
    // Two spheres, each with half the samples: both stay, and nothing changes.
    const PointCloud samples = sample_shape(Shape::TwoSpheres, {.count = 20000, .seed = 3});
    const PointField field(compute_surfels(samples, {.radius_scale = 1.5}).surfels);
    TriMesh mesh = marching_cubes(field, grid_over(field.bounds(), default_cell_size(field))).mesh;
    const TriMesh copy = mesh;
    const ComponentFilterReport report =
        remove_unsupported_components(mesh, field.surfels(), default_min_component_samples(20000));
    EXPECT_EQ(report.components, 2U);
    EXPECT_EQ(report.removed_components, 0U);
    EXPECT_EQ(mesh.triangles, copy.triangles);
    EXPECT_EQ(mesh.vertices.positions, copy.vertices.positions);
    // A support above every component's keeps the best supported one only.
    const ComponentFilterReport all = remove_unsupported_components(mesh, field.surfels(), 1000000);
    EXPECT_EQ(all.removed_components, 1U);
    EXPECT_EQ(analyze_topology(mesh).components, 1U);
    // 0 keeps everything.
    TriMesh again = copy;
    EXPECT_EQ(remove_unsupported_components(again, field.surfels(), 0).removed_components, 0U);
    EXPECT_EQ(again.triangles, copy.triangles);
    EXPECT_EQ(default_min_component_samples(1000), 32U);
    EXPECT_EQ(default_min_component_samples(1000000), 1000U);
}

/// 10k samples of the unit sphere and `sprayed` points spread evenly through the cube of side 4
/// around it (a spray of stray returns), raw; and beside it, when `sparse` > 0, a second unit
/// sphere 3.5 away sampled by `sparse` points.
PointCloud sphere_with_spray(std::size_t sprayed, std::size_t sparse)
{
    PointCloud cloud = sample_shape(Shape::Sphere, {.count = 10000, .seed = 2});
    cloud.normals.clear();
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<float> uni(-2.0F, 2.0F);
    for (std::size_t i = 0; i < sprayed; ++i)
        cloud.positions.emplace_back(uni(rng), uni(rng), uni(rng));
    if (sparse > 0)
        for (const Vec3f& p : sample_shape(Shape::Sphere, {.count = sparse, .seed = 5}).positions)
            cloud.positions.push_back(p + Vec3f(3.5F, 0.0F, 0.0F));
    return cloud;
}

TEST(Components, SheetsOverAScatteredSprayAreRemoved)
{
    // The spray's samples reach far and their neighbourhoods fill a volume: the sheets the field
    // makes over them are held up by hundreds of them (more than min_samples), but by scattered
    // samples only. (A blending field leaves a spray's samples out of its blend, and makes no
    // such sheets: the field of nearest centroid planes, which does not, makes them.)
    const PointField field(
        compute_surfels(sphere_with_spray(200, 0), {.radius_scale = 1.5}).surfels,
        {.fit = PlaneFit::Centroid});
    TriMesh mesh = marching_cubes(field, grid_over(field.bounds(), default_cell_size(field))).mesh;
    ASSERT_GT(analyze_topology(mesh).components, 1U) << "no sheets: the test tests nothing";
    TriMesh again = mesh;
    const ComponentFilterReport report =
        remove_unsupported_components(mesh, field.surfels(), 32, &field.tree());
    ASSERT_GE(report.scattered_components, 1U);
    EXPECT_EQ(report.removed_components, report.components - 1);
    const MeshTopology after = analyze_topology(mesh);
    EXPECT_EQ(after.components, 1U);
    EXPECT_TRUE(after.is_closed());
    EXPECT_EQ(after.euler_characteristic, 2);
    // (Nearest planes: within about a spacing, 0.035, of the sphere.)
    for (std::size_t v = 0; v < mesh.vertex_count(); ++v)
        ASSERT_NEAR(mesh.vertices.world(v).norm(), 1.0, 0.035);
    // The same without a tree given (one is built).
    EXPECT_EQ(remove_unsupported_components(again, field.surfels(), 32).scattered_components,
              report.scattered_components);
    EXPECT_EQ(again.triangles, mesh.triangles);
}

TEST(Components, ASparselySampledObjectIsNotScattered)
{
    // A second sphere sampled by 250 points (40 times more sparsely: its reach over four times
    // the cloud's median, but its samples on a sheet) stays, as a noisy one sampled as densely
    // as the rest does (SupportedComponentsStay).
    const PointField field(
        compute_surfels(sphere_with_spray(0, 250), {.radius_scale = 1.5}).surfels);
    TriMesh mesh = marching_cubes(field, grid_over(field.bounds(), default_cell_size(field))).mesh;
    ASSERT_EQ(analyze_topology(mesh).components, 2U);
    const TriMesh copy = mesh;
    const ComponentFilterReport report =
        remove_unsupported_components(mesh, field.surfels(), 32, &field.tree());
    EXPECT_EQ(report.removed_components, 0U);
    EXPECT_EQ(report.scattered_components, 0U);
    EXPECT_EQ(mesh.triangles, copy.triangles);
}

} // namespace
} // namespace pointform
