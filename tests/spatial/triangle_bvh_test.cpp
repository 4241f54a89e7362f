// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// TriangleBvh: exact closest points against an independent brute-force oracle, degenerate
// triangles, bad input, and determinism.

#include "pointform/spatial/triangle_bvh.h"

#include "pointform/core/error.h"
#include "pointform/core/parallel.h"
#include "pointform/spatial/spatial_sort.h"

#include "support/polygon_fan.h"
#include "support/thread_counts.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <vector>

namespace pointform {
namespace {

using Real = long double;
using Vec3r = Eigen::Matrix<Real, 3, 1>;

/// Independent oracle: the minimum over the plane projection (when it falls inside, solved from
/// the 2x2 normal equations in long double) and the three edges (clamped projections).
double oracle_distance(const Vec3d& pd, const Vec3d& ad, const Vec3d& bd, const Vec3d& cd)
{
    const Vec3r p = pd.cast<Real>();
    const Vec3r a = ad.cast<Real>();
    const Vec3r b = bd.cast<Real>();
    const Vec3r c = cd.cast<Real>();
    const auto segment = [&](const Vec3r& s, const Vec3r& e) {
        const Vec3r d = e - s;
        const Real len2 = d.squaredNorm();
        const Real t = len2 > 0 ? std::clamp((p - s).dot(d) / len2, Real(0), Real(1)) : Real(0);
        return (p - (s + t * d)).norm();
    };
    Real best = std::min({segment(a, b), segment(b, c), segment(c, a)});
    const Vec3r ab = b - a;
    const Vec3r ac = c - a;
    const Vec3r ap = p - a;
    const Real g00 = ab.dot(ab);
    const Real g01 = ab.dot(ac);
    const Real g11 = ac.dot(ac);
    const Real det = g00 * g11 - g01 * g01;
    if (det > Real(1e-24) * g00 * g11)
    {
        const Real r0 = ab.dot(ap);
        const Real r1 = ac.dot(ap);
        const Real v = (g11 * r0 - g01 * r1) / det;
        const Real w = (g00 * r1 - g01 * r0) / det;
        if (v >= 0 && w >= 0 && v + w <= 1)
            best = std::min(best, (ap - v * ab - w * ac).norm());
    }
    return static_cast<double>(best);
}

double brute_force_distance(const TriMesh& mesh, const Vec3d& world)
{
    double best = std::numeric_limits<double>::infinity();
    for (const auto& t : mesh.triangles)
        best =
            std::min(best, oracle_distance(world, mesh.vertices.world(t[0]),
                                           mesh.vertices.world(t[1]), mesh.vertices.world(t[2])));
    return best;
}

/// The distance from `world` to the mesh by the BVH's own closest-point routine on every
/// triangle (exactly what the BVH must find, bit for bit).
double exhaustive_distance(const TriMesh& mesh, const Vec3d& world)
{
    double best = std::numeric_limits<double>::infinity();
    for (const Triangle& t : mesh.triangles)
    {
        const Vec3d a = mesh.vertices.world(t[0]);
        const Vec3d b = mesh.vertices.world(t[1]);
        const Vec3d c = mesh.vertices.world(t[2]);
        const Vec3d w = closest_point_barycentric(world, a, b, c);
        best = std::min(best, (world - (w[0] * a + w[1] * b + w[2] * c)).norm());
    }
    return best;
}

/// A triangle soup over shared random vertices in [-1, 1]³, with degenerate triangles mixed in:
/// repeated vertices, single points and exactly collinear triples.
TriMesh random_mesh(std::size_t vertices, std::size_t faces, std::uint64_t seed)
{
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<float> uni(-1.0F, 1.0F);
    std::uniform_int_distribution<std::uint32_t> pick(0, static_cast<std::uint32_t>(vertices - 1));
    TriMesh mesh;
    for (std::size_t i = 0; i < vertices; ++i)
        mesh.vertices.positions.emplace_back(uni(rng), uni(rng), uni(rng));
    for (std::size_t f = 0; f < faces; ++f)
    {
        const std::uint32_t i = pick(rng);
        const std::uint32_t j = pick(rng);
        const std::uint32_t k = pick(rng);
        switch (f % 16)
        {
            case 0:
                mesh.triangles.push_back({i, i, j});
                break;
            case 1:
                mesh.triangles.push_back({k, k, k});
                break;
            default:
                mesh.triangles.push_back({i, j, k});
                break;
        }
    }
    // Exactly collinear: three points on one line with exactly representable coordinates.
    const auto base = static_cast<std::uint32_t>(mesh.vertices.size());
    mesh.vertices.positions.emplace_back(0.25F, -0.5F, 0.125F);
    mesh.vertices.positions.emplace_back(0.5F, -0.25F, 0.125F);
    mesh.vertices.positions.emplace_back(0.75F, 0.0F, 0.125F);
    mesh.triangles.push_back({base, base + 1, base + 2});
    mesh.triangles.push_back({base, base + 2, base + 1});
    return mesh;
}

std::vector<Vec3d> random_queries(std::size_t n, double spread, std::uint64_t seed)
{
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> uni(-spread, spread);
    std::vector<Vec3d> queries(n);
    for (auto& q : queries)
        q = Vec3d(uni(rng), uni(rng), uni(rng));
    return queries;
}

/// An n x n grid of the square [-1, 1]² at z = 0, two triangles a cell.
TriMesh grid_plane(std::uint32_t n)
{
    TriMesh mesh;
    for (std::uint32_t j = 0; j <= n; ++j)
        for (std::uint32_t i = 0; i <= n; ++i)
            mesh.vertices.positions.emplace_back(-1.0F + 2.0F * static_cast<float>(i) / n,
                                                 -1.0F + 2.0F * static_cast<float>(j) / n, 0.0F);
    for (std::uint32_t j = 0; j < n; ++j)
        for (std::uint32_t i = 0; i < n; ++i)
        {
            const std::uint32_t v = j * (n + 1) + i;
            mesh.triangles.push_back({v, v + 1, v + n + 2});
            mesh.triangles.push_back({v, v + n + 2, v + n + 1});
        }
    return mesh;
}

TEST(ClosestPointOnTriangle, EveryRegion)
{
    const Vec3d a(0, 0, 0);
    const Vec3d b(1, 0, 0);
    const Vec3d c(0, 1, 0);
    struct Case
    {
        Vec3d p;
        Vec3d expected;
    };
    const Case cases[] = {
        {{-1, -1, 1}, a},                // vertex a
        {{2, -0.5, 0}, b},               // vertex b
        {{-0.5, 3, -2}, c},              // vertex c
        {{0.5, -1, 2}, {0.5, 0, 0}},     // edge ab
        {{-1, 0.25, 0}, {0, 0.25, 0}},   // edge ac
        {{1, 1, 0.5}, {0.5, 0.5, 0}},    // edge bc
        {{0.2, 0.3, 5}, {0.2, 0.3, 0}},  // face, above
        {{0.1, 0.1, -2}, {0.1, 0.1, 0}}, // face, below
    };
    for (const Case& k : cases)
    {
        const Vec3d w = closest_point_barycentric(k.p, a, b, c);
        const Vec3d q = w[0] * a + w[1] * b + w[2] * c;
        EXPECT_NEAR((q - k.expected).norm(), 0.0, 1e-15) << k.p.transpose();
        EXPECT_NEAR(w.sum(), 1.0, 1e-15);
        EXPECT_GE(w.minCoeff(), 0.0);
    }
}

TEST(ClosestPointOnTriangle, DegenerateTriangles)
{
    const Vec3d p(0.3, 2.0, 0.0);
    // Collinear, a point, a repeated vertex, and a needle 1e-12 wide.
    const Vec3d a(0, 0, 0);
    const Vec3d b(1, 0, 0);
    const Vec3d m(2, 0, 0);
    for (const auto& [u, v, w] : {std::array<Vec3d, 3>{a, b, m}, std::array<Vec3d, 3>{a, m, b},
                                  std::array<Vec3d, 3>{b, b, a}, std::array<Vec3d, 3>{a, a, m},
                                  std::array<Vec3d, 3>{a, Vec3d(0.5, 1e-12, 0), m}})
    {
        const Vec3d bary = closest_point_barycentric(p, u, v, w);
        ASSERT_TRUE(bary.allFinite());
        const Vec3d q = bary[0] * u + bary[1] * v + bary[2] * w;
        EXPECT_NEAR((p - q).norm(), 2.0, 1e-11);
    }
    const Vec3d point(1, 2, 3);
    const Vec3d bary = closest_point_barycentric(Vec3d(1, 2, 5), point, point, point);
    ASSERT_TRUE(bary.allFinite());
    EXPECT_NEAR((bary[0] + bary[1] + bary[2]), 1.0, 1e-15);
}

TEST(TriangleBvh, MatchesBruteForceOnRandomMeshes)
{
    for (const std::size_t leaf : {1U, 4U, 16U})
    {
        const TriMesh mesh = random_mesh(300, 600, 11 + leaf);
        const TriangleBvh bvh(mesh, {.leaf_size = leaf});
        EXPECT_EQ(bvh.face_count(), mesh.face_count());
        // Queries inside, near and far outside the mesh's box.
        for (const double spread : {0.5, 1.5, 20.0})
        {
            for (const Vec3d& q : random_queries(80, spread, 5))
            {
                const TriangleBvh::Hit hit = bvh.closest(q);
                ASSERT_TRUE(hit.found());
                const double truth = brute_force_distance(mesh, q);
                EXPECT_NEAR(hit.distance, truth, 1e-12 * std::max(1.0, truth));
                // The hit is consistent: its point lies on its face at its distance.
                const auto& t = mesh.triangles[hit.face.value];
                const Vec3d on_face = hit.barycentric[0] * mesh.vertices.world(t[0]) +
                                      hit.barycentric[1] * mesh.vertices.world(t[1]) +
                                      hit.barycentric[2] * mesh.vertices.world(t[2]);
                EXPECT_NEAR((on_face - hit.point).norm(), 0.0, 1e-14);
                EXPECT_NEAR((q - hit.point).norm(), hit.distance, 1e-14 * std::max(1.0, truth));
                EXPECT_GE(hit.barycentric.minCoeff(), 0.0);
                EXPECT_NEAR(hit.barycentric.sum(), 1.0, 1e-14);
            }
        }
    }
}

TEST(TriangleBvh, GridPlaneAnalyticDistances)
{
    // A 20 x 20 grid of the square [-1, 1]² at z = 0: distance is |z| above it and the distance
    // to the square's border beyond it.
    const TriMesh mesh = grid_plane(20);
    const TriangleBvh bvh(mesh);
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> uni(-3.0, 3.0);
    for (int k = 0; k < 2000; ++k)
    {
        const Vec3d q(uni(rng), uni(rng), uni(rng));
        const double dx = std::max(std::abs(q.x()) - 1.0, 0.0);
        const double dy = std::max(std::abs(q.y()) - 1.0, 0.0);
        const double truth = std::sqrt(dx * dx + dy * dy + q.z() * q.z());
        EXPECT_NEAR(bvh.distance(q), truth, 1e-12);
    }
}

TEST(TriangleBvh, OnlyDegenerateTriangles)
{
    TriMesh mesh;
    mesh.vertices.positions = {Vec3f(0, 0, 0), Vec3f(1, 0, 0), Vec3f(2, 0, 0), Vec3f(5, 5, 5)};
    mesh.triangles = {{0, 1, 2}, {3, 3, 3}};
    const TriangleBvh bvh(mesh);
    EXPECT_NEAR(bvh.distance(Vec3d(1.5, 0, 2)), 2.0, 1e-15);
    EXPECT_NEAR(bvh.distance(Vec3d(-3, 4, 0)), 5.0, 1e-15);
    EXPECT_NEAR(bvh.distance(Vec3d(5, 5, 7)), 2.0, 1e-15);
    const auto hit = bvh.closest(Vec3d(5, 6, 5));
    EXPECT_EQ(hit.face, FaceId(1));
}

TEST(TriangleBvh, MaxDistanceLimitsTheSearch)
{
    const TriMesh mesh = random_mesh(100, 200, 4);
    const TriangleBvh bvh(mesh);
    for (const Vec3d& q : random_queries(200, 3.0, 9))
    {
        const double truth = bvh.distance(q);
        const auto near = bvh.closest(q, truth * 1.01 + 1e-12);
        ASSERT_TRUE(near.found());
        EXPECT_EQ(near.distance, truth);
        const auto far = bvh.closest(q, truth * 0.99);
        EXPECT_FALSE(far.found());
        EXPECT_TRUE(std::isinf(far.distance));
    }
}

TEST(TriangleBvh, GeoreferencedOriginKeepsPrecision)
{
    TriMesh local = random_mesh(100, 200, 21);
    TriMesh geo = local;
    const Vec3d origin(512345.0, 4123456.0, 250.0);
    geo.vertices.origin = origin;
    const TriangleBvh bvh_local(local);
    const TriangleBvh bvh_geo(geo);
    EXPECT_NEAR((bvh_geo.bounds().min - bvh_local.bounds().min - origin).norm(), 0.0, 1e-8);
    for (const Vec3d& q : random_queries(200, 2.0, 22))
    {
        const auto a = bvh_local.closest(q);
        const auto b = bvh_geo.closest(q + origin);
        EXPECT_NEAR(a.distance, b.distance, 1e-9);
        EXPECT_NEAR((a.point + origin - b.point).norm(), 0.0, 1e-8);
    }
}

TEST(TriangleBvh, BatchMatchesSingleWhateverTheThreadCount)
{
    const TriMesh mesh = random_mesh(300, 600, 31);
    const TriangleBvh bvh(mesh);
    const auto queries = random_queries(20000, 1.5, 32); // several blocks of queries
    const auto runs = test::at_thread_counts([&] { return closest_points(bvh, queries); });
    const auto& one = runs[0];
    ASSERT_EQ(one.size(), queries.size());
    for (std::size_t i = 0; i < queries.size(); ++i)
    {
        for (std::size_t r = 1; r < runs.size(); ++r)
        {
            ASSERT_EQ(one[i].distance, runs[r][i].distance) << r + 1 << " threads";
            ASSERT_EQ(one[i].face, runs[r][i].face) << r + 1 << " threads";
            ASSERT_EQ(one[i].point, runs[r][i].point) << r + 1 << " threads";
        }
        EXPECT_EQ(one[i].distance, bvh.closest(queries[i]).distance);
        EXPECT_EQ(one[i].face, bvh.closest(queries[i]).face);
    }
    PointCloud cloud;
    for (const Vec3d& q : queries)
        cloud.positions.push_back(q.cast<float>());
    const auto distances = distances_to_mesh(bvh, cloud);
    ASSERT_EQ(distances.size(), queries.size());
    for (std::size_t i = 0; i < queries.size(); ++i)
        EXPECT_EQ(distances[i], bvh.distance(cloud.world(i)));
}

TEST(TriangleBvh, LargeMeshExactAndTheSameTreeForAnyThreadCount)
{
    // A wavy 300 x 300 grid (180,000 triangles, in shuffled order): large enough that the top
    // splits bin and partition in parallel blocks and the subtrees are built in parallel.
    TriMesh mesh = grid_plane(300);
    for (Vec3f& p : mesh.vertices.positions)
        p.z() = 0.1F * std::sin(7.0F * p.x()) * std::cos(5.0F * p.y());
    std::shuffle(mesh.triangles.begin(), mesh.triangles.end(), std::mt19937_64(41));
    const auto queries = random_queries(5000, 1.2, 42);
    struct Built
    {
        std::size_t nodes;
        std::vector<TriangleBvh::Hit> hits;
    };
    const auto runs = test::at_thread_counts(
        [&] {
            const TriangleBvh bvh(mesh);
            return Built{bvh.node_count(), closest_points(bvh, queries)};
        },
        {.min_multi_block_loops = 4}, {1, 2, 3});
    for (std::size_t r = 1; r < runs.size(); ++r)
    {
        ASSERT_EQ(runs[r].nodes, runs[0].nodes) << r + 1 << " threads";
        for (std::size_t i = 0; i < queries.size(); ++i)
        {
            ASSERT_EQ(runs[r].hits[i].distance, runs[0].hits[i].distance) << r + 1 << " threads";
            ASSERT_EQ(runs[r].hits[i].face, runs[0].hits[i].face) << r + 1 << " threads";
        }
    }
    // Every 50th query against every triangle, by the same closest-point routine.
    for (std::size_t i = 0; i < queries.size(); i += 50)
        EXPECT_EQ(runs[0].hits[i].distance, exhaustive_distance(mesh, queries[i])) << "query " << i;
}

TEST(TriangleBvh, SubtreesBuiltAtOnceSplitInBlocksOfTheirOwn)
{
    // Blocks of 256 groups: ranges of 1,024 and more are split in blocks, inside the subtrees
    // that are built at once too, as those of meshes of millions of faces are at the default block
    // (a buffer shared by those subtrees once corrupted the tree). A wavy 120 x 120 grid,
    // 28,800 triangles in shuffled order, alone and in groups of 4 (as the refinement builds it).
    TriMesh mesh = grid_plane(120);
    for (Vec3f& p : mesh.vertices.positions)
        p.z() = 0.15F * std::sin(6.0F * p.x()) * std::cos(4.0F * p.y());
    std::shuffle(mesh.triangles.begin(), mesh.triangles.end(), std::mt19937_64(43));
    const auto queries = random_queries(1000, 1.2, 44);
    const std::vector<TriangleBvh::Hit> reference = closest_points(TriangleBvh(mesh), queries);
    for (const std::size_t group : {1U, 4U})
    {
        struct Built
        {
            std::size_t nodes;
            std::vector<TriangleBvh::Hit> hits;
        };
        const auto runs = test::at_thread_counts(
            [&] {
                const TriangleBvh bvh(mesh, {.group_size = group, .build_block = 256});
                return Built{bvh.node_count(), closest_points(bvh, queries)};
            },
            {.min_multi_block_loops = 4}, {1, 2, 3});
        for (std::size_t r = 0; r < runs.size(); ++r)
        {
            ASSERT_EQ(runs[r].nodes, runs[0].nodes) << r + 1 << " threads, groups of " << group;
            for (std::size_t i = 0; i < queries.size(); ++i)
            {
                // Exact, as the default build's; the same tree at every thread count.
                ASSERT_EQ(runs[r].hits[i].distance, reference[i].distance)
                    << "query " << i << ", " << r + 1 << " threads, groups of " << group;
                ASSERT_EQ(runs[r].hits[i].face, runs[0].hits[i].face) << r + 1 << " threads";
            }
        }
    }
    // Every 25th query against every triangle, by the same closest-point routine.
    for (std::size_t i = 0; i < queries.size(); i += 25)
        EXPECT_EQ(reference[i].distance, exhaustive_distance(mesh, queries[i])) << "query " << i;
}

TEST(TriangleBvh, GroupsOfFacesGiveTheSameDistances)
{
    // The children of a 1-to-4 split kept together: the same distances as one face at a time,
    // and each hit's face among those at that distance.
    TriMesh mesh = grid_plane(60); // 7,200 triangles
    for (Vec3f& p : mesh.vertices.positions)
        p.z() = 0.2F * std::sin(3.0F * p.x() + 2.0F * p.y());
    const TriangleBvh single(mesh);
    const TriangleBvh grouped(mesh, {.group_size = 4});
    EXPECT_EQ(grouped.face_count(), mesh.face_count());
    EXPECT_LT(grouped.node_count(), single.node_count());
    for (const Vec3d& q : random_queries(3000, 1.5, 51))
    {
        const TriangleBvh::Hit a = single.closest(q);
        const TriangleBvh::Hit b = grouped.closest(q);
        ASSERT_TRUE(b.found());
        EXPECT_EQ(a.distance, b.distance);
        const auto& t = mesh.triangles[b.face.value];
        const Vec3d w = closest_point_barycentric(
            q, mesh.vertices.world(t[0]), mesh.vertices.world(t[1]), mesh.vertices.world(t[2]));
        EXPECT_EQ((q - (w[0] * mesh.vertices.world(t[0]) + w[1] * mesh.vertices.world(t[1]) +
                        w[2] * mesh.vertices.world(t[2])))
                      .norm(),
                  b.distance);
    }
    mesh.triangles.pop_back();
    EXPECT_THROW(TriangleBvh(mesh, {.group_size = 4}), InvalidInput);
}

TEST(TriangleBvh, BoundsOnlyPruneTheNearestTriangles)
{
    const TriMesh mesh = random_mesh(300, 600, 41);
    const TriangleBvh bvh(mesh);
    const auto queries = random_queries(5000, 1.5, 42);
    PointCloud cloud;
    for (const Vec3d& q : queries)
        cloud.positions.push_back(q.cast<float>());
    std::vector<TriangleBvh::Hit> truth;
    for (std::size_t i = 0; i < cloud.size(); ++i)
        truth.push_back(bvh.closest(cloud.world(i)));
    // Bounds as a caller makes them: the distance to some triangle (valid: never below the
    // nearest's), to the nearest itself (tight), half the true distance (wrong), or none.
    std::mt19937 random(43);
    std::uniform_int_distribution<std::size_t> any_face(0, mesh.face_count() - 1);
    std::vector<double> some_face(cloud.size());
    std::vector<double> tight(cloud.size());
    std::vector<double> wrong(cloud.size());
    std::vector<double> none(cloud.size(), std::numeric_limits<double>::quiet_NaN());
    for (std::size_t i = 0; i < cloud.size(); ++i)
    {
        const Triangle& t = mesh.triangles[any_face(random)];
        const Vec3d p = cloud.world(i);
        const Vec3d a = mesh.vertices.positions[t[0]].cast<double>();
        const Vec3d b = mesh.vertices.positions[t[1]].cast<double>();
        const Vec3d c = mesh.vertices.positions[t[2]].cast<double>();
        const Vec3d w = closest_point_barycentric(p, a, b, c);
        some_face[i] = (p - (w[0] * a + w[1] * b + w[2] * c)).norm();
        tight[i] = truth[i].distance;
        wrong[i] = 0.5 * truth[i].distance;
    }
    for (const auto* bounds : {&some_face, &tight, &wrong, &none})
    {
        const NearestTriangles found = nearest_triangles(bvh, cloud, *bounds);
        ASSERT_EQ(found.distances.size(), cloud.size());
        for (std::size_t i = 0; i < cloud.size(); ++i)
        {
            ASSERT_EQ(found.distances[i], truth[i].distance) << i;
            ASSERT_EQ(found.faces[i], truth[i].face.value) << i;
        }
    }
    const NearestTriangles unbounded = nearest_triangles(bvh, cloud);
    for (std::size_t i = 0; i < cloud.size(); ++i)
        ASSERT_EQ(unbounded.faces[i], truth[i].face.value);
    EXPECT_THROW((void)nearest_triangles(bvh, cloud, std::vector<double>(3, 1.0)), InvalidInput);
}

TEST(TriangleBvh, AGivenQueryOrderChangesNoResult)
{
    const TriMesh mesh = random_mesh(300, 600, 44);
    const TriangleBvh bvh(mesh);
    PointCloud cloud;
    for (const Vec3d& q : random_queries(4000, 1.5, 45))
        cloud.positions.push_back(q.cast<float>());
    const NearestTriangles sorted = nearest_triangles(bvh, cloud);
    // The order a caller keeps between passes (spatial_order()), and any other permutation: a
    // reversed one, and a shuffled one, which only runs the queries beside other neighbours.
    std::vector<std::uint32_t> keep = spatial_order(cloud.positions);
    std::vector<std::uint32_t> reversed(keep.rbegin(), keep.rend());
    std::vector<std::uint32_t> shuffled = keep;
    std::shuffle(shuffled.begin(), shuffled.end(), std::mt19937(46));
    for (const auto* order : {&keep, &reversed, &shuffled})
    {
        const NearestTriangles found = nearest_triangles(bvh, cloud, {}, {.order = *order});
        const std::vector<double> distances = distances_to_mesh(bvh, cloud, {.order = *order});
        for (std::size_t i = 0; i < cloud.size(); ++i)
        {
            ASSERT_EQ(found.distances[i], sorted.distances[i]) << i;
            ASSERT_EQ(found.faces[i], sorted.faces[i]) << i;
            ASSERT_EQ(distances[i], sorted.distances[i]) << i;
        }
    }
    // An order of other points, with an index past the queries, or with one query twice (and
    // so another never) is refused.
    const std::vector<std::uint32_t> short_order(keep.begin(), keep.end() - 1);
    EXPECT_THROW((void)nearest_triangles(bvh, cloud, {}, {.order = short_order}), InvalidInput);
    std::vector<std::uint32_t> past = keep;
    past[7] = static_cast<std::uint32_t>(cloud.size());
    EXPECT_THROW((void)distances_to_mesh(bvh, cloud, {.order = past}), InvalidInput);
    std::vector<std::uint32_t> twice = keep;
    twice[7] = twice[8];
    EXPECT_THROW((void)distances_to_mesh(bvh, cloud, {.order = twice}), InvalidInput);
}

TEST(TriangleBvh, AnyWithinAgreesWithTheClosestDistance)
{
    const TriMesh mesh = random_mesh(300, 600, 51);
    const TriangleBvh bvh(mesh);
    std::mt19937 random(52);
    std::uniform_real_distribution<double> factor(0.0, 2.0);
    for (const Vec3d& q : random_queries(3000, 1.5, 53))
    {
        const double d = bvh.closest(q).distance;
        EXPECT_FALSE(bvh.any_within(q, d * (1.0 - 1e-9)));
        EXPECT_TRUE(bvh.any_within(q, d * (1.0 + 1e-9) + 1e-300));
        const double r = factor(random) * d;
        EXPECT_EQ(bvh.any_within(q, r), d < r) << r << " " << d;
    }
    EXPECT_FALSE(bvh.any_within(Vec3d::Zero(), 0.0));
    EXPECT_FALSE(bvh.any_within(Vec3d::Constant(std::nan("")), 1.0));
}

TEST(TriangleBoxDepth, AnalyticValues)
{
    // A 20 x 20 grid of [-1, 1]²: 800 triangles whose boxes are the 0.1 x 0.1 cells, twice
    // over, in a 2 x 2 box: depth 800 × 0.01 / 4 = 2.
    const TriMesh grid = grid_plane(20);
    EXPECT_NEAR(triangle_box_depth(grid), 2.0, 1e-5);

    // An n-gon fanned from vertex (1, 0): the sliver to the edge at angle φ has a box of area
    // (1 − cos φ)|sin φ|, whose mean over φ is 2/π; the whole box is 2 x 2, so the depth is
    // (n − 2)(2/π)/4 = (n − 2)/(2π).
    for (const std::size_t vertices : {1000U, 100000U})
    {
        const double expected = static_cast<double>(vertices - 2) / (2.0 * std::numbers::pi);
        EXPECT_NEAR(triangle_box_depth(test::polygon_fan_mesh(vertices)), expected,
                    0.01 * expected);
    }

    // All triangles on one point: every query tests them all.
    TriMesh point;
    point.vertices.positions = {Vec3f(1, 2, 3)};
    point.triangles = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
    EXPECT_EQ(triangle_box_depth(point), 3.0);

    TriMesh bad = point;
    bad.triangles.push_back({0, 0, 1});
    EXPECT_THROW((void)triangle_box_depth(bad), InvalidInput);
}

TEST(TriangleBoxDepth, QueryWorkRefusesOnlyOverlappingSliversAtScale)
{
    const TriMesh fan = test::polygon_fan_mesh(100000);    // depth 15,915
    EXPECT_NO_THROW(check_query_work(fan, 1000, "test"));  // 1.6e7 tests
    EXPECT_NO_THROW(check_query_work(fan, 60000, "test")); // 9.5e8 tests
    try
    {
        check_query_work(fan, 200000, "point-to-mesh distance"); // 3.2e9 tests
        ADD_FAILURE() << "the 100,000-gon's fan was not refused";
    }
    catch (const InvalidInput& e)
    {
        const std::string message = e.what();
        EXPECT_NE(message.find("point-to-mesh distance"), std::string::npos) << message;
        EXPECT_NE(message.find("15916 of its 99998 triangles"), std::string::npos) << message;
        EXPECT_NE(message.find("retriangulate"), std::string::npos) << message;
    }
    // A larger budget admits it. A 1,000-gon (depth 159) at a million queries is 1.6e8 tests:
    // within the budget.
    EXPECT_NO_THROW(check_query_work(fan, 200000, "test", 1e10));
    EXPECT_NO_THROW(check_query_work(test::polygon_fan_mesh(1000), 1000000, "test"));
    // Well-shaped meshes are never refused, however many queries.
    const TriMesh triangle = test::polygon_fan_mesh(3); // depth 1
    EXPECT_NO_THROW(check_query_work(triangle, std::size_t{1} << 40, "test"));
}

TEST(TriangleBvh, BadInputIsRejected)
{
    TriMesh empty;
    empty.vertices.positions = {Vec3f(0, 0, 0)};
    EXPECT_THROW(TriangleBvh{empty}, InvalidInput);

    TriMesh out_of_range;
    out_of_range.vertices.positions = {Vec3f(0, 0, 0), Vec3f(1, 0, 0), Vec3f(0, 1, 0)};
    out_of_range.triangles = {{0, 1, 3}};
    EXPECT_THROW(TriangleBvh{out_of_range}, InvalidInput);

    TriMesh not_finite = out_of_range;
    not_finite.triangles = {{0, 1, 2}};
    not_finite.vertices.positions[1].x() = std::numeric_limits<float>::quiet_NaN();
    EXPECT_THROW(TriangleBvh{not_finite}, InvalidInput);
}

} // namespace
} // namespace pointform
