// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/polygonize/handles.h"

#include "pointform/core/error.h"
#include "pointform/geometry/mesh_topology.h"
#include "pointform/geometry/shapes.h"
#include "pointform/hermite/surfels.h"
#include "pointform/polygonize/reconstruct.h"

#include "support/thread_counts.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <numbers>
#include <vector>

namespace pointform {
namespace {

constexpr double pi = std::numbers::pi;

/// Appends a torus round the z axis through `centre` (tube radius r round a circle of radius R):
/// `around` segments along the circle, `tube` round the tube, counter-clockwise from outside.
void add_torus(TriMesh& mesh, Vec3d centre, double R, double r, std::uint32_t around,
               std::uint32_t tube)
{
    const auto first = static_cast<std::uint32_t>(mesh.vertex_count());
    for (std::uint32_t i = 0; i < around; ++i)
        for (std::uint32_t j = 0; j < tube; ++j)
        {
            const double theta = 2.0 * pi * i / around;
            const double phi = 2.0 * pi * j / tube;
            const double w = R + r * std::cos(phi);
            mesh.vertices.positions.emplace_back(
                (centre + Vec3d(w * std::cos(theta), w * std::sin(theta), r * std::sin(phi)))
                    .cast<float>());
        }
    auto at = [&](std::uint32_t i, std::uint32_t j) {
        return first + (i % around) * tube + (j % tube);
    };
    for (std::uint32_t i = 0; i < around; ++i)
        for (std::uint32_t j = 0; j < tube; ++j)
        {
            mesh.triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
            mesh.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
        }
}

/// Appends a surface of revolution round the z axis through `centre`: rings at z(t), radius
/// radius(t) for t = k / rings (k = 1 ... rings − 1), `segments` round each, and the poles at
/// t = 0 and 1 unless `open` (then the end rings are at t = 0 and 1 and stay open).
void add_revolution(TriMesh& mesh, Vec3d centre, const std::function<double(double)>& radius,
                    const std::function<double(double)>& z, std::uint32_t rings,
                    std::uint32_t segments, bool open)
{
    const auto first = static_cast<std::uint32_t>(mesh.vertex_count());
    const std::uint32_t k0 = open ? 0 : 1;
    const std::uint32_t k1 = open ? rings : rings - 1;
    for (std::uint32_t k = k0; k <= k1; ++k)
        for (std::uint32_t s = 0; s < segments; ++s)
        {
            const double t = static_cast<double>(k) / rings;
            const double a = 2.0 * pi * s / segments;
            mesh.vertices.positions.emplace_back(
                (centre + Vec3d(radius(t) * std::cos(a), radius(t) * std::sin(a), z(t)))
                    .cast<float>());
        }
    auto at = [&](std::uint32_t k, std::uint32_t s) {
        return first + (k - k0) * segments + (s % segments);
    };
    for (std::uint32_t k = k0; k < k1; ++k)
        for (std::uint32_t s = 0; s < segments; ++s)
        {
            mesh.triangles.push_back({at(k, s), at(k, s + 1), at(k + 1, s + 1)});
            mesh.triangles.push_back({at(k, s), at(k + 1, s + 1), at(k + 1, s)});
        }
    if (open)
        return;
    const auto bottom = static_cast<std::uint32_t>(mesh.vertex_count());
    mesh.vertices.positions.emplace_back((centre + Vec3d(0.0, 0.0, z(0.0))).cast<float>());
    const auto top = static_cast<std::uint32_t>(mesh.vertex_count());
    mesh.vertices.positions.emplace_back((centre + Vec3d(0.0, 0.0, z(1.0))).cast<float>());
    for (std::uint32_t s = 0; s < segments; ++s)
    {
        mesh.triangles.push_back({bottom, at(k0, s + 1), at(k0, s)});
        mesh.triangles.push_back({top, at(k1, s), at(k1, s + 1)});
    }
}

/// The perimeter of a regular polygon of n sides inscribed in a circle of radius r.
double polygon(double r, std::uint32_t n)
{
    return 2.0 * n * r * std::sin(pi / n);
}

std::size_t genus(const TriMesh& mesh)
{
    const MeshTopology t = analyze_topology(mesh);
    return static_cast<std::size_t>((2 * static_cast<std::int64_t>(t.components) -
                                     t.euler_characteristic -
                                     static_cast<std::int64_t>(t.boundary_loops)) /
                                    2);
}

TEST(Handles, ARealHandleIsNoSponge)
{
    // A torus's inner side curves negatively (-4π in all, spread round its inner circle), a
    // sphere's positively: no cell of 8 radii adds up to two handles. Cells of 0.5 here.
    TriMesh torus;
    add_torus(torus, Vec3d::Zero(), 1.0, 0.1, 120, 24);
    EXPECT_TRUE(spongy_cells(torus, 0.5 / 8.0).cells.empty());
    EXPECT_EQ(sponge_genus(torus), 0U);
    TriMesh sphere;
    add_revolution(
        sphere, Vec3d::Zero(), [](double t) { return std::sin(pi * t); },
        [](double t) { return -std::cos(pi * t); }, 40, 60, false);
    EXPECT_TRUE(spongy_cells(sphere, 0.5 / 8.0).cells.empty());
    // Many tori in one cell, each a piece of its own: each adds up to 0 (a handle's -4π counts
    // only where it is attached to a surface), and they are not a sponge either.
    TriMesh many;
    for (int i = 0; i < 80; ++i)
        add_torus(many, Vec3d(0.01 * i, 0.0, 0.0), 0.05, 0.01, 24, 12);
    EXPECT_TRUE(spongy_cells(many, 1.0).cells.empty());
}

TEST(Handles, TheShortestLoopOfATorusIsItsTubesMeridian)
{
    TriMesh torus;
    add_torus(torus, Vec3d::Zero(), 1.0, 0.1, 120, 24);
    const double meridian = polygon(0.1, 24);
    const MeshLoop loop = shortest_handle_loop(torus, 2.0 * meridian);
    ASSERT_EQ(loop.vertices.size(), 24U);
    EXPECT_NEAR(loop.length, meridian, 1e-5 * meridian);
    // Every vertex of the loop is on one meridian circle: one angle round the z axis.
    const Vec3d p0 = torus.vertices.world(loop.vertices[0]);
    for (const std::uint32_t v : loop.vertices)
    {
        const Vec3d p = torus.vertices.world(v);
        EXPECT_NEAR(std::atan2(p.y(), p.x()), std::atan2(p0.y(), p0.x()), 1e-6);
    }
    // A bound below the meridian finds nothing.
    EXPECT_TRUE(shortest_handle_loop(torus, 0.99 * meridian).vertices.empty());
}

TEST(Handles, SeparatingLoopsAndLoopsRoundHolesAreNotHandles)
{
    // A thick torus (its meridian, 1.88, past the bound) makes the mesh genus 1; beside it a
    // dumbbell whose neck (0.63 round) separates its two balls, and an open tube (0.63 round)
    // whose loops go round its two holes. None is a handle within the bound.
    TriMesh mesh;
    add_torus(mesh, Vec3d::Zero(), 1.0, 0.3, 60, 24);
    add_revolution(
        mesh, Vec3d(4.0, 0.0, 0.0),
        [](double t) {
            const double z = 4.0 * t - 2.0;
            const double d = std::abs(z) - 1.0;
            return 0.1 + std::sqrt(std::max(0.0, 1.0 - d * d));
        },
        [](double t) { return 4.0 * t - 2.0; }, 80, 24, false);
    add_revolution(
        mesh, Vec3d(-4.0, 0.0, 0.0), [](double) { return 0.1; }, [](double t) { return 2.0 * t; },
        40, 24, true);
    ASSERT_EQ(genus(mesh), 1U);
    EXPECT_TRUE(shortest_handle_loop(mesh, 1.5).vertices.empty());
    const TriMesh before = mesh;
    const HandleCutReport report = cut_short_handles(mesh, 1.5);
    EXPECT_EQ(report.genus_before, 1U);
    EXPECT_EQ(report.genus_after, 1U);
    EXPECT_EQ(report.cuts, 0U);
    EXPECT_EQ(mesh.triangles, before.triangles);
    // The torus's own meridian is found once the bound passes it.
    const MeshLoop loop = shortest_handle_loop(mesh, 2.0);
    EXPECT_NEAR(loop.length, polygon(0.3, 24), 1e-5);
}

TEST(Handles, CutsTheThinHandleAndKeepsTheThickOne)
{
    TriMesh mesh;
    add_torus(mesh, Vec3d::Zero(), 1.0, 0.1, 120, 24);         // meridian 0.627
    add_torus(mesh, Vec3d(5.0, 0.0, 0.0), 1.0, 0.3, 60, 24);   // meridian 1.88
    add_torus(mesh, Vec3d(0.0, 5.0, 0.0), 1.0, 0.05, 160, 16); // meridian 0.312
    const MeshTopology before = analyze_topology(mesh);
    const HandleCutReport report = cut_short_handles(mesh, 1.0);
    EXPECT_EQ(report.genus_before, 3U);
    EXPECT_EQ(report.genus_after, 1U);
    ASSERT_EQ(report.cuts, 2U);
    EXPECT_EQ(report.rounds, 1U); // independent loops, clear of each other: one round
    ASSERT_EQ(report.lengths.size(), 2U);
    // Shortest first.
    EXPECT_NEAR(report.lengths[0], polygon(0.05, 16), 1e-5);
    EXPECT_NEAR(report.lengths[1], polygon(0.1, 24), 1e-5);
    EXPECT_DOUBLE_EQ(report.longest_cut, report.lengths[1]);
    EXPECT_DOUBLE_EQ(report.max_length, 1.0);

    const MeshTopology after = analyze_topology(mesh);
    EXPECT_TRUE(after.is_oriented_manifold());
    EXPECT_TRUE(after.is_closed());
    EXPECT_EQ(after.components, before.components);
    EXPECT_EQ(genus(mesh), 1U);
    // Each cut copies the loop's vertices and adds two cap centres, and two fans of triangles.
    EXPECT_EQ(mesh.vertex_count(), before.vertices + 16 + 2 + 24 + 2);
    EXPECT_EQ(mesh.face_count(), before.faces + 2 * 16 + 2 * 24);
    // The last cut's caps (the r = 0.1 tube's) are centred on the tube's axis, each a tenth of
    // its radius along the axis from the loop's plane, on its own side.
    const Vec3d left = mesh.vertices.world(mesh.vertex_count() - 2);
    const Vec3d right = mesh.vertices.world(mesh.vertex_count() - 1);
    for (const Vec3d& p : {left, right})
        EXPECT_NEAR((p - Vec3d(p.x(), p.y(), 0.0).normalized()).norm(), 0.0, 2e-4);
    EXPECT_NEAR((left - right).norm(), 2.0 * 0.1 * 0.1, 1e-4);
    // Nothing short is left.
    EXPECT_TRUE(shortest_handle_loop(mesh, 1.0).vertices.empty());
    EXPECT_FALSE(shortest_handle_loop(mesh, 2.0).vertices.empty());
}

TEST(Handles, NothingIsCutWithoutALengthOrAHandle)
{
    TriMesh torus;
    add_torus(torus, Vec3d::Zero(), 1.0, 0.1, 60, 12);
    const TriMesh before = torus;
    const HandleCutReport report = cut_short_handles(torus, 0.0);
    EXPECT_EQ(report.genus_before, 1U);
    EXPECT_EQ(report.cuts, 0U);
    EXPECT_EQ(torus.triangles, before.triangles);
    TriMesh empty;
    EXPECT_EQ(cut_short_handles(empty, 1.0).cuts, 0U);
    EXPECT_TRUE(shortest_handle_loop(empty, 1.0).vertices.empty());
}

TEST(Handles, ANonManifoldMeshIsLeftAsItIs)
{
    // A torus with a fin: a triangle on one of its edges makes that edge's third.
    TriMesh mesh;
    add_torus(mesh, Vec3d::Zero(), 1.0, 0.05, 120, 16);
    const Triangle& t = mesh.triangles.front();
    mesh.vertices.positions.emplace_back(2.0f, 2.0f, 2.0f);
    mesh.triangles.push_back({t[0], t[1], static_cast<std::uint32_t>(mesh.vertex_count() - 1)});
    const TriMesh before = mesh;
    const HandleCutReport report = cut_short_handles(mesh, 1.0);
    EXPECT_TRUE(report.skipped_not_manifold);
    EXPECT_EQ(report.cuts, 0U);
    EXPECT_EQ(mesh.triangles, before.triangles);
    EXPECT_EQ(mesh.vertices.positions, before.vertices.positions);
}

TEST(Handles, TheSameCutsWhateverTheThreadCount)
{
    // Ten thin tori: the search from each of their 19,200 vertices runs in several blocks.
    TriMesh mesh;
    for (int i = 0; i < 10; ++i)
        add_torus(mesh, Vec3d(3.0 * i, 0.0, 0.0), 1.0, 0.05 + 0.005 * i, 120, 16);
    const auto runs = test::at_thread_counts([&] {
        TriMesh cut = mesh;
        const HandleCutReport report = cut_short_handles(cut, 0.7);
        return std::make_pair(cut, report.lengths);
    });
    ASSERT_EQ(runs[0].second.size(), 10U);
    for (std::size_t i = 1; i < runs.size(); ++i)
    {
        EXPECT_EQ(runs[i].first.triangles, runs[0].first.triangles);
        EXPECT_EQ(runs[i].first.vertices.positions, runs[0].first.vertices.positions);
        EXPECT_EQ(runs[i].second, runs[0].second);
    }
}

TEST(Handles, ReconstructCutsTheTunnelsOfANoisySharpRim)
{
    // A noisy 45° cone: the base's and the side's fits reach past the rim and meet as small
    // tunnels. The default cuts them; the result is closer to the cone's genus 0, and no
    // farther from the samples.
    PointCloud raw = sample_shape(Shape::Cone, {.count = 20000, .seed = 2, .noise = 0.002});
    raw.normals.clear();
    const PointCloud surfels = surfels_from_samples(std::move(raw)).surfels;
    ReconstructOptions keep;
    keep.max_handle = 0.0;
    const ReconstructReport kept = reconstruct(surfels, keep);
    const ReconstructReport cut = reconstruct(surfels, {});
    EXPECT_EQ(kept.handles.cuts, 0U);
    ASSERT_GT(kept.handles.genus_before, 3U) << "no tunnels: the test tests nothing";
    EXPECT_EQ(cut.handles.genus_before, kept.handles.genus_before);
    EXPECT_GT(cut.handles.cuts, kept.handles.genus_before / 2);
    EXPECT_EQ(cut.handles.genus_after, cut.handles.genus_before - cut.handles.cuts);
    EXPECT_LE(cut.handles.longest_cut, cut.handles.max_length);
    const MultiresMesh& h_kept = kept.semi_regular.hierarchy;
    const MultiresMesh& h_cut = cut.semi_regular.hierarchy;
    const TriMesh out_kept = h_kept.level_mesh(h_kept.finest_level());
    const TriMesh out_cut = h_cut.level_mesh(h_cut.finest_level());
    EXPECT_LT(genus(out_cut), genus(out_kept) / 2);
    EXPECT_TRUE(analyze_topology(out_cut).is_oriented_manifold());

    ReconstructOptions bad;
    bad.max_handle = -1.0;
    EXPECT_THROW((void)reconstruct(surfels, bad), InvalidInput);
    bad.max_handle = std::nan("");
    EXPECT_THROW((void)reconstruct(surfels, bad), InvalidInput);
    bad.max_handle = max_handle_radii + 1.0;
    EXPECT_THROW((void)reconstruct(surfels, bad), InvalidInput);
}

} // namespace
} // namespace pointform
