// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/polygonize/reconstruct.h"

#include "pointform/core/error.h"
#include "pointform/geometry/mesh_topology.h"
#include "pointform/geometry/shapes.h"
#include "pointform/hermite/surfels.h"
#include "pointform/implicit/primitives.h"
#include "pointform/polygonize/marching_cubes.h"

#include "support/test_meshes.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <string>
#include <vector>

namespace pointform {
namespace {

double sphere_error(const TriMesh& mesh)
{
    double error = 0.0;
    for (std::size_t v = 0; v < mesh.vertex_count(); ++v)
        error = std::max(error, std::abs(mesh.vertices.world(v).norm() - 1.0));
    return error;
}

PointCloud sphere_surfels(std::size_t count)
{
    PointCloud raw = sample_shape(Shape::Sphere, {.count = count, .seed = 41});
    raw.normals.clear();
    return surfels_from_samples(std::move(raw)).surfels;
}

TEST(Reconstruct, SampledSphereStopsByTheRuleWithinTheBudgetOnTheSphere)
{
    const ReconstructReport report = reconstruct(sphere_surfels(20000));
    const SemiRegularReport& semi = report.semi_regular;
    const MultiresMesh& hierarchy = semi.hierarchy;
    ASSERT_TRUE(semi.base.has_value());
    EXPECT_TRUE(semi.base->topology_kept);
    EXPECT_TRUE(semi.measured);
    EXPECT_FALSE(semi.exact_levels);
    EXPECT_EQ(semi.level_cap, default_max_level);
    EXPECT_EQ(semi.sample_count, 20000U);
    // The automatic rule stops within the vertex budget (the samples).
    EXPECT_LE(hierarchy.vertex_count(), 20000U);
    EXPECT_EQ(semi.refinement.levels.size(), hierarchy.finest_level());
    EXPECT_GE(hierarchy.finest_level(), 1U);
    const TriMesh finest = hierarchy.level_mesh(hierarchy.finest_level());
    const MeshTopology topo = analyze_topology(finest);
    EXPECT_TRUE(topo.is_closed());
    EXPECT_EQ(topo.euler_characteristic, 2);
    EXPECT_LT(sphere_error(finest), semi.refinement.sampling_density);
    // Every stage reported, in order.
    ASSERT_EQ(report.stage_seconds.size(), 6U);
    EXPECT_EQ(report.stage_seconds.front().first, "field");
    EXPECT_EQ(report.stage_seconds[3].first, "handles");
    EXPECT_EQ(report.handles.genus_before, 0U);
    EXPECT_EQ(report.stage_seconds.back().first, "refinement");
    EXPECT_GT(report.intermediate_faces, semi.base->faces);
}

/// Checks that a reconstruction of samples of the unit sphere is closed, in one piece, of genus 0
/// and within `tolerance` of the sphere (default: the samples' density).
void expect_unit_sphere(const ReconstructReport& report, double tolerance = 0.0)
{
    const MultiresMesh& hierarchy = report.semi_regular.hierarchy;
    const TriMesh finest = hierarchy.level_mesh(hierarchy.finest_level());
    const MeshTopology topo = analyze_topology(finest);
    EXPECT_TRUE(topo.is_closed());
    EXPECT_EQ(topo.euler_characteristic, 2);
    EXPECT_EQ(topo.components, 1U);
    EXPECT_LT(sphere_error(finest),
              tolerance > 0.0 ? tolerance : report.semi_regular.refinement.sampling_density);
}

/// Every stage that reports progress stops when the callback asks it to, by throwing Cancelled
/// (the Python module's Ctrl-C relies on it): asked at each stage's first report and at its
/// last in turn, from raw points (the normals' stages too) to the refinement's last level, with
/// the levels given and with the automatic stop.
TEST(Reconstruct, EveryStageStopsWhenAsked)
{
    PointCloud raw = sample_shape(Shape::Torus, {.count = 6000, .seed = 7});
    raw.normals.clear();
    for (const bool exact : {true, false})
    {
        ReconstructOptions options;
        if (exact)
            options.semi_regular.levels = 2; // else the automatic stop
        // Runs the pipeline as the Python module does, with `progress`.
        const auto run = [&](const ProgressCallback& progress) {
            SurfelsFromSamples input = surfels_from_samples(raw, {.progress = progress});
            ReconstructOptions with_progress = options;
            with_progress.progress = progress;
            return reconstruct(std::move(input.surfels), with_progress);
        };
        // The stages' names, in the order they first reported.
        std::vector<std::string> stages;
        (void)run([&](std::string_view stage, double) {
            if (std::find(stages.begin(), stages.end(), stage) == stages.end())
                stages.emplace_back(stage);
            return true;
        });
        ASSERT_GE(stages.size(), 6U);
        // Asked at each stage's first report, and at its report of the stage done (fraction 1;
        // how many reports come between depends on the threads).
        for (const std::string& stop_at : stages)
            for (const bool at_end : {false, true})
            {
                bool asked = false;
                EXPECT_THROW((void)run([&](std::string_view stage, double fraction) {
                                 asked =
                                     asked || (stage == stop_at && (!at_end || fraction >= 1.0));
                                 return !asked;
                             }),
                             Cancelled)
                    << "stage " << stop_at << (at_end ? ", at its end" : ", at its start");
                EXPECT_TRUE(asked) << "stage " << stop_at;
            }
        std::string names;
        for (const std::string& stage : stages)
            names += (names.empty() ? "" : ", ") + stage;
        RecordProperty(exact ? "stages_exact" : "stages_automatic", names);
    }
}

TEST(Reconstruct, TheIntermediateMeshHasAFewFacesPerBaseFace)
{
    // The base mesh is simplified from a marching-cubes mesh of about
    // intermediate_faces_per_base_face faces per base face, on a grid coarser than the field's
    // where that would make more; the mesh is as closed and as close to the sphere.
    const ReconstructReport report = reconstruct(sphere_surfels(20000));
    const SemiRegularReport& semi = report.semi_regular;
    ASSERT_TRUE(semi.base.has_value());
    EXPECT_GT(report.coarsening, 1.0);
    const double per_target = static_cast<double>(report.intermediate_faces) /
                              static_cast<double>(semi.base->target_faces);
    RecordProperty("per_target", std::to_string(per_target));
    EXPECT_GT(per_target, 0.5 * intermediate_faces_per_base_face);
    EXPECT_LT(per_target, 2.0 * intermediate_faces_per_base_face);
    expect_unit_sphere(report);
    // A picked face count sets the limit: 8 of the intermediate's faces each, and never fewer
    // faces than the base mesh asks for.
    const PointField field(sphere_surfels(20000), {});
    const double cell = default_cell_size(field);
    SemiRegularOptions picked;
    picked.base_faces = 500;
    EXPECT_DOUBLE_EQ(intermediate_face_limit(field, cell, picked, 20000),
                     intermediate_faces_per_base_face * 500.0);
    picked.base_faces = 1000000;
    EXPECT_DOUBLE_EQ(intermediate_face_limit(field, cell, picked, 20000), max_intermediate_faces);
}

// A scan with one stray return far away (10^6 radii off the sphere): the stray was the whole
// field's bounds and made marching cubes' cells larger than the sphere ("no triangles"); it is
// left out (surfels_from_samples()), and the sphere comes out as without it.
// A clean plate 2.2 sample spacings thick (30k samples): the neighbourhood of a face's sample
// reaches the far face, and with principal-component normals a sixth of them turned more than
// 26° and 1% were oriented the wrong way (at 100k samples the field's surface had 293 handles
// through the plate, 292 of them cut, a Hausdorff distance of 2.1% of the diagonal). With the
// normals refitted to the nearest neighbours by a parallel sheet (NeighbourWeights::Local) the
// plate is one closed surface, its rim rounded by under two spacings, its faces' vertices within
// a fifth of the thickness of the box's but for a few dimples (45 of 7,920 here; `pointform
// reconstruct` of these samples 29 of 8,044, where the principal components left 1,021 of
// 18,172 and cut 10 handles).
TEST(Reconstruct, AThinCleanPlateIsOneClosedSurface)
{
    constexpr std::size_t count = 30000;
    const double thickness = 2.2 * std::sqrt(8.3 / static_cast<double>(count));
    PointCloud points =
        sample_shape(Shape::Plate, {.count = count, .seed = 12, .thickness = thickness});
    points.normals.clear();
    const ReconstructReport report = reconstruct(surfels_from_samples(points).surfels);
    const MultiresMesh& hierarchy = report.semi_regular.hierarchy;
    const TriMesh mesh = hierarchy.level_mesh(hierarchy.finest_level());
    const MeshTopology topology = analyze_topology(mesh);
    EXPECT_EQ(topology.components, 1U);
    EXPECT_EQ(topology.boundary_loops, 0U);
    EXPECT_EQ(topology.euler_characteristic, 2);
    EXPECT_EQ(report.handles.cuts, 0U);
    const double spacing = std::sqrt(8.3 / static_cast<double>(count));
    const Vec3d half(1.0, 1.0, 0.5 * thickness);
    double worst = 0.0;
    std::size_t face_vertices = 0;
    std::size_t off_faces = 0; // over the faces, 3 spacings or more from the rim
    for (std::size_t v = 0; v < mesh.vertex_count(); ++v)
    {
        // Distance to the box's surface: outside, to the box; inside, to the nearest face.
        const Vec3d p = mesh.vertices.world(v);
        const Vec3d q = p.cwiseAbs() - half;
        const double outside = q.cwiseMax(0.0).norm();
        const double distance = outside > 0.0 ? outside : -q.maxCoeff();
        worst = std::max(worst, distance);
        if (std::max(std::abs(p.x()), std::abs(p.y())) < 1.0 - 3.0 * spacing)
        {
            ++face_vertices;
            off_faces += distance > 0.2 * thickness ? 1U : 0U;
        }
    }
    EXPECT_LT(worst, 2.0 * spacing); // the rim's two edges, rounded (1.6 spacings here)
    EXPECT_LT(off_faces, face_vertices / 100) << off_faces << " of " << face_vertices;
}

TEST(Reconstruct, AStrayPointFarAwayDoesNotSpoilTheSurface)
{
    PointCloud points = sample_shape(Shape::Sphere, {.count = 20000, .seed = 31});
    points.normals.clear();
    points.radii.clear();
    points.positions.emplace_back(1e6F, 0.0F, 0.0F);
    const SurfelsFromSamples surfels = surfels_from_samples(points);
    EXPECT_EQ(surfels.isolated, 1U);
    expect_unit_sphere(reconstruct(surfels.surfels));
}

// Clusters of 1 to 15 stray returns a fifth to a half of the radius off a scanned sphere (as a
// real scanner leaves them near an object): each stray's row reaches the sphere, so its radius
// spans the gap and its plane, fitted to a few strays, made sheets hanging off the sphere.
// Every stray is isolated and left out; the sphere comes out closed, in one piece, as close to
// the truth as its sampling density.
TEST(Reconstruct, ClustersOfStraysDoNotSpoilTheSurface)
{
    PointCloud points = sample_shape(Shape::Sphere, {.count = 20000, .seed = 32});
    points.normals.clear();
    points.radii.clear();
    std::mt19937 random(5);
    std::normal_distribution<float> gauss;
    std::uniform_real_distribution<float> unit(0.0F, 1.0F);
    std::size_t strays = 0;
    for (int cluster = 0; cluster < 12; ++cluster)
    {
        const Vec3f direction = Vec3f(gauss(random), gauss(random), gauss(random)).normalized();
        const Vec3f centre = direction * (1.2F + 0.3F * unit(random));
        const int count = 1 + cluster;
        for (int i = 0; i < count; ++i)
            points.positions.push_back(centre +
                                       0.02F * Vec3f(gauss(random), gauss(random), gauss(random)));
        strays += static_cast<std::size_t>(count);
    }
    const SurfelsFromSamples surfels = surfels_from_samples(points);
    EXPECT_EQ(surfels.isolated, strays);
    expect_unit_sphere(reconstruct(surfels.surfels));
}

// A spray of stray returns through the space around a scanned sphere (150 points spread evenly
// through the cube of side 6 around it): far from each other and from the sphere, none isolated,
// each with a radius that reaches its fellows, so the field made a sheet through them many times
// the sphere's area, held up by more samples than debris needs. The spray's samples are strays
// (PointField::stray_samples()), from which marching cubes does not start: the sheet is never
// made (it was, and then removed as debris held up by scattered samples), and the sphere comes
// out as without them.
TEST(Reconstruct, ASprayOfStraysThroughSpaceDoesNotSpoilTheSurface)
{
    PointCloud points = sample_shape(Shape::Sphere, {.count = 5000, .seed = 33});
    points.normals.clear();
    points.radii.clear();
    const ReconstructReport clean = reconstruct(surfels_from_samples(points).surfels);
    std::mt19937 random(9);
    std::uniform_real_distribution<float> side(-3.0F, 3.0F);
    for (int i = 0; i < 150; ++i)
        points.positions.emplace_back(side(random), side(random), side(random));
    const SurfelsFromSamples surfels = surfels_from_samples(points);
    const ReconstructReport report = reconstruct(surfels.surfels);
    EXPECT_EQ(clean.stray_samples, 0U);
    // Of 150, and a few lie near the sphere; those standing off it are left out before.
    EXPECT_GE(report.stray_samples + surfels.off_surface, 135U);
    EXPECT_LE(report.stray_samples + surfels.off_surface, 150U);
    EXPECT_LT(report.intermediate_faces, clean.intermediate_faces + clean.intermediate_faces / 10);
    expect_unit_sphere(report);
}

// Stray returns near a scanned sphere, outside and inside it (200, 1%: 0.06-0.2 off it, 2.5-8
// spacings of its samples), the nearer no farther from the sphere than a sample of it reaches,
// so not isolated. Their fits raised tents off the sphere as high as they stand (up to 0.14 at
// 20k samples); those off the surface (off_surface_samples()) are left out, the farther ones
// isolated, and the sphere comes out closed, in one piece, as close to the truth as its
// sampling density. (A stray nearer than two spacings is kept, and its tent stays as high.)
TEST(Reconstruct, StraysNearTheSurfaceRaiseNoTents)
{
    PointCloud points = sample_shape(Shape::Sphere, {.count = 20000, .seed = 34});
    points.normals.clear();
    points.radii.clear();
    std::mt19937 random(11);
    std::normal_distribution<float> gauss;
    std::uniform_real_distribution<float> off(0.06F, 0.2F);
    for (int i = 0; i < 200; ++i)
    {
        const Vec3f direction = Vec3f(gauss(random), gauss(random), gauss(random)).normalized();
        points.positions.push_back(direction * (1.0F + (i % 2 == 0 ? 1.0F : -1.0F) * off(random)));
    }
    const SurfelsFromSamples surfels = surfels_from_samples(points);
    EXPECT_GT(surfels.off_surface, 60U);
    EXPECT_GE(surfels.off_surface + surfels.isolated, 190U);
    expect_unit_sphere(reconstruct(surfels.surfels));
}

// Coordinates quantized by a scanner or a file format (here a sphere's 30k samples rounded to a
// grid of 0.03 of its radius, about the samples' spacing): many samples fall on one place, and
// a place with more samples than a row had neighbours of no reach and a radius of 0 ("the cloud
// has no samples"). Each place is one surfel, and the sphere comes out closed, in one piece,
// within the rounding of the truth.
TEST(Reconstruct, QuantizedCoordinatesGiveTheSurface)
{
    PointCloud points = sample_shape(Shape::Sphere, {.count = 30000, .seed = 33});
    points.normals.clear();
    points.radii.clear();
    constexpr float step = 0.03F;
    for (Vec3f& p : points.positions)
        p = (p / step).array().round().matrix() * step;
    const SurfelsFromSamples surfels = surfels_from_samples(points);
    EXPECT_GT(surfels.copies, 1000U);
    expect_unit_sphere(reconstruct(surfels.surfels), step);
}

// The samples are put in Morton order before the field: the same samples in any order (and the
// same storage origin) give the same mesh, bit for bit.
TEST(Reconstruct, TheSamplesOrderDoesNotChangeTheMesh)
{
    const PointCloud surfels = sphere_surfels(20000);
    PointCloud shuffled = surfels;
    std::vector<std::uint32_t> order(surfels.size());
    std::iota(order.begin(), order.end(), 0U);
    std::shuffle(order.begin(), order.end(), std::mt19937(8));
    reorder_points(shuffled, order);
    ASSERT_NE(shuffled.positions, surfels.positions);
    const auto finest = [](const PointCloud& samples) {
        const ReconstructReport report = reconstruct(samples);
        const MultiresMesh& hierarchy = report.semi_regular.hierarchy;
        return hierarchy.level_mesh(hierarchy.finest_level());
    };
    const TriMesh a = finest(surfels);
    const TriMesh b = finest(shuffled);
    EXPECT_GT(a.face_count(), 1000U);
    EXPECT_EQ(a.triangles, b.triangles);
    EXPECT_EQ(a.vertices.positions, b.vertices.positions);
}

TEST(Reconstruct, ExactLevelsAndTheBaseFaceTarget)
{
    ReconstructOptions options;
    options.semi_regular.levels = 2;
    options.semi_regular.base_faces = 150;
    const ReconstructReport report = reconstruct(sphere_surfels(8000), options);
    const SemiRegularReport& semi = report.semi_regular;
    EXPECT_TRUE(semi.exact_levels);
    EXPECT_EQ(semi.hierarchy.finest_level(), 2U);
    EXPECT_EQ(semi.refinement.stop, RefineStop::LevelCap);
    EXPECT_EQ(semi.base->target_faces, 150U);
    EXPECT_EQ(semi.hierarchy.face_count(2), 16 * semi.hierarchy.face_count(0));

    ReconstructOptions too_deep;
    too_deep.semi_regular.levels = max_exact_levels + 1;
    EXPECT_THROW((void)reconstruct(sphere_surfels(2000), too_deep), InvalidInput);
    ReconstructOptions too_many;
    too_many.semi_regular.base_faces = 100000000;
    EXPECT_THROW((void)reconstruct(sphere_surfels(2000), too_many), InvalidInput);
}

TEST(Reconstruct, PaperRuleDropsAStalledLevelAndTheMemoryCapHolds)
{
    // Outliers far off the sphere keep the Hausdorff distance from falling: under the paper's
    // rule a level that lowers it by less than 5% is measured and not kept.
    PointCloud surfels = sphere_surfels(6000);
    for (std::size_t i = 0; i < 5; ++i)
    {
        surfels.positions.push_back(Vec3f(0.0F, 0.0F, 1.3F + 0.01F * static_cast<float>(i)));
        surfels.normals.emplace_back(0.0F, 0.0F, 1.0F);
        surfels.radii.push_back(0.001F);
    }
    ReconstructOptions options;
    options.semi_regular.stop_rule = StopRule::Paper;
    options.min_component_samples = 0;
    const ReconstructReport report = reconstruct(std::move(surfels), options);
    const SemiRegularReport& semi = report.semi_regular;
    EXPECT_EQ(semi.refinement.stop, RefineStop::Stalled);
    ASSERT_TRUE(semi.refinement.dropped.has_value());
    EXPECT_EQ(semi.refinement.dropped->level, semi.hierarchy.finest_level() + 1);

    EXPECT_EQ(affordable_level(100, 3), 3U);
    // 2^32 faces do not fit in 32-bit indices, whatever the memory.
    EXPECT_LT(affordable_level(std::size_t{1} << 20, 8), 6U);
    EXPECT_THROW(check_refinement_memory(std::size_t{1} << 20, 8), InvalidInput);
}

TEST(SemiRegularMesh, WithoutSamplesRefinesExactlyToTheLevels)
{
    // A modeled surface: the marching-cubes mesh of an exact sphere, no samples.
    const auto sphere = make_sphere(Vec3d::Zero(), 1.0);
    const MarchingCubesResult mc = marching_cubes(*sphere, grid_over(sphere->bounds(), 0.05));
    SemiRegularOptions options;
    options.levels = 2;
    const SemiRegularReport report = semi_regular_mesh(mc.mesh, *sphere, nullptr, options, 16);
    EXPECT_FALSE(report.measured);
    EXPECT_EQ(report.hierarchy.finest_level(), 2U);
    EXPECT_EQ(report.refinement.levels.size(), 2U);
    EXPECT_FALSE(report.refinement.levels[0].hausdorff.has_value());
    const TriMesh finest = report.hierarchy.level_mesh(2);
    const VertexResidual residual = field_residual_at_vertices(finest, *sphere);
    EXPECT_EQ(residual.defined, finest.vertex_count());
    EXPECT_LT(residual.max, 1e-3);
    EXPECT_LT(sphere_error(finest), 1e-3);
    // Without samples the levels are needed.
    EXPECT_THROW((void)semi_regular_mesh(mc.mesh, *sphere, nullptr, {}, 16), InvalidInput);
}

TEST(Remesh, AnIcosphereBecomesASemiRegularMeshOnIt)
{
    const TriMesh input = test::icosphere(4); // 5120 faces
    RemeshOptions options;
    options.semi_regular.levels = 1;
    const RemeshReport report = remesh(input, options);
    const SemiRegularReport& semi = report.semi_regular;
    EXPECT_EQ(report.vertex_surfels, input.vertex_count());
    EXPECT_EQ(report.area_surfels, input.vertex_count());
    EXPECT_EQ(semi.base->target_faces, default_remesh_base_faces(input));
    EXPECT_EQ(default_remesh_base_faces(input), 1280U);
    const TriMesh finest = semi.hierarchy.level_mesh(1);
    EXPECT_TRUE(analyze_topology(finest).is_closed());
    // Within the chord error of the input's facets (edge ~0.08: sagitta ~1e-3).
    EXPECT_LT(sphere_error(finest), 3e-3);

    TriMesh open = input;
    open.triangles.pop_back();
    open.triangles.push_back(open.triangles.front()); // a duplicated face: not a manifold
    EXPECT_THROW(check_remesh_input(open), InvalidInput);
    EXPECT_THROW((void)remesh(open, options), InvalidInput);
    EXPECT_THROW(check_remesh_input(TriMesh{}), InvalidInput);
}

} // namespace
} // namespace pointform
