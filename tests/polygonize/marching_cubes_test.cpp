// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/polygonize/marching_cubes.h"

#include "pointform/core/error.h"
#include "pointform/core/parallel.h"
#include "pointform/geometry/mesh_topology.h"
#include "pointform/geometry/shapes.h"
#include "pointform/hermite/radius.h"
#include "pointform/hermite/surfels.h"
#include "pointform/implicit/operators.h"
#include "pointform/implicit/point_field.h"
#include "pointform/implicit/primitives.h"
#include "pointform/spatial/kd_tree.h"

#include "support/self_intersection.h"
#include "support/thread_counts.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

namespace pointform {
namespace {

/// Exact signed distance to a sphere; seeds on its surface unless told otherwise.
class SphereField final : public Field
{
public:
    SphereField(Vec3d centre, double radius, bool seeds = true)
        : centre_(std::move(centre)), radius_(radius), seeds_(seeds)
    {}
    [[nodiscard]] FieldSample evaluate(const Vec3d& p) const override
    {
        const Vec3d d = p - centre_;
        const double r = d.norm();
        return {r - radius_, r > 0.0 ? Vec3d(d / r) : Vec3d::UnitZ(), true};
    }
    using Field::evaluate;
    [[nodiscard]] Aabb bounds() const override
    {
        return {centre_ - Vec3d::Constant(radius_), centre_ + Vec3d::Constant(radius_)};
    }
    void append_seeds(std::vector<Vec3d>& seeds) const override
    {
        if (seeds_)
        {
            seeds.push_back(centre_ + radius_ * Vec3d::UnitX());
        }
    }

private:
    Vec3d centre_;
    double radius_;
    bool seeds_;
};

/// Exact signed distance to a torus about z (major R, minor r), seeded.
class TorusField final : public Field
{
public:
    TorusField(double major, double minor) : major_(major), minor_(minor) {}
    [[nodiscard]] FieldSample evaluate(const Vec3d& p) const override
    {
        const double rho = std::hypot(p.x(), p.y());
        const Vec3d ring = rho > 0.0 ? Vec3d(p.x() * major_ / rho, p.y() * major_ / rho, 0.0)
                                     : Vec3d(major_, 0.0, 0.0);
        const Vec3d d = p - ring;
        return {d.norm() - minor_, d.normalized(), true};
    }
    using Field::evaluate;
    [[nodiscard]] Aabb bounds() const override
    {
        const double e = major_ + minor_;
        return {Vec3d(-e, -e, -minor_), Vec3d(e, e, minor_)};
    }
    void append_seeds(std::vector<Vec3d>& seeds) const override
    {
        seeds.emplace_back(major_ + minor_, 0.0, 0.0);
    }

private:
    double major_;
    double minor_;
};

/// Trilinear interpolation of random values on a lattice: defined everywhere, full of ambiguous
/// faces. No seeds, so it is swept densely.
class RandomLatticeField final : public Field
{
public:
    RandomLatticeField(int n, std::uint64_t seed) : n_(n), values_((n + 1) * (n + 1) * (n + 1))
    {
        std::mt19937_64 rng(seed);
        std::uniform_real_distribution<double> u(-1.0, 1.0);
        for (double& v : values_)
        {
            v = u(rng);
        }
    }
    [[nodiscard]] FieldSample evaluate(const Vec3d& p) const override
    {
        const Vec3d q = p.cwiseMax(Vec3d::Zero()).cwiseMin(Vec3d::Constant(n_ - 1e-9));
        const int i = static_cast<int>(q.x());
        const int j = static_cast<int>(q.y());
        const int k = static_cast<int>(q.z());
        const double x = q.x() - i;
        const double y = q.y() - j;
        const double z = q.z() - k;
        double value = 0.0;
        for (int c = 0; c < 8; ++c)
        {
            const int dx = c & 1;
            const int dy = c >> 1 & 1;
            const int dz = c >> 2 & 1;
            value +=
                at(i + dx, j + dy, k + dz) * (dx ? x : 1 - x) * (dy ? y : 1 - y) * (dz ? z : 1 - z);
        }
        return {value, Vec3d::UnitZ(), true};
    }
    using Field::evaluate;
    [[nodiscard]] Aabb bounds() const override { return {Vec3d::Zero(), Vec3d::Constant(n_)}; }

private:
    [[nodiscard]] double at(int i, int j, int k) const
    {
        return values_[static_cast<std::size_t>((k * (n_ + 1) + j) * (n_ + 1) + i)];
    }
    int n_;
    std::vector<double> values_;
};

double signed_volume(const TriMesh& mesh)
{
    double volume = 0.0;
    for (const Triangle& t : mesh.triangles)
    {
        const Vec3d a = mesh.vertices.world(t[0]);
        const Vec3d b = mesh.vertices.world(t[1]);
        const Vec3d c = mesh.vertices.world(t[2]);
        volume += a.dot(b.cross(c)) / 6.0;
    }
    return volume;
}

TEST(MarchingCubes, SphereIsClosedOutwardAndOnTheSurface)
{
    const SphereField sphere(Vec3d(0.1, -0.2, 0.3), 1.0);
    const double cell = 0.05;
    const auto result = marching_cubes(sphere, grid_over(sphere.bounds(), cell));
    const TriMesh& mesh = result.mesh;
    const MeshTopology topo = analyze_topology(mesh);
    EXPECT_TRUE(topo.is_oriented_manifold());
    EXPECT_TRUE(topo.is_closed());
    EXPECT_EQ(topo.components, 1U);
    EXPECT_EQ(topo.euler_characteristic, 2);
    EXPECT_EQ(result.stats.degenerate_triangles, 0U);
    // Vertices on the sphere (the field is exact, so regula falsi converges).
    for (std::size_t v = 0; v < mesh.vertex_count(); ++v)
    {
        const Vec3d p = mesh.vertices.world(v);
        // Within the margin that keeps vertices off the grid corners (1e-4 of a cell).
        ASSERT_NEAR((p - Vec3d(0.1, -0.2, 0.3)).norm(), 1.0, 2e-4 * cell) << v;
        const Vec3d n = mesh.vertices.normals[v].cast<double>();
        ASSERT_NEAR(n.dot((p - Vec3d(0.1, -0.2, 0.3)).normalized()), 1.0, 1e-5);
    }
    // Outward: positive volume, close to the ball's (an inscribed polyhedron is a bit smaller).
    const double ball = 4.0 / 3.0 * std::numbers::pi;
    EXPECT_GT(signed_volume(mesh), 0.99 * ball);
    EXPECT_LT(signed_volume(mesh), ball);
    // Sparse: besides the cells the surface passes through, only the few cells probed around
    // the seed were visited.
    EXPECT_LE(result.stats.cells_visited, result.stats.surface_cells + 7);
    EXPECT_FALSE(result.stats.dense);
}

TEST(MarchingCubes, TorusHasGenusOne)
{
    const TorusField torus(1.0, 0.3);
    const auto result = marching_cubes(torus, grid_over(torus.bounds(), 0.04));
    const MeshTopology topo = analyze_topology(result.mesh);
    EXPECT_TRUE(topo.is_oriented_manifold());
    EXPECT_TRUE(topo.is_closed());
    EXPECT_EQ(topo.components, 1U);
    EXPECT_EQ(topo.euler_characteristic, 0);
    const double volume = 2.0 * std::numbers::pi * std::numbers::pi * 1.0 * 0.3 * 0.3;
    EXPECT_NEAR(signed_volume(result.mesh), volume, 0.02 * volume);
}

TEST(MarchingCubes, AmbiguousFacesResolveToAManifold)
{
    // Random lattices are full of ambiguous faces and cubes; the mesh must still be an oriented
    // manifold whose only boundary is where it meets the end of the grid.
    for (std::uint64_t seed = 1; seed <= 4; ++seed)
    {
        const RandomLatticeField field(12, seed);
        // Cells of 1/3 of a lattice cell, offset so that grid corners are off the lattice.
        CellGrid grid = grid_over(field.bounds(), 1.0 / 3.0);
        grid.origin += Vec3d::Constant(0.01);
        const auto result = marching_cubes(field, grid);
        EXPECT_TRUE(result.stats.dense);
        const TriMesh& mesh = result.mesh;
        const MeshTopology topo = analyze_topology(mesh);
        EXPECT_GT(topo.faces, 1000U);
        EXPECT_EQ(topo.non_manifold_edges, 0U);
        EXPECT_EQ(topo.non_manifold_vertices, 0U);
        EXPECT_EQ(topo.misoriented_edges, 0U);
        EXPECT_EQ(topo.degenerate_faces, 0U);
        // Every triangle's normal agrees with the field's growth direction, checked by the
        // field's values a little off the triangle's centre on either side.
        std::size_t against = 0;
        for (const Triangle& t : mesh.triangles)
        {
            const Vec3d a = mesh.vertices.world(t[0]);
            const Vec3d b = mesh.vertices.world(t[1]);
            const Vec3d c = mesh.vertices.world(t[2]);
            const Vec3d centre = (a + b + c) / 3.0;
            const Vec3d n = (b - a).cross(c - a).normalized();
            const double step = 0.02;
            if (field.evaluate(centre + step * n).value < field.evaluate(centre - step * n).value)
            {
                ++against;
            }
        }
        EXPECT_LT(static_cast<double>(against), 0.01 * static_cast<double>(mesh.face_count()));
    }
}

TEST(MarchingCubes, TunnelsThroughAmbiguousFacesStayManifold)
{
    // Random values at the grid corners themselves (cells of one lattice cell): every one of the
    // 256 corner patterns occurs, tunnels through ambiguous faces too, where a cell's loop
    // cannot be cut into triangles without a chord on a face. Cut on a face that the
    // neighbour's loop also needs, it made an edge of four triangles (found on a noisy scan of
    // a plate); such a loop is fanned around a vertex inside its cell instead.
    std::size_t cell_vertices = 0;
    for (std::uint64_t seed = 1; seed <= 6; ++seed)
    {
        const RandomLatticeField field(24, seed);
        const CellGrid grid = grid_over(field.bounds(), 1.0);
        const auto result = marching_cubes(field, grid, {.refine_steps = 40});
        const MeshTopology topo = analyze_topology(result.mesh);
        EXPECT_GT(topo.faces, 10000U);
        EXPECT_EQ(topo.non_manifold_edges, 0U) << "seed " << seed;
        EXPECT_EQ(topo.non_manifold_vertices, 0U) << "seed " << seed;
        EXPECT_EQ(topo.misoriented_edges, 0U) << "seed " << seed;
        EXPECT_EQ(topo.degenerate_faces, 0U) << "seed " << seed;
        cell_vertices += result.stats.cell_vertices;
        // Every vertex, a cell's own on a diagonal of its cell too, is refined onto the zero set
        // (within the margin that keeps vertices 1e-4 of a cell off the corners, where the
        // random values' gradients reach several units).
        for (std::size_t v = 0; v < result.mesh.vertex_count(); ++v)
        {
            const Vec3d p = result.mesh.vertices.world(v);
            EXPECT_LT(std::abs(field.evaluate(p).value), 1e-3) << "vertex " << v;
        }
    }
    EXPECT_GT(cell_vertices, 0U);
}

TEST(MarchingCubes, UndefinedCellsLeaveAHole)
{
    // A sphere whose field is undefined above z = 0.5: the cap is cut away and its rim is the
    // only boundary.
    class CappedSphere final : public Field
    {
    public:
        [[nodiscard]] FieldSample evaluate(const Vec3d& p) const override
        {
            FieldSample s = sphere_.evaluate(p);
            s.defined = p.z() < 0.5;
            return s;
        }
        using Field::evaluate;
        [[nodiscard]] Aabb bounds() const override { return sphere_.bounds(); }
        void append_seeds(std::vector<Vec3d>& seeds) const override { sphere_.append_seeds(seeds); }

    private:
        SphereField sphere_{Vec3d::Zero(), 1.0};
    };
    const CappedSphere field;
    const auto result = marching_cubes(field, grid_over(field.bounds(), 0.05));
    const MeshTopology topo = analyze_topology(result.mesh);
    EXPECT_TRUE(topo.is_oriented_manifold());
    EXPECT_EQ(topo.boundary_loops, 1U);
    EXPECT_EQ(topo.euler_characteristic, 1); // a disc
    EXPECT_GT(result.stats.undefined_cells, 0U);
    for (std::size_t v = 0; v < result.mesh.vertex_count(); ++v)
    {
        ASSERT_LT(result.mesh.vertices.world(v).z(), 0.5);
    }

    // Cells with one defined corner or more (min_defined_corners = 1) reach one cell further:
    // still a disc, its rim higher, within a cell diagonal of z = 0.5.
    const auto partial =
        marching_cubes(field, grid_over(field.bounds(), 0.05), {.min_defined_corners = 1});
    const MeshTopology partial_topo = analyze_topology(partial.mesh);
    EXPECT_TRUE(partial_topo.is_oriented_manifold());
    EXPECT_EQ(partial_topo.boundary_loops, 1U);
    EXPECT_EQ(partial_topo.euler_characteristic, 1);
    const auto highest = [](const TriMesh& mesh) {
        double top = -1.0;
        for (std::size_t v = 0; v < mesh.vertex_count(); ++v)
        {
            top = std::max(top, mesh.vertices.world(v).z());
        }
        return top;
    };
    const double top = highest(partial.mesh);
    EXPECT_GT(top, highest(result.mesh) + 0.01);
    EXPECT_LT(top, 0.5 + 0.05 * std::sqrt(3.0) + 1e-6);
    EXPECT_GT(partial.mesh.face_count(), result.mesh.face_count());
    EXPECT_THROW(
        (void)marching_cubes(field, grid_over(field.bounds(), 0.05), {.min_defined_corners = 0}),
        InvalidInput);
}

TEST(MarchingCubes, SampledSphereThroughThePointField)
{
    const PointCloud samples = sample_shape(Shape::Sphere, {.count = 20000, .seed = 8});
    const PointField field(
        compute_surfels(samples, {.radius_scale = default_field_radius_scale}).surfels);
    const auto result = marching_cubes(field, grid_over(field.bounds(), default_cell_size(field)));
    const MeshTopology topo = analyze_topology(result.mesh);
    EXPECT_TRUE(topo.is_oriented_manifold());
    EXPECT_TRUE(topo.is_closed());
    EXPECT_EQ(topo.components, 1U);
    EXPECT_EQ(topo.euler_characteristic, 2);
    EXPECT_EQ(result.stats.degenerate_triangles, 0U);
    const double spacing = std::sqrt(4.0 * std::numbers::pi / 20000.0);
    double worst = 0.0;
    for (std::size_t v = 0; v < result.mesh.vertex_count(); ++v)
    {
        worst = std::max(worst, std::abs(result.mesh.vertices.world(v).norm() - 1.0));
    }
    EXPECT_LT(worst, 0.25 * spacing);
    EXPECT_GT(signed_volume(result.mesh), 0.0);
}

/// A unit sphere sampled with exact normals, without its cap above z = 0.8, radii = the 16th
/// neighbour's distance times `scale`.
PointCloud capless_sphere(double scale)
{
    const PointCloud all = sample_shape(Shape::Sphere, {.count = 6000, .seed = 12});
    PointCloud cloud;
    for (std::size_t i = 0; i < all.size(); ++i)
    {
        if (all.positions[i].z() <= 0.8F)
        {
            cloud.positions.push_back(all.positions[i]);
            cloud.normals.push_back(all.positions[i].normalized());
        }
    }
    const KdTree tree(cloud.positions);
    cloud.radii = influence_radii(knn_batch(tree, cloud.positions, 17), scale);
    return cloud;
}

TEST(MarchingCubes, RemovedCapStaysOpenAtASmallRadiusAndClosesAtALargeOne)
{
    // The cap's rim has radius 0.6: radii of ~0.1 leave it open, radii near 0.9 reach across.
    const PointField small(capless_sphere(1.5));
    const auto open = marching_cubes(small, grid_over(small.bounds(), default_cell_size(small)));
    const MeshTopology open_topo = analyze_topology(open.mesh);
    EXPECT_TRUE(open_topo.is_oriented_manifold());
    EXPECT_EQ(open_topo.boundary_loops, 1U);
    EXPECT_EQ(open_topo.euler_characteristic, 1);
    // The surface reaches at most one influence radius past the rim samples.
    const auto& radii = small.surfels().radii;
    const double reach = 0.8 + static_cast<double>(*std::max_element(radii.begin(), radii.end()));
    for (std::size_t v = 0; v < open.mesh.vertex_count(); ++v)
    {
        ASSERT_LT(open.mesh.vertices.world(v).z(), reach);
    }

    const PointField large(capless_sphere(8.0));
    const auto closed = marching_cubes(large, grid_over(large.bounds(), 0.04));
    const MeshTopology closed_topo = analyze_topology(closed.mesh);
    EXPECT_TRUE(closed_topo.is_oriented_manifold());
    EXPECT_TRUE(closed_topo.is_closed());
    EXPECT_EQ(closed_topo.euler_characteristic, 2);
}

TEST(MarchingCubes, IntermediateGridIsCoarsenedToTheFaceLimitAndKeepsHolesOpen)
{
    // The estimate 3 A / h² against the mesh at the field's own cell.
    const PointCloud samples = sample_shape(Shape::Sphere, {.count = 20000, .seed = 8});
    const PointField field(
        compute_surfels(samples, {.radius_scale = default_field_radius_scale}).surfels);
    const double cell = default_cell_size(field);
    const IntermediateGrid own = intermediate_grid(field, cell);
    EXPECT_EQ(own.coarsening, 1.0);
    EXPECT_EQ(own.cell, cell);
    EXPECT_EQ(own.min_defined_corners, 8);
    const auto fine = marching_cubes(field, grid_over(field.bounds(), cell));
    const auto fine_faces = static_cast<double>(fine.mesh.face_count());
    EXPECT_NEAR(own.estimated_faces, fine_faces, 0.15 * fine_faces);

    // A limit of a sixteenth: a grid four times coarser, whose corners lie beyond the influence
    // radii, still gives one closed sphere of about that many faces, on the surface.
    const IntermediateGrid coarse = intermediate_grid(field, cell, own.estimated_faces / 16.0);
    EXPECT_NEAR(coarse.coarsening, 4.0, 1e-9);
    EXPECT_LT(coarse.min_defined_corners, 8);
    const auto mesh = marching_cubes(field, grid_over(field.bounds(), coarse.cell),
                                     {.min_defined_corners = coarse.min_defined_corners});
    const MeshTopology topo = analyze_topology(mesh.mesh);
    EXPECT_TRUE(topo.is_oriented_manifold());
    EXPECT_TRUE(topo.is_closed());
    EXPECT_EQ(topo.euler_characteristic, 2);
    EXPECT_NEAR(static_cast<double>(mesh.mesh.face_count()), fine_faces / 16.0,
                0.25 * fine_faces / 16.0);
    for (std::size_t v = 0; v < mesh.mesh.vertex_count(); ++v)
    {
        ASSERT_NEAR(mesh.mesh.vertices.world(v).norm(), 1.0, 0.05 * coarse.cell);
    }
    // Without the looser corners, the coarse grid's mesh falls apart.
    const auto strict = marching_cubes(field, grid_over(field.bounds(), coarse.cell));
    EXPECT_GT(analyze_topology(strict.mesh).boundary_loops, 0U);

    // A sphere without its cap above z = 0.8: the coarse mesh keeps the hole (the triangles
    // reaching past the field's rim are dropped), within a coarse cell of where the fine one has
    // it.
    const PointField capless(capless_sphere(1.5));
    const double capless_cell = default_cell_size(capless);
    const IntermediateGrid holed = intermediate_grid(
        capless, capless_cell, intermediate_grid(capless, capless_cell).estimated_faces / 9.0);
    const auto open = marching_cubes(capless, grid_over(capless.bounds(), holed.cell),
                                     {.min_defined_corners = holed.min_defined_corners});
    const MeshTopology open_topo = analyze_topology(open.mesh);
    EXPECT_TRUE(open_topo.is_oriented_manifold());
    EXPECT_EQ(open_topo.boundary_loops, 1U);
    EXPECT_EQ(open_topo.euler_characteristic, 1);
    EXPECT_GT(open.stats.undefined_triangles, 0U);
    const auto& radii = capless.surfels().radii;
    const double reach = 0.8 + static_cast<double>(*std::max_element(radii.begin(), radii.end()));
    for (std::size_t v = 0; v < open.mesh.vertex_count(); ++v)
    {
        ASSERT_LT(open.mesh.vertices.world(v).z(), reach);
    }
}

TEST(MarchingCubes, SameMeshWhateverTheThreadCount)
{
    const PointCloud samples = sample_shape(Shape::Torus, {.count = 20000, .seed = 2});
    const PointField field(
        compute_surfels(samples, {.radius_scale = default_field_radius_scale}).surfels);
    const CellGrid grid = grid_over(field.bounds(), default_cell_size(field));
    const auto runs = test::at_thread_counts([&] { return marching_cubes(field, grid).mesh; });
    const TriMesh& one = runs[0];
    for (std::size_t i = 1; i < runs.size(); ++i)
    {
        ASSERT_EQ(one.triangles, runs[i].triangles) << i + 1 << " threads";
        ASSERT_EQ(one.vertices.positions, runs[i].vertices.positions) << i + 1 << " threads";
    }
    EXPECT_EQ(analyze_topology(one).euler_characteristic, 0);
}

/// A mesh from world positions and triangles (origin 0, so the floats are the positions).
TriMesh mesh_of(const std::vector<Vec3d>& points, const std::vector<Triangle>& triangles)
{
    TriMesh mesh;
    for (const Vec3d& p : points)
    {
        mesh.vertices.positions.push_back(p.cast<float>());
    }
    mesh.triangles = triangles;
    return mesh;
}

TEST(SelfIntersectionCheck, FindsCrossingTouchingAndOverlappingTriangles)
{
    using test::find_self_intersections;
    // Two triangles piercing each other; then one only touching the other's interior with a
    // corner (closed triangles: a touch counts); then one just clear of it.
    const std::vector<Vec3d> base = {{0, 0, 0}, {4, 0, 0}, {0, 4, 0}};
    const auto with = [&](const std::vector<Vec3d>& more) {
        std::vector<Vec3d> points = base;
        points.insert(points.end(), more.begin(), more.end());
        return mesh_of(points, {{0, 1, 2}, {3, 4, 5}});
    };
    EXPECT_EQ(find_self_intersections(with({{1, 1, -1}, {1, 1, 1}, {2, 2, 1}})).pairs.size(), 1U);
    EXPECT_EQ(find_self_intersections(with({{1, 1, 0}, {1, 1, 1}, {2, 2, 1}})).pairs.size(), 1U);
    EXPECT_EQ(find_self_intersections(with({{1, 1, 0x1p-20}, {1, 1, 1}, {2, 2, 1}})).pairs.size(),
              0U);
    // Coplanar: overlapping, and disjoint.
    EXPECT_EQ(find_self_intersections(with({{1, 1, 0}, {5, 1, 0}, {1, 5, 0}})).pairs.size(), 1U);
    EXPECT_EQ(find_self_intersections(with({{3, 3, 0}, {5, 3, 0}, {3, 5, 0}})).pairs.size(), 0U);
    // An edge of one crossing the other where it does not reach a corner (no vertex inside).
    EXPECT_EQ(find_self_intersections(with({{-1, 1, 0.5}, {5, 1, 0.5}, {2, 1, -3}})).pairs.size(),
              1U);
}

TEST(SelfIntersectionCheck, NeighboursMeetOnlyWhereTheyShareUnlessTheyFoldOver)
{
    using test::find_self_intersections;
    // A shared edge: a proper hinge is fine, a coplanar fold-over is an overlap.
    const std::vector<Vec3d> hinge = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, -1, 1}};
    EXPECT_TRUE(find_self_intersections(mesh_of(hinge, {{0, 1, 2}, {1, 0, 3}})).pairs.empty());
    const std::vector<Vec3d> fold = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0.5, 2, 0}};
    EXPECT_EQ(find_self_intersections(mesh_of(fold, {{0, 1, 2}, {1, 0, 3}})).pairs.size(), 1U);
    // A shared corner: a fan is fine; a face whose edge from the corner runs inside the other,
    // or whose far edge pierces it, is not.
    const std::vector<Vec3d> fan = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {-1, 0, 0.2}, {0, -1, 0.3}};
    EXPECT_TRUE(find_self_intersections(mesh_of(fan, {{0, 1, 2}, {0, 3, 4}})).pairs.empty());
    const std::vector<Vec3d> inside = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0.3, 0.3, 0}, {0, 0, 1}};
    EXPECT_EQ(find_self_intersections(mesh_of(inside, {{0, 1, 2}, {0, 3, 4}})).pairs.size(), 1U);
    const std::vector<Vec3d> pierce = {
        {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0.4, 0.2, -1}, {0.2, 0.4, 1}};
    EXPECT_EQ(find_self_intersections(mesh_of(pierce, {{0, 1, 2}, {0, 3, 4}})).pairs.size(), 1U);
    // Copies of a vertex at one position count as the same corner; a repeated face overlaps.
    const std::vector<Vec3d> copies = {{0, 0, 0}, {1, 0, 0},    {0, 1, 0},
                                       {0, 0, 0}, {-1, 0, 0.2}, {0, -1, 0.3}};
    EXPECT_TRUE(find_self_intersections(mesh_of(copies, {{0, 1, 2}, {3, 4, 5}})).pairs.empty());
    EXPECT_EQ(find_self_intersections(mesh_of(hinge, {{0, 1, 2}, {1, 2, 0}})).pairs.size(), 1U);
    // Collinear corners are reported as degenerate, not tested.
    const std::vector<Vec3d> line = {{0, 0, 0}, {1, 1, 1}, {2, 2, 2}, {0, 1, 0}};
    EXPECT_EQ(find_self_intersections(mesh_of(line, {{0, 1, 2}, {0, 1, 3}})).degenerate.size(), 1U);
}

TEST(SelfIntersectionCheck, OrientationIsExactWhereDoublesRoundToZero)
{
    // d is 2⁻⁶⁰ off the plane through a, b, c at a scale of 1: the naive double determinant
    // rounds, the exact sign does not.
    const double a[3] = {0.0, 0.0, 0.0};
    const double b[3] = {1.0, 0.1, 0.0};
    const double c[3] = {0.1, 1.0, 0.0};
    const double above[3] = {0.3, 0.7, 0x1p-60};
    const double below[3] = {0.3, 0.7, -0x1p-60};
    const double on[3] = {0.3, 0.7, 0.0};
    EXPECT_EQ(test::orient3d_exact(a, b, c, above), 1);
    EXPECT_EQ(test::orient3d_exact(a, b, c, below), -1);
    EXPECT_EQ(test::orient3d_exact(a, b, c, on), 0);
    // Nearly collinear points far from the origin (a case where the filter must defer).
    const double p[3] = {1e8 + 1.0, 1e8 + 2.0, 1e8 + 3.0};
    const double q[3] = {1e8 + 2.0, 1e8 + 4.0, 1e8 + 6.0};
    const double r[3] = {1e8 + 3.0, 1e8 + 6.0, 1e8 + 9.0};
    const double s[3] = {1e8, 1e8 + 0x1p-20, 1e8};
    EXPECT_EQ(test::orient3d_exact(p, q, r, s), 0);
}

/// Closed, manifold, with `components` spheres' Euler characteristic, no degenerate triangle
/// and no two triangles intersecting (exactly, on the stored float positions).
void expect_closed_and_embedded(const MarchingCubesResult& result, std::size_t components,
                                const std::string& what)
{
    const MeshTopology topo = analyze_topology(result.mesh);
    EXPECT_TRUE(topo.is_oriented_manifold()) << what;
    EXPECT_EQ(topo.boundary_edges, 0U) << what;
    EXPECT_EQ(topo.components, components) << what;
    EXPECT_EQ(topo.euler_characteristic, 2 * static_cast<std::int64_t>(components)) << what;
    const test::SelfIntersections found = test::find_self_intersections(result.mesh);
    EXPECT_TRUE(found.degenerate.empty()) << what << ": " << found.degenerate.size();
    EXPECT_TRUE(found.pairs.empty()) << what << ": " << found.pairs.size() << " pairs, e.g. "
                                     << (found.pairs.empty() ? 0 : found.pairs[0].first) << ", "
                                     << (found.pairs.empty() ? 0 : found.pairs[0].second);
}

TEST(MarchingCubes, SurfacesThroughGridCornersStayClosedAndEmbedded)
{
    // Corners exactly on the surface (f = 0) put vertices at the ends of their edges: boxes
    // whose faces lie on grid planes, spheres centred on a grid corner with a radius of whole
    // cells, and their unions, where the sheets meet along grid lines.
    const double h = 0.125;
    const CellGrid grid{.origin = Vec3d(-2.0, -2.0, -2.0), .cell = h, .cells = {32, 32, 32}};
    const auto box = make_box(Vec3d(-1.0, -0.75, -0.5), Vec3d(0.5, 0.75, 1.0));
    const auto sphere = make_sphere(Vec3d(0.5, 0.0, 0.0), 0.75);
    const auto small = make_sphere(Vec3d(-1.0, -0.75, 1.0), 0.5);
    struct Case
    {
        std::shared_ptr<const Field> field;
        std::size_t components;
        const char* what;
    };
    const std::vector<Case> cases = {
        {box, 1, "box on grid planes"},
        {sphere, 1, "sphere through grid corners"},
        {make_union({box, sphere}), 1, "box and sphere"},
        {make_union({box, sphere, small}), 1, "box and two spheres"},
        {make_difference(box, sphere), 1, "box minus sphere"},
        {make_intersection({box, sphere}), 1, "box and sphere intersected"},
    };
    for (const Case& c : cases)
    {
        const MarchingCubesResult result = marching_cubes(*c.field, grid);
        ASSERT_GT(result.mesh.face_count(), 0U) << c.what;
        EXPECT_EQ(result.stats.degenerate_kept, 0U) << c.what;
        expect_closed_and_embedded(result, c.components, c.what);
    }
}

TEST(MarchingCubes, SurfacesFarApartOnAHugeGridStayClosedAndEmbedded)
{
    // Two small spheres 500000 cells apart: float32 positions then resolve about 1/30 of a
    // cell, so tiny corner triangles are crushed by rounding unless the corner margin grows with
    // it, and any triangle left with zero area is flipped away rather than dropped.
    const double h = 1.0 / 64.0;
    const CellGrid grid{.origin = Vec3d::Zero(), .cell = h, .cells = {1 << 19, 8, 8}};
    // Both pass through grid corners (centred on one, a radius of whole cells), which puts
    // vertices at the corner margin.
    const auto near = make_sphere(Vec3d(4.0 * h, 4.0 * h, 4.0 * h), 3.0 * h);
    const auto far = make_union(
        {make_sphere(Vec3d(500000.0 * h, 4.0 * h, 4.0 * h), 3.0 * h),
         make_box(Vec3d(499998.0 * h, 2.0 * h, 2.0 * h), Vec3d(500000.0 * h, 6.0 * h, 5.0 * h))});
    const MarchingCubesResult result = marching_cubes(*make_union({near, far}), grid);
    expect_closed_and_embedded(result, 2, "two spheres far apart");
    EXPECT_EQ(result.stats.degenerate_kept, 0U);
}

TEST(MarchingCubes, SampledTwoSpheresAreClosedAndEmbedded)
{
    const PointCloud samples = sample_shape(Shape::TwoSpheres, {.count = 100000, .seed = 1});
    const PointField field(
        compute_surfels(samples, {.radius_scale = default_field_radius_scale}).surfels);
    const MarchingCubesResult result =
        marching_cubes(field, grid_over(field.bounds(), default_cell_size(field)));
    EXPECT_GT(result.mesh.face_count(), 100000U);
    expect_closed_and_embedded(result, 2, "two sampled spheres");
}

TEST(MarchingCubes, RejectsBadGrids)
{
    const SphereField sphere(Vec3d::Zero(), 1.0);
    EXPECT_THROW((void)grid_over(sphere.bounds(), 0.0), InvalidInput);
    EXPECT_THROW((void)grid_over(sphere.bounds(), -1.0), InvalidInput);
    EXPECT_THROW((void)grid_over(sphere.bounds(), 1e-9), InvalidInput);
    EXPECT_THROW((void)grid_over(Aabb{}, 0.1), InvalidInput);
    EXPECT_THROW((void)cell_for_resolution(sphere.bounds(), 1), InvalidInput);
    EXPECT_NEAR(cell_for_resolution(sphere.bounds(), 100), 0.02, 1e-12);
    // A dense sweep that would not fit is refused rather than attempted.
    const SphereField unseeded(Vec3d::Zero(), 1.0, false);
    EXPECT_THROW((void)marching_cubes(unseeded, grid_over(unseeded.bounds(), 0.002)), InvalidInput);
}

} // namespace
} // namespace pointform
