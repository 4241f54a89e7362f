// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// Issue 13: reconstruct() closes the holes a scan leaves (BaseMeshOptions::fill_holes), with a
// patch that stays near the true surface, and leaves the rim of a partial scan open.

#include "pointform/core/error.h"
#include "pointform/geometry/mesh_topology.h"
#include "pointform/geometry/shapes.h"
#include "pointform/hermite/surfels.h"
#include "pointform/polygonize/reconstruct.h"

#include <gtest/gtest.h>

#include <cmath>

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

TEST(HoleFill, OutOfRangeIsRefused)
{
    const PointCloud samples = sample_shape(Shape::Sphere, {.count = 3000, .seed = 4});
    EXPECT_THROW((void)reconstruct_samples(samples, 1.0), InvalidInput);
    EXPECT_THROW((void)reconstruct_samples(samples, -0.1), InvalidInput);
    EXPECT_THROW((void)reconstruct_samples(samples, std::nan("")), InvalidInput);
}

} // namespace
} // namespace pointform
