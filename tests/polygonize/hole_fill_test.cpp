// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// Issue 13: reconstruct() closes the holes a scan leaves (BaseMeshOptions::fill_holes), with a
// patch that stays near the true surface, and leaves the rim of a partial scan open.

#include "pointform/core/error.h"
#include "pointform/geometry/mesh_topology.h"
#include "pointform/geometry/shapes.h"
#include "pointform/hermite/surfels.h"
#include "pointform/implicit/primitives.h"
#include "pointform/polygonize/base_mesh.h"
#include "pointform/polygonize/reconstruct.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace pointform {
namespace {

ReconstructReport reconstruct_samples(const PointCloud& samples, double fill_holes)
{
    ReconstructOptions options;
    options.fill_holes = fill_holes;
    return reconstruct(surfels_from_samples(samples).surfels, options);
}

TEST(HoleFill, HolesOfASphereScanAreClosedNearTheSphere)
{
    // Six holes of radius 4% of the diagonal (0.14 on the unit sphere): a cap over one lies
    // within r²/2 ≈ 0.01 of the sphere.
    const PointCloud samples =
        sample_shape(Shape::Sphere, {.count = 30000, .seed = 2, .holes = 6, .hole_radius = 0.04});
    const ReconstructReport open = reconstruct_samples(samples, 0.0);
    const TriMesh open_mesh =
        open.semi_regular.hierarchy.level_mesh(open.semi_regular.hierarchy.finest_level());
    EXPECT_EQ(analyze_topology(open_mesh).boundary_loops, 6U);
    EXPECT_EQ(open.semi_regular.base->holes_filled, 0U);

    const ReconstructReport closed = reconstruct_samples(samples, ReconstructOptions{}.fill_holes);
    const BaseMeshStats& base = *closed.semi_regular.base;
    EXPECT_EQ(base.holes_filled, 6U);
    EXPECT_GT(base.hole_vertices, 0U);
    EXPECT_TRUE(base.topology_kept) << base.topology_change;
    const TriMesh mesh =
        closed.semi_regular.hierarchy.level_mesh(closed.semi_regular.hierarchy.finest_level());
    const MeshTopology topology = analyze_topology(mesh);
    EXPECT_TRUE(topology.is_closed());
    EXPECT_TRUE(topology.is_oriented_manifold());
    EXPECT_EQ(topology.euler_characteristic, 2);
    double worst = 0.0;
    for (std::size_t v = 0; v < mesh.vertex_count(); ++v)
        worst = std::max(worst, std::abs(mesh.vertices.world(v).norm() - 1.0));
    EXPECT_LT(worst, 0.03);
    // The patches cover less than the holes took (6 π 0.14² of the sphere's 4π): the field
    // reaches into each hole by about an influence radius.
    EXPECT_GT(base.hole_area_share, 0.0);
    EXPECT_LT(base.hole_area_share, 6.0 * 0.14 * 0.14 / 4.0);
}

TEST(HoleFill, LargeHolesFollowTheCurvatureAroundThem)
{
    // Three holes of radius 8% of the diagonal (0.28 on the unit sphere): a membrane over one
    // (a flat patch) would lie up to 0.28²/2 ≈ 0.04 inside the sphere. The patch continues the
    // slope of the mesh around its rim (thin-plate fairing) and follows the sphere.
    const PointCloud samples =
        sample_shape(Shape::Sphere, {.count = 30000, .seed = 5, .holes = 3, .hole_radius = 0.08});
    const ReconstructReport closed = reconstruct_samples(samples, ReconstructOptions{}.fill_holes);
    EXPECT_EQ(closed.semi_regular.base->holes_filled, 3U);
    const TriMesh mesh =
        closed.semi_regular.hierarchy.level_mesh(closed.semi_regular.hierarchy.finest_level());
    EXPECT_TRUE(analyze_topology(mesh).is_closed());
    double worst = 0.0;
    for (std::size_t v = 0; v < mesh.vertex_count(); ++v)
        worst = std::max(worst, std::abs(mesh.vertices.world(v).norm() - 1.0));
    RecordProperty("worst", std::to_string(worst));
    EXPECT_LT(worst, 0.015); // 0.010 measured; the membrane alone: 0.034
}

TEST(HoleFill, APartialScanKeepsItsRim)
{
    // One side of a sphere, as a single range scan sees it: its rim encloses about as much as
    // the surface, and stays open.
    const PointCloud sphere = sample_shape(Shape::Sphere, {.count = 30000, .seed = 3});
    PointCloud half;
    half.origin = sphere.origin;
    for (std::size_t i = 0; i < sphere.size(); ++i)
    {
        if (sphere.world(i).z() > 0.2)
        {
            half.positions.push_back(sphere.positions[i]);
            half.normals.push_back(sphere.normals[i]);
        }
    }
    const ReconstructReport report = reconstruct_samples(half, ReconstructOptions{}.fill_holes);
    EXPECT_EQ(report.semi_regular.base->holes_filled, 0U);
    const TriMesh mesh =
        report.semi_regular.hierarchy.level_mesh(report.semi_regular.hierarchy.finest_level());
    EXPECT_EQ(analyze_topology(mesh).boundary_loops, 1U);
}

/// A flat grid of n × n squares over [0, 1]² (z = 0), two triangles each, without the faces
/// whose centroid lies in one of the ellipses (centre, semi-axes, angle).
TriMesh holed_grid(int n, const std::vector<std::array<double, 5>>& ellipses)
{
    TriMesh mesh;
    for (int y = 0; y <= n; ++y)
        for (int x = 0; x <= n; ++x)
            mesh.vertices.positions.emplace_back(static_cast<float>(x) / static_cast<float>(n),
                                                 static_cast<float>(y) / static_cast<float>(n),
                                                 0.0F);
    const auto inside = [&](double px, double py) {
        for (const auto& [cx, cy, ra, rb, angle] : ellipses)
        {
            const double u = std::cos(angle) * (px - cx) + std::sin(angle) * (py - cy);
            const double v = -std::sin(angle) * (px - cx) + std::cos(angle) * (py - cy);
            if ((u / ra) * (u / ra) + (v / rb) * (v / rb) < 1.0)
                return true;
        }
        return false;
    };
    std::vector<char> removed(static_cast<std::size_t>(n * n), 0);
    const auto at = [n, &removed](int x, int y) -> char& {
        return removed[static_cast<std::size_t>(y * n + x)];
    };
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x)
            at(x, y) = inside((x + 0.5) / n, (y + 0.5) / n) ? 1 : 0;
    // No two holes' squares meeting at a corner only (a vertex with two fans).
    for (bool changed = true; changed;)
    {
        changed = false;
        for (int y = 0; y + 1 < n; ++y)
            for (int x = 0; x + 1 < n; ++x)
            {
                const bool diagonal =
                    at(x, y) && at(x + 1, y + 1) && !at(x + 1, y) && !at(x, y + 1);
                const bool anti = at(x + 1, y) && at(x, y + 1) && !at(x, y) && !at(x + 1, y + 1);
                if (diagonal || anti)
                {
                    at(x + 1, y) = at(x, y + 1) = at(x, y) = at(x + 1, y + 1) = 1;
                    changed = true;
                }
            }
    }
    const auto id = [n](int x, int y) {
        return static_cast<std::uint32_t>(y * (n + 1) + x);
    };
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x)
        {
            if (at(x, y))
                continue;
            mesh.triangles.push_back({id(x, y), id(x + 1, y), id(x + 1, y + 1)});
            mesh.triangles.push_back({id(x, y), id(x + 1, y + 1), id(x, y + 1)});
        }
    return mesh;
}

TEST(HoleFill, ElongatedAndTurnedHolesGetManifoldPatches)
{
    // Holes of many shapes (long thin slots, turned, round): each patch's rings must close
    // into a manifold strip however unlike their vertex counts are (a 1M-sample noisy plate had
    // a 122-vertex rim whose inner ring wrapped round before its outer one).
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    for (int trial = 0; trial < 16; ++trial)
    {
        const double ra = 0.1 + 0.3 * unit(rng);
        const std::vector<std::array<double, 5>> ellipses{
            {0.5, 0.5, ra, ra * (0.05 + 0.5 * unit(rng)), std::numbers::pi * unit(rng)}};
        const TriMesh grid = holed_grid(100, ellipses);
        const auto plane = make_half_space(Vec3d::Zero(), Vec3d::UnitZ());
        BaseMeshOptions options;
        options.target_faces = grid.face_count() / (1 + trial % 3);
        options.fill_holes = 0.5; // every hole here, however large
        const BaseMeshResult base = build_base_mesh(grid, *plane, options);
        const MeshTopology topology = analyze_topology(base.mesh);
        EXPECT_TRUE(topology.is_oriented_manifold()) << "trial " << trial;
        EXPECT_EQ(topology.boundary_loops + base.stats.holes_filled,
                  base.stats.topology_before.boundary_loops)
            << "trial " << trial;
        EXPECT_GE(base.stats.holes_filled, 1U) << "trial " << trial;
        EXPECT_TRUE(base.stats.topology_kept) << base.stats.topology_change;
        for (std::size_t v = 0; v < base.mesh.vertex_count(); ++v)
            EXPECT_NEAR(base.mesh.vertices.world(v).z(), 0.0, 1e-6);
    }
}

TEST(HoleFill, OutOfRangeIsRefused)
{
    const PointCloud samples = sample_shape(Shape::Sphere, {.count = 3000, .seed = 4});
    EXPECT_THROW((void)reconstruct_samples(samples, 1.0), InvalidInput);
    EXPECT_THROW((void)reconstruct_samples(samples, -0.1), InvalidInput);
    EXPECT_THROW((void)reconstruct_samples(samples, std::nan("")), InvalidInput);
}

} // namespace
} // namespace pointform
