// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/polygonize/refine.h"

#include "pointform/core/error.h"
#include "pointform/core/parallel.h"
#include "pointform/geometry/mesh_topology.h"
#include "pointform/geometry/shapes.h"
#include "pointform/hermite/radius.h"
#include "pointform/implicit/point_field.h"
#include "pointform/implicit/primitives.h"
#include "pointform/metrics/quality.h"
#include "pointform/polygonize/projection.h"
#include "pointform/spatial/kd_tree.h"

#include "relax.h"
#include "support/test_meshes.h"
#include "support/thread_counts.h"
#include "thin_plate.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <set>
#include <tuple>
#include <utility>

namespace pointform {
namespace {

/// The octahedron inscribed in the unit sphere, outward faces.
TriMesh octahedron()
{
    TriMesh mesh;
    mesh.vertices.positions = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    mesh.triangles = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4},
                      {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
    return mesh;
}

constexpr double torus_major = 1.0;
constexpr double torus_minor = 0.35;

/// A coarse torus about z: an nu × nv grid of quads on the surface, each split in two,
/// counter-clockwise seen from outside.
TriMesh torus_grid(std::uint32_t nu, std::uint32_t nv)
{
    TriMesh mesh;
    for (std::uint32_t j = 0; j < nv; ++j)
        for (std::uint32_t i = 0; i < nu; ++i)
        {
            const double u = 2.0 * std::numbers::pi * i / nu;
            const double v = 2.0 * std::numbers::pi * j / nv;
            const double rho = torus_major + torus_minor * std::cos(v);
            mesh.vertices.positions.emplace_back(static_cast<float>(rho * std::cos(u)),
                                                 static_cast<float>(rho * std::sin(u)),
                                                 static_cast<float>(torus_minor * std::sin(v)));
        }
    const auto at = [&](std::uint32_t i, std::uint32_t j) {
        return (j % nv) * nu + (i % nu);
    };
    for (std::uint32_t j = 0; j < nv; ++j)
        for (std::uint32_t i = 0; i < nu; ++i)
        {
            mesh.triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
            mesh.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
        }
    return mesh;
}

double torus_distance(const Vec3d& p)
{
    return std::hypot(std::hypot(p.x(), p.y()) - torus_major, p.z()) - torus_minor;
}

/// A unit sphere sampled with exact normals, radii 1.5 × the 16th neighbour's distance,
/// without the samples within angle `cap` of `cap_axis` (no cap if cap = 0).
PointCloud sampled_sphere(std::size_t count, const Vec3d& cap_axis = Vec3d::UnitZ(),
                          double cap = 0.0)
{
    const PointCloud all = sample_shape(Shape::Sphere, {.count = count, .seed = 5});
    PointCloud cloud;
    const Vec3d axis = cap_axis.normalized();
    for (std::size_t i = 0; i < all.size(); ++i)
    {
        const Vec3d p = all.world(i);
        if (cap > 0.0 && p.normalized().dot(axis) > std::cos(cap))
            continue;
        cloud.positions.push_back(all.positions[i]);
        cloud.normals.push_back(all.positions[i].normalized());
    }
    const KdTree tree(cloud.positions);
    cloud.radii = influence_radii(knn_batch(tree, cloud.positions, 17), 1.5);
    return cloud;
}

/// Level meshes and checks common to every refinement on a closed surface.
struct LevelChecks
{
    std::size_t folded = 0;        ///< child faces against their parent
    std::size_t irregular_new = 0; ///< added vertices without valence 6
    bool nested = true;            ///< coarser prefixes identical bit for bit
    std::vector<MeshTopology> topology;
};

LevelChecks check_levels(const MultiresMesh& mesh)
{
    LevelChecks out;
    const TriMesh finest = mesh.level_mesh(mesh.finest_level());
    for (std::size_t level = 0; level < mesh.level_count(); ++level)
    {
        const TriMesh m = mesh.level_mesh(level);
        out.topology.push_back(analyze_topology(m));
        out.nested =
            out.nested && std::equal(m.vertices.positions.begin(), m.vertices.positions.end(),
                                     finest.vertices.positions.begin());
        if (level == 0)
            continue;
        std::vector<std::set<std::uint32_t>> ring(m.vertex_count());
        for (const Triangle& t : m.triangles)
            for (std::size_t k = 0; k < 3; ++k)
            {
                ring[t[k]].insert(t[(k + 1) % 3]);
                ring[t[(k + 1) % 3]].insert(t[k]);
            }
        for (std::size_t v = mesh.vertex_count(level - 1); v < m.vertex_count(); ++v)
            out.irregular_new += ring[v].size() == 6 ? 0 : 1;
        const std::vector<Triangle> parents = mesh.faces(level - 1);
        const auto normal = [&](const Triangle& t) {
            const Vec3d a = mesh.positions()[t[0]];
            return Vec3d((mesh.positions()[t[1]] - a).cross(mesh.positions()[t[2]] - a));
        };
        for (std::size_t c = 0; c < m.face_count(); ++c)
            out.folded += normal(m.triangles[c]).dot(normal(parents[c / 4])) > 0.0 ? 0 : 1;
    }
    return out;
}

/// The smallest angle of any triangle of level `level`, in degrees.
double min_angle_degrees(const MultiresMesh& mesh, std::size_t level)
{
    double smallest = 180.0;
    for (const Triangle& t : mesh.faces(level))
        for (std::size_t k = 0; k < 3; ++k)
        {
            const Vec3d& p = mesh.positions()[t[k]];
            const Vec3d u = (mesh.positions()[t[(k + 1) % 3]] - p).normalized();
            const Vec3d w = (mesh.positions()[t[(k + 2) % 3]] - p).normalized();
            smallest = std::min(
                smallest, std::acos(std::clamp(u.dot(w), -1.0, 1.0)) * 180.0 / std::numbers::pi);
        }
    return smallest;
}

TEST(Projection, FindsTheNearestOutwardCrossing)
{
    const auto sphere = make_sphere(Vec3d::Zero(), 1.0);
    // From inside at x = 0.5 along +x: the crossing at x = 1 (the one at x = -1 goes from
    // outside to inside along +x, and is farther).
    const auto hit = project_to_zero(*sphere, Vec3d(0.5, 0, 0), Vec3d(2, 0, 0), 1.0);
    ASSERT_TRUE(hit);
    EXPECT_NEAR(hit->x(), 1.0, 1e-6);
    // From outside, the search goes backwards along the direction.
    const auto back = project_to_zero(*sphere, Vec3d(0, 1.3, 0), Vec3d(0, 1, 0), 0.5);
    ASSERT_TRUE(back);
    EXPECT_NEAR(back->y(), 1.0, 1e-6);
    // Direction against the gradient: the crossing at y = 1 goes outside-to-inside along −y,
    // so the only valid one is the far side y = −1, out of reach here.
    EXPECT_FALSE(project_to_zero(*sphere, Vec3d(0, 1.3, 0), Vec3d(0, -1, 0), 0.5));
    EXPECT_FALSE(project_to_zero(*sphere, Vec3d(0, 3, 0), Vec3d(0, 1, 0), 0.5)); // out of reach
    EXPECT_FALSE(project_to_zero(*sphere, Vec3d(0, 1, 0), Vec3d::Zero(), 0.5));
    EXPECT_THROW((void)project_to_zero(*sphere, Vec3d::Zero(), Vec3d::UnitX(), 1.0, {.steps = 0}),
                 InvalidInput);
}

/// The unit sphere's distance field, counting its evaluations.
struct CountingSphere : Field
{
    std::shared_ptr<const Field> inner = make_sphere(Vec3d::Zero(), 1.0);
    mutable int evaluations = 0;
    using Field::evaluate;
    [[nodiscard]] FieldSample evaluate(const Vec3d& p) const override
    {
        ++evaluations;
        return inner->evaluate(p);
    }
    [[nodiscard]] Aabb bounds() const override { return inner->bounds(); }
};

TEST(Projection, TheCallersSampleAtTheStartGivesTheSamePoint)
{
    // The caller's sample at p saves the evaluation at p, nothing else.
    const CountingSphere field;
    for (const Vec3d& p : {Vec3d(0.5, 0.2, 0.1), Vec3d(0.0, 1.3, 0.0), Vec3d(1.0, 0.0, 0.0)})
    {
        for (const Vec3d& direction : {Vec3d(p.normalized()), Vec3d(-p.normalized())})
        {
            field.evaluations = 0;
            const auto plain = project_to_zero(field, p, direction, 0.6);
            const int plain_evaluations = field.evaluations;
            const FieldSample at_p = field.inner->evaluate(p);
            field.evaluations = 0;
            const auto given = project_to_zero(field, at_p, p, direction, 0.6);
            ASSERT_EQ(plain.has_value(), given.has_value());
            if (plain)
            {
                EXPECT_EQ(*plain, *given);
            }
            EXPECT_LE(field.evaluations, plain_evaluations - 1);
        }
    }
}

TEST(Projection, APointNearTheSurfaceBracketsItsCrossingAtTwiceTheNewtonStep)
{
    const CountingSphere field;
    const double reach = 1.0;
    const double tolerance = ProjectionOptions{}.relative_tolerance * reach;
    // Inside and outside, a thousandth of the reach off the unit sphere, along the radius (the
    // field linear along it) and across it at 60° (curved): the crossing nearest p, within the
    // tolerance of the sphere, in at most 3 and 4 evaluations (a march by steps of reach / 16
    // and regula falsi on that bracket took 3 and 6 from inside).
    for (const double off : {-1e-3, 1e-3})
    {
        const Vec3d p = (1.0 + off) * Vec3d(0.48, 0.6, 0.64);
        field.evaluations = 0;
        const auto radial = project_to_zero(field, p, p, reach);
        ASSERT_TRUE(radial);
        EXPECT_NEAR(radial->norm(), 1.0, tolerance);
        EXPECT_NEAR(radial->normalized().dot(p.normalized()), 1.0, 1e-12);
        EXPECT_LE(field.evaluations, 3);

        const Vec3d tilted = (std::sqrt(0.75) * p.unitOrthogonal() + 0.5 * p.normalized());
        field.evaluations = 0;
        const auto across = project_to_zero(field, p, tilted, reach);
        ASSERT_TRUE(across);
        EXPECT_NEAR(across->norm(), 1.0, tolerance);
        EXPECT_NEAR((*across - p).normalized().dot(tilted.normalized()) * (off < 0.0 ? 1.0 : -1.0),
                    1.0, 1e-9);
        EXPECT_LE(field.evaluations, 4);
    }
    // Already on it within the tolerance: p itself, at one evaluation.
    const Vec3d on = (1.0 + 0.25 * tolerance) * Vec3d::UnitZ();
    field.evaluations = 0;
    const auto same = project_to_zero(field, on, Vec3d::UnitZ(), reach);
    ASSERT_TRUE(same);
    EXPECT_EQ(*same, on);
    EXPECT_EQ(field.evaluations, 1);
}

TEST(Projection, NewtonReachesTheNearestZero)
{
    // On a sphere's distance field one step lands on the radial point.
    const auto sphere = make_sphere(Vec3d::Zero(), 1.0);
    const Vec3d p(0.5, 0.3, 0.1);
    const auto hit = newton_to_zero(*sphere, p, 1.0);
    ASSERT_TRUE(hit);
    EXPECT_NEAR(hit->norm(), 1.0, 1e-7);
    EXPECT_NEAR(hit->normalized().dot(p.normalized()), 1.0, 1e-12);
    // Inside a box next to its edge x = y = 1 (a crease's corner cut by a midpoint): the nearest
    // face, not the corner along the diagonal.
    const auto box = make_box(Vec3d(-1, -1, -1), Vec3d(1, 1, 1));
    const auto face = newton_to_zero(*box, Vec3d(0.9, 0.8, 0.0), 0.5);
    ASSERT_TRUE(face);
    EXPECT_NEAR(face->x(), 1.0, 1e-7);
    EXPECT_NEAR(face->y(), 0.8, 1e-7);
    EXPECT_FALSE(newton_to_zero(*sphere, Vec3d(0, 0, 3), 0.5)); // farther than the reach
    EXPECT_FALSE(newton_to_zero(*sphere, Vec3d(0, 0, 3), 0.0));
    EXPECT_FALSE(newton_to_zero(*sphere, Vec3d::Constant(std::nan("")), 1.0));
}

TEST(Refine, OctahedronOnAnalyticSphere)
{
    const auto sphere = make_sphere(Vec3d::Zero(), 1.0);
    MultiresMesh mesh(octahedron());
    std::vector<double> min_angles;
    for (std::size_t level = 1; level <= 4; ++level)
    {
        const RefineLevelStats stats = refine_once(mesh, *sphere);
        EXPECT_EQ(stats.level, level);
        EXPECT_EQ(stats.faces, 8U << (2 * level));
        EXPECT_EQ(stats.vertices, mesh.vertex_count());
        EXPECT_EQ(stats.unprojected, 0U);
        EXPECT_EQ(stats.folded_faces, 0U);
        EXPECT_FALSE(stats.hausdorff); // no samples given
        min_angles.push_back(min_angle_degrees(mesh, level));
    }
    // Every vertex on the sphere (the root finder's tolerance is 1e-6 of the edge length).
    for (const Vec3d& p : mesh.positions())
        ASSERT_NEAR(p.norm(), 1.0, 1e-6);
    const LevelChecks checks = check_levels(mesh);
    EXPECT_TRUE(checks.nested);
    EXPECT_EQ(checks.folded, 0U);
    EXPECT_EQ(checks.irregular_new, 0U);
    for (const MeshTopology& t : checks.topology)
    {
        EXPECT_TRUE(t.is_oriented_manifold());
        EXPECT_TRUE(t.is_closed());
        EXPECT_EQ(t.euler_characteristic, 2);
    }
    // Relaxation keeps triangles well shaped: the octahedron's 45° right angles-split triangles
    // do not degenerate with depth.
    EXPECT_GT(*std::min_element(min_angles.begin(), min_angles.end()), 30.0);
}

/// Largest over smallest face area of a level, and the largest depth of a face's centroid
/// below the unit sphere (how far the flat faces sag: the mesh's distance to the surface).
std::pair<double, double> area_ratio_and_sag(const MultiresMesh& mesh, std::size_t level)
{
    const std::span<const Vec3d> x = mesh.positions();
    double smallest = std::numeric_limits<double>::max();
    double largest = 0.0;
    double sag = 0.0;
    for (const Triangle& t : mesh.faces(level))
    {
        const double area = 0.5 * (x[t[1]] - x[t[0]]).cross(x[t[2]] - x[t[0]]).norm();
        smallest = std::min(smallest, area);
        largest = std::max(largest, area);
        sag = std::max(sag, 1.0 - ((x[t[0]] + x[t[1]] + x[t[2]]) / 3.0).norm());
    }
    return {largest / smallest, sag};
}

TEST(Refine, AcrossEdgeRelaxationKeepsFaceSizesEven)
{
    // The octahedron's six vertices have valence 4. The full umbrella move shifts the new
    // vertices next to them along their parent edges every level, and the shifts compound; the
    // move across the edge keeps every split ratio, so the faces stay as even as the projected
    // midpoint subdivision makes them.
    const auto sphere = make_sphere(Vec3d::Zero(), 1.0);
    std::array<std::pair<double, double>, 3> measured{};
    const std::array<std::pair<Relaxation, int>, 3> runs = {
        {{Relaxation::AcrossEdge, 1}, {Relaxation::Umbrella, 1}, {Relaxation::AcrossEdge, 0}}};
    for (std::size_t r = 0; r < runs.size(); ++r)
    {
        MultiresMesh mesh(octahedron());
        RefineOptions options;
        options.relaxation = runs[r].first;
        options.relax_iterations = runs[r].second;
        for (int level = 0; level < 5; ++level)
            (void)refine_once(mesh, *sphere, options);
        measured[r] = area_ratio_and_sag(mesh, 5);
        EXPECT_TRUE(check_levels(mesh).nested);
    }
    const auto [across_ratio, across_sag] = measured[0];
    const auto [umbrella_ratio, umbrella_sag] = measured[1];
    const auto [none_ratio, none_sag] = measured[2];
    // Measured at level 5: area ratios 1.49 (across), 33 (umbrella), 1.80 (no relaxation).
    EXPECT_GT(umbrella_ratio, 5.0 * across_ratio); // the umbrella's sizes compound
    EXPECT_LT(across_ratio, none_ratio);           // and the move across still evens them out
    EXPECT_LT(across_sag, umbrella_sag);
    EXPECT_LT(across_sag, none_sag);
}

TEST(Refine, TorusKeepsGenusOne)
{
    const auto torus = make_torus(Vec3d::Zero(), Vec3d::UnitZ(), torus_major, torus_minor);
    for (const Predictor predictor : {Predictor::Midpoint, Predictor::Butterfly})
    {
        MultiresMesh mesh(torus_grid(8, 4));
        std::size_t unprojected = 0;
        for (int level = 0; level < 3; ++level)
            unprojected += refine_once(mesh, *torus, {.predictor = predictor}).unprojected;
        EXPECT_EQ(unprojected, 0U);
        // Base vertices are float-rounded; new ones are exact up to the root finder.
        for (const Vec3d& p : mesh.positions())
            ASSERT_NEAR(torus_distance(p), 0.0, 1e-6);
        const LevelChecks checks = check_levels(mesh);
        EXPECT_TRUE(checks.nested);
        EXPECT_EQ(checks.folded, 0U);
        EXPECT_EQ(checks.irregular_new, 0U);
        for (const MeshTopology& t : checks.topology)
        {
            EXPECT_TRUE(t.is_oriented_manifold());
            EXPECT_TRUE(t.is_closed());
            EXPECT_EQ(t.euler_characteristic, 0);
            EXPECT_EQ(t.components, 1U);
        }
    }
}

TEST(Refine, SampledSphereStopsBelowTheSamplingDensity)
{
    const PointCloud samples = sampled_sphere(8000);
    const PointField field(samples);
    MultiresMesh mesh(test::icosphere(0));
    const RefineReport report =
        refine(mesh, field, samples, {.max_level = 6, .stop_rule = StopRule::Paper});
    const double density = report.sampling_density;
    // 8000 area-uniform samples on the unit sphere are about sqrt(4π/8000) ≈ 0.04 apart; the
    // median nearest-neighbour distance is a fraction of that.
    EXPECT_GT(density, 0.005);
    EXPECT_LT(density, 0.04);
    ASSERT_EQ(report.stop, RefineStop::BelowSamplingDensity);
    ASSERT_FALSE(report.levels.empty());
    EXPECT_LT(*report.levels.back().hausdorff, density);
    EXPECT_LT(mesh.finest_level(), 6U);
    // Hausdorff from the samples non-increasing with level.
    double previous = report.initial_hausdorff;
    for (const RefineLevelStats& s : report.levels)
    {
        EXPECT_LE(*s.hausdorff, previous) << "level " << s.level;
        EXPECT_LE(*s.mean_distance, *s.hausdorff);
        EXPECT_EQ(s.unprojected, 0U);
        previous = *s.hausdorff;
    }
    // Every vertex within the sampling density of the true sphere.
    for (const Vec3d& p : mesh.positions())
        ASSERT_NEAR(p.norm(), 1.0, density);
    const LevelChecks checks = check_levels(mesh);
    EXPECT_TRUE(checks.nested);
    EXPECT_EQ(checks.folded, 0U);
    EXPECT_EQ(checks.irregular_new, 0U);
    for (const MeshTopology& t : checks.topology)
    {
        EXPECT_TRUE(t.is_closed());
        EXPECT_EQ(t.euler_characteristic, 2);
    }
}

TEST(Refine, HoleLeavesVerticesAtThePrediction)
{
    // The cap of angular radius 25° around the centre of the octahedron's first face has no
    // samples; the octahedron's vertices and its edges' midpoints (35° away) are outside it.
    const Vec3d axis = Vec3d(1, 1, 1).normalized();
    const double cap = 25.0 * std::numbers::pi / 180.0;
    const PointCloud samples = sampled_sphere(6000, axis, cap);
    const PointField field(samples);
    MultiresMesh mesh(octahedron());
    std::size_t unprojected = 0;
    for (int level = 0; level < 3; ++level)
    {
        const RefineLevelStats stats = refine_once(mesh, field, {}, &samples);
        EXPECT_EQ(stats.folds_unresolved, 0U);
        // Vertices left at their prediction (the midpoint) are exactly the unprojected ones.
        std::size_t at_midpoint = 0;
        for (std::size_t v = mesh.vertex_count(stats.level - 1); v < mesh.vertex_count(); ++v)
        {
            const ParentEdge e = mesh.parent_edge(static_cast<std::uint32_t>(v));
            const Vec3d& p = mesh.positions()[v];
            const double angle = std::acos(std::clamp(p.normalized().dot(axis), -1.0, 1.0));
            if (p == Vec3d(0.5 * (mesh.positions()[e.a] + mesh.positions()[e.b])))
            {
                ++at_midpoint;
                EXPECT_LT(angle, cap + 0.1)
                    << "vertex " << v; // only in (or at the rim of) the hole
            }
            else
            {
                EXPECT_NEAR(p.norm(), 1.0, 0.02) << "vertex " << v; // on the sampled surface
            }
        }
        EXPECT_EQ(at_midpoint, stats.unprojected);
        unprojected += stats.unprojected;
    }
    EXPECT_GT(unprojected, 0U);
    const LevelChecks checks = check_levels(mesh);
    EXPECT_TRUE(checks.nested);
    EXPECT_EQ(checks.folded, 0U);
}

/// A field defined nowhere: every new vertex stays at its prediction.
class NowhereField final : public Field
{
public:
    [[nodiscard]] FieldSample evaluate(const Vec3d& p) const override
    {
        return {p.norm() - 1.0, p.normalized(), false};
    }
    using Field::evaluate;
    [[nodiscard]] Aabb bounds() const override { return {Vec3d::Constant(-1), Vec3d::Constant(1)}; }
};

TEST(Refine, ButterflyPredictsBetterThanTheMidpoint)
{
    const NowhereField nowhere;
    double worst[2] = {0.0, 0.0};
    for (const Predictor predictor : {Predictor::Midpoint, Predictor::Butterfly})
    {
        // Icosphere level 1: valence-5 and valence-6 vertices, so both stencils are used.
        MultiresMesh mesh(test::icosphere(1));
        const RefineLevelStats stats = refine_once(mesh, nowhere, {.predictor = predictor});
        EXPECT_EQ(stats.unprojected, stats.new_vertices);
        for (std::size_t v = mesh.vertex_count(0); v < mesh.vertex_count(); ++v)
            worst[static_cast<int>(predictor)] = std::max(
                worst[static_cast<int>(predictor)], std::abs(mesh.positions()[v].norm() - 1.0));
    }
    EXPECT_LT(worst[1], 0.25 * worst[0]);

    // Affine invariance: on a flat grid (boundary and interior) predictions stay in the plane,
    // and away from the square's corners (where the 4-point rule rounds the border) inside it.
    MultiresMesh flat(test::square_grid(4));
    refine_once(flat, nowhere, {.predictor = Predictor::Butterfly});
    const auto is_corner = [&](std::uint32_t v) {
        return flat.positions()[v].head<2>().cwiseAbs() == Eigen::Vector2d(1.0, 1.0);
    };
    for (std::size_t v = flat.vertex_count(0); v < flat.vertex_count(); ++v)
    {
        const Vec3d& p = flat.positions()[v];
        EXPECT_EQ(p.z(), 0.0);
        const ParentEdge e = flat.parent_edge(static_cast<std::uint32_t>(v));
        if (!is_corner(e.a) && !is_corner(e.b))
        {
            EXPECT_LE(p.cwiseAbs().maxCoeff(), 1.0 + 1e-12);
        }
    }
}

TEST(Refine, RecordsItsPredictorAndKeepsIt)
{
    const NowhereField nowhere;
    MultiresMesh flat(test::square_grid(2));
    refine_once(flat, nowhere, {.predictor = Predictor::Butterfly});
    EXPECT_EQ(flat.predictor(), Predictor::Butterfly);
    refine_once(flat, nowhere, {.predictor = Predictor::Butterfly});
    EXPECT_THROW(refine_once(flat, nowhere, {.predictor = Predictor::Midpoint}), InvalidInput);
    EXPECT_EQ(flat.level_count(), 3U);
}

/// `count` samples of the unit sphere with isotropic Gaussian noise of `sigma` (absolute), with
/// the true normals.
PointCloud noisy_sphere(std::size_t count, double sigma)
{
    // sample_shape's noise is relative to the diagonal of the samples' box (2√3 for the sphere).
    PointCloud cloud = sample_shape(
        Shape::Sphere, {.count = count, .seed = 9, .noise = sigma / (2.0 * std::sqrt(3.0))});
    const KdTree tree(cloud.positions);
    cloud.radii = influence_radii(knn_batch(tree, cloud.positions, 17), 1.5);
    return cloud;
}

/// Largest |‖p‖ − 1| over the vertices of the finest level.
double sphere_error(const MultiresMesh& mesh)
{
    double error = 0.0;
    for (std::size_t v = 0; v < mesh.vertex_count(); ++v)
        error = std::max(error, std::abs(mesh.world(static_cast<std::uint32_t>(v)).norm() - 1.0));
    return error;
}

TEST(RefineAutomaticStop, CleanSphereRefinesToTheVertexBudget)
{
    // A clean sphere: every level brings the mesh about four times closer to the samples, so the
    // budget (the number of samples) is what stops it, at the deepest level that fits.
    const PointCloud samples = sampled_sphere(20000);
    const PointField field(samples);
    MultiresMesh mesh(test::icosphere(0));
    const RefineReport report = refine(mesh, field, samples);
    EXPECT_EQ(report.stop_rule, StopRule::Automatic);
    EXPECT_EQ(report.vertex_budget, samples.size());
    ASSERT_EQ(report.stop, RefineStop::VertexBudget);
    EXPECT_LE(mesh.vertex_count(), samples.size());
    // The next level (V + E = 4V − 6 on a closed genus-0 mesh) would not fit.
    EXPECT_GT(4 * mesh.vertex_count() - 6, samples.size());
    ASSERT_FALSE(report.levels.empty());
    double previous = report.initial_robust_distance;
    for (const RefineLevelStats& s : report.levels)
    {
        ASSERT_TRUE(s.robust_distance && s.p90_distance);
        EXPECT_LT(*s.robust_distance, 0.8 * previous) << "level " << s.level;
        EXPECT_LE(*s.robust_distance, *s.mean_distance + 1e-15);
        EXPECT_LE(*s.p90_distance, *s.hausdorff);
        previous = *s.robust_distance;
    }
    // Level J of an icosahedron has 10·4^J + 2 vertices: J = 5 (10242; 40962 is over 20000),
    // and it lies on the sphere to within its chord error.
    EXPECT_EQ(mesh.finest_level(), 5U);
    EXPECT_LT(sphere_error(mesh), 0.2 * report.sampling_density);
    EXPECT_FALSE(report.dropped);
}

/// The vertex rings of a mesh as detail::despike() takes them.
struct TestRings
{
    std::vector<std::uint32_t> offsets;
    std::vector<std::uint32_t> adjacent;
    std::vector<std::uint8_t> boundary;
};

TestRings rings_of(const TriMesh& mesh)
{
    std::vector<std::set<std::uint32_t>> sets(mesh.vertex_count());
    for (const Triangle& t : mesh.triangles)
        for (std::size_t c = 0; c < 3; ++c)
        {
            sets[t[c]].insert(t[(c + 1) % 3]);
            sets[t[(c + 1) % 3]].insert(t[c]);
        }
    TestRings rings;
    rings.offsets.push_back(0);
    for (const auto& set : sets)
    {
        rings.adjacent.insert(rings.adjacent.end(), set.begin(), set.end());
        rings.offsets.push_back(static_cast<std::uint32_t>(rings.adjacent.size()));
    }
    rings.boundary.assign(mesh.vertex_count(), 0);
    return rings;
}

TEST(RelaxMembranes, ATuttesLayoutOfABulgeIsSpreadOutInItsPlane)
{
    // A membrane over connectivity made for a bulge, as a faired region over a face the
    // scanner never saw (the field's surface there bulged): the unit icosphere's vertices above
    // z = -0.6 (about 80% of the sphere), those next to a vertex below held, the others laid out
    // by the membrane's solve (detail::thin_plate_fairing(), Fairing::membrane: Tutte's
    // embedding, its middle crowded) and squeezed across the middle as well, which leaves 60%
    // of the faces under 20°. Fifty rounds towards the faces' area centroids leave 30% (the
    // crowding has to spread over the whole membrane, 28 rings deep); relax_membranes() goes
    // on while a round helps, up to depth² rounds: 150 rounds, 0.9%, unfolded and flat.
    const TriMesh ball = test::icosphere(4);
    const std::size_t n = ball.vertex_count();
    std::vector<Vec3d> x(n);
    for (std::size_t v = 0; v < n; ++v)
        x[v] = ball.vertices.positions[v].cast<double>();
    TriMesh cap;
    cap.vertices = ball.vertices;
    for (const Triangle& t : ball.triangles)
        if (x[t[0]].z() > -0.6 && x[t[1]].z() > -0.6 && x[t[2]].z() > -0.6)
            cap.triangles.push_back(t);
    const TestRings rings = rings_of(cap);
    const TestRings all = rings_of(ball);
    std::vector<std::uint32_t> free;
    for (std::uint32_t v = 0; v < n; ++v)
    {
        bool inside = x[v].z() > -0.6;
        for (std::uint32_t e = all.offsets[v]; e < all.offsets[v + 1]; ++e)
            inside = inside && x[all.adjacent[e]].z() > -0.6;
        if (inside)
            free.push_back(v);
    }
    std::vector<char> is_free(n, 0);
    for (const std::uint32_t v : free)
        is_free[v] = 1;
    const std::size_t deepest = detail::depth_in_rings(rings.offsets, rings.adjacent, is_free);
    const auto neighbours = [&](std::uint32_t v, const auto& visit) {
        for (std::uint32_t e = rings.offsets[v]; e < rings.offsets[v + 1]; ++e)
            visit(rings.adjacent[e]);
    };
    const std::optional<std::vector<Vec3d>> laid = detail::thin_plate_fairing(
        n, free, neighbours, [&](std::uint32_t v) { return x[v]; }, detail::Fairing::membrane);
    ASSERT_TRUE(laid.has_value());
    // Squeezed across its middle as well, x -> x (|x| / r)² with r the rim's radius: thin
    // triangles along a band, which the rounds have to spread across the whole membrane.
    double radius = 0.0;
    for (std::uint32_t v = 0; v < n; ++v)
        if (is_free[v] == 0 && x[v].z() > -0.6)
            radius = std::max(radius, std::abs(x[v].x()));
    for (std::size_t i = 0; i < free.size(); ++i)
    {
        Vec3d p = (*laid)[i];
        p.x() *= (p.x() / radius) * (p.x() / radius);
        x[free[i]] = p;
    }
    // The held rim's heights (a ring of the icosphere's vertices, near z = -0.6).
    double rim_low = std::numeric_limits<double>::infinity();
    double rim_high = -rim_low;
    for (std::uint32_t v = 0; v < n; ++v)
        if (is_free[v] == 0 && x[v].z() > -0.6)
        {
            rim_low = std::min(rim_low, x[v].z());
            rim_high = std::max(rim_high, x[v].z());
        }
    const auto thin_share = [&](std::span<const Vec3d> at) {
        std::size_t thin = 0;
        for (const Triangle& t : cap.triangles)
            if (triangle_min_angle(at[t[0]], at[t[1]], at[t[2]]) < 20.0 * std::numbers::pi / 180.0)
                ++thin;
        return static_cast<double>(thin) / static_cast<double>(cap.triangles.size());
    };
    const double laid_out = thin_share(x);
    std::vector<Vec3d> fifty = x;
    detail::relax_tangentially(fifty, cap.triangles, rings.offsets, rings.adjacent, free,
                               detail::faired_relax_rounds, detail::RelaxTarget::face_centroids);
    const double after_fifty = thin_share(fifty);
    const int rounds =
        detail::relax_membranes(x, cap.triangles, rings.offsets, rings.adjacent, free, deepest);
    const double after = thin_share(x);
    RecordProperty("depth", static_cast<int>(deepest));
    RecordProperty("laid_out", std::to_string(laid_out));
    RecordProperty("after_fifty", std::to_string(after_fifty));
    RecordProperty("after", std::to_string(after));
    RecordProperty("rounds", rounds);
    EXPECT_GT(after_fifty, 2.0 * detail::membrane_thin_share);
    EXPECT_GT(rounds, detail::faired_relax_rounds);
    EXPECT_LE(static_cast<std::size_t>(rounds), deepest * deepest + detail::faired_relax_rounds);
    EXPECT_LE(after, detail::membrane_thin_share);
    // Unfolded (every face turned the same way) and flat (the vertices within the rim's own
    // spread of heights).
    std::size_t up = 0;
    for (const Triangle& t : cap.triangles)
        up += (x[t[1]] - x[t[0]]).cross(x[t[2]] - x[t[0]]).z() > 0.0 ? 1 : 0;
    EXPECT_TRUE(up == 0 || up == cap.triangles.size()) << up << " of " << cap.triangles.size();
    for (const std::uint32_t v : free)
    {
        EXPECT_GE(x[v].z(), rim_low - 1e-9);
        EXPECT_LE(x[v].z(), rim_high + 1e-9);
    }
}

TEST(Despike, ALoneSpikeGoesBackOnTheSurfaceAndCreasesStay)
{
    // An icosphere on the unit sphere's field with one vertex pushed out by 0.2 (its edges are
    // about 0.15): back on the sphere, from its neighbours' centroid; nothing else moves.
    const auto sphere = make_sphere(Vec3d::Zero(), 1.0);
    const TriMesh ball = test::icosphere(3);
    std::vector<Vec3d> x(ball.vertex_count());
    for (std::size_t v = 0; v < x.size(); ++v)
        x[v] = ball.vertices.positions[v].cast<double>();
    const std::vector<Vec3d> before = x;
    x[100] *= 1.2;
    const TestRings rings = rings_of(ball);
    EXPECT_EQ(
        detail::despike(x, Vec3d::Zero(), *sphere, rings.offsets, rings.adjacent, rings.boundary),
        1U);
    EXPECT_NEAR(x[100].norm(), 1.0, 1e-6);
    for (std::size_t v = 0; v < x.size(); ++v)
    {
        if (v != 100)
        {
            EXPECT_EQ(x[v], before[v]) << v;
        }
    }
    // A dent of 0.05 is under a quarter of an edge: it stays.
    x[100] = 0.95 * before[100];
    EXPECT_EQ(
        detail::despike(x, Vec3d::Zero(), *sphere, rings.offsets, rings.adjacent, rings.boundary),
        0U);
    // A box's corners and edges stand off their neighbours' planes too, with neighbours along
    // the crease as far, and the field at their centroids is as far from zero: none moves.
    const auto box = make_box(Vec3d(-1, -1, -1), Vec3d(1, 1, 1));
    const TriMesh cube = test::box_mesh(Vec3d(-1, -1, -1), Vec3d(1, 1, 1));
    std::vector<Vec3d> y(cube.vertex_count());
    for (std::size_t v = 0; v < y.size(); ++v)
        y[v] = cube.vertices.positions[v].cast<double>();
    const TestRings cube_rings = rings_of(cube);
    EXPECT_EQ(detail::despike(y, Vec3d::Zero(), *box, cube_rings.offsets, cube_rings.adjacent,
                              cube_rings.boundary),
              0U);
}

/// Mean distance from the true unit sphere over the centroids of the finest level's faces: the
/// chord error and the field's error together.
double centroid_error(const MultiresMesh& mesh)
{
    const std::vector<Triangle> faces = mesh.faces(mesh.finest_level());
    double sum = 0.0;
    for (const Triangle& t : faces)
        sum +=
            std::abs((mesh.world(t[0]) + mesh.world(t[1]) + mesh.world(t[2])).norm() / 3.0 - 1.0);
    return sum / static_cast<double>(faces.size());
}

TEST(RefineAutomaticStop, NoiseStopsRefinementAtTheNoiseFloor)
{
    // With noise the field's residual at the samples is the noise, and once a level's details
    // shrink by noise_decay or less (not fourfold, as a smooth surface's do) they follow the noise
    // in the field: refinement stops there, before the budget (made ample here), and a further
    // level would not bring the mesh closer to the true sphere.
    const double sigma = 0.01;
    const PointCloud samples = noisy_sphere(20000, sigma);
    const PointField field(samples);
    MultiresMesh mesh(test::icosphere(0));
    const RefineReport report =
        refine(mesh, field, samples, {.vertex_budget = 100 * samples.size()});
    EXPECT_TRUE(report.stop == RefineStop::NoisyDetails || report.stop == RefineStop::SmallDetails)
        << to_string(report.stop);
    EXPECT_LT(mesh.finest_level(), 6U);
    EXPECT_NEAR(report.detail_threshold, 0.1 * report.field_residual, 1e-15);
    ASSERT_FALSE(report.levels.empty());
    const double last = *report.levels.back().next_detail;
    const double before = report.levels.size() == 1
                              ? report.initial_next_detail
                              : *report.levels[report.levels.size() - 2].next_detail;
    if (report.stop == RefineStop::NoisyDetails)
    {
        EXPECT_LT(last, report.field_residual);
        EXPECT_GT(last, RefineOptions{}.noise_decay * before);
    }
    else
        EXPECT_LE(last, report.detail_threshold);
    // The field's residual is the noise's: E|N(0, σ²)| = σ·√(2/π) ≈ 0.8σ, trimmed a little.
    EXPECT_GT(report.field_residual, 0.5 * sigma);
    EXPECT_LT(report.field_residual, 0.9 * sigma);
    // One more level gains less than a tenth against the true sphere.
    MultiresMesh finer = mesh;
    (void)refine_once(finer, field);
    EXPECT_GT(centroid_error(finer), 0.9 * centroid_error(mesh));
    // The mesh follows the true sphere, not the noise.
    EXPECT_LT(sphere_error(mesh), 4.0 * sigma);
}

TEST(RefineAutomaticStop, OutliersDoNotStopRefinement)
{
    // 1% of the measured samples are strays far off the surface: the largest distance stays at
    // their distance at every level, so the paper's rule stalls at once, while the robust
    // distance ignores them and refinement goes on to the budget.
    const PointCloud clean = sampled_sphere(20000);
    const PointField field(clean);
    PointCloud measured = clean;
    for (std::size_t i = 0; i < measured.size(); i += 100)
        measured.positions[i] *= 1.4F;
    MultiresMesh automatic(test::icosphere(0));
    const RefineReport a = refine(automatic, field, measured);
    EXPECT_EQ(a.stop, RefineStop::VertexBudget);
    EXPECT_EQ(automatic.finest_level(), 5U);
    EXPECT_FALSE(a.paper_level);
    MultiresMesh paper(test::icosphere(0));
    const RefineReport p = refine(paper, field, measured, {.stop_rule = StopRule::Paper});
    EXPECT_EQ(p.stop, RefineStop::Stalled);
    EXPECT_LT(paper.finest_level(), automatic.finest_level());
    ASSERT_TRUE(p.dropped);
    EXPECT_EQ(p.dropped->level, paper.finest_level() + 1);
}

TEST(RefineAutomaticStop, VertexBudgetOptionAndChecks)
{
    const PointCloud samples = sampled_sphere(20000);
    const PointField field(samples);
    MultiresMesh mesh(test::icosphere(0));
    const RefineReport report = refine(mesh, field, samples, {.vertex_budget = 700});
    EXPECT_EQ(report.stop, RefineStop::VertexBudget);
    EXPECT_EQ(report.vertex_budget, 700U);
    EXPECT_EQ(mesh.vertex_count(), 642U); // level 3; level 4 has 2562
    MultiresMesh other(test::icosphere(0));
    EXPECT_THROW((void)refine(other, field, samples, {.detail_factor = 0.0}), InvalidInput);
    EXPECT_THROW((void)refine(other, field, samples, {.detail_factor = 1.5}), InvalidInput);
    EXPECT_EQ(parse_stop_rule("auto"), StopRule::Automatic);
    EXPECT_EQ(parse_stop_rule("paper"), StopRule::Paper);
    EXPECT_EQ(parse_stop_rule("exact"), StopRule::Exact);
    EXPECT_THROW((void)parse_stop_rule("max"), InvalidInput);
    // Exact: to max_level whatever the distances.
    MultiresMesh exact(test::icosphere(0));
    const RefineReport r =
        refine(exact, field, samples, {.max_level = 2, .stop_rule = StopRule::Exact});
    EXPECT_EQ(exact.finest_level(), 2U);
    EXPECT_EQ(r.stop, RefineStop::LevelCap);
}

TEST(RefineAutomaticStop, TheCallersSampleTreeGivesTheSameMesh)
{
    // The field's own k-d tree of its surfels serves the refinement as one built for it would;
    // a tree over other storage, even of the same points, is refused.
    const PointField field(sampled_sphere(20000));
    const PointCloud& samples = field.surfels();
    MultiresMesh own(test::icosphere(0));
    const RefineReport a = refine(own, field, samples, {.vertex_budget = 3000});
    MultiresMesh given(test::icosphere(0));
    const RefineReport b =
        refine(given, field, samples, {.vertex_budget = 3000, .sample_tree = &field.tree()});
    EXPECT_EQ(a.sampling_density, b.sampling_density);
    ASSERT_EQ(own.vertex_count(), given.vertex_count());
    EXPECT_EQ(own.finest_level(), 4U);
    for (std::size_t v = 0; v < own.vertex_count(); ++v)
        ASSERT_EQ(own.positions()[v], given.positions()[v]) << "vertex " << v;
    const std::vector<Vec3f> copy = samples.positions;
    const KdTree other(copy);
    MultiresMesh refused(test::icosphere(0));
    EXPECT_THROW((void)refine(refused, field, samples, {.sample_tree = &other}), InvalidInput);
}

TEST(Refine, ButterflyOnSampledSphere)
{
    const PointCloud samples = sampled_sphere(6000);
    const PointField field(samples);
    MultiresMesh mesh(octahedron());
    const RefineReport report =
        refine(mesh, field, samples, {.predictor = Predictor::Butterfly, .max_level = 4});
    for (const RefineLevelStats& s : report.levels)
        EXPECT_EQ(s.unprojected, 0U);
    for (const Vec3d& p : mesh.positions())
        ASSERT_NEAR(p.norm(), 1.0, report.sampling_density);
    const LevelChecks checks = check_levels(mesh);
    EXPECT_EQ(checks.folded, 0U);
    EXPECT_EQ(checks.topology.back().euler_characteristic, 2);
}

TEST(Refine, FoldsAreFixedByTheVertexBasedEdgeNormal)
{
    // A thin triangle F1 = (a, b, c) facing +z, hinged along ab to a large triangle F2 tilted by
    // 45°, and flanked by two wide triangles facing +z. AW_FEN of ab is dominated by F2, so
    // projecting ab's midpoint along it onto a plane below slides it sideways across F1's
    // children (a fold); VEN, dominated by the wide faces at a and b, does not.
    TriMesh base;
    base.vertices.positions = {{-1, 0, 0},  {1, 0, 0},    {0, 0.1F, 0},
                               {0, -1, -1}, {-10, 10, 0}, {10, 10, 0}};
    base.triangles = {{0, 1, 2}, {1, 0, 3}, {0, 2, 4}, {2, 1, 5}};
    const Vec3d aw_fen = Vec3d(0.0, -2.0, 2.2).normalized(); // F1 + F2 area normals
    const auto plane = make_half_space(-0.2 * aw_fen, aw_fen);
    for (const int relax : {0, 1})
    {
        MultiresMesh mesh(base);
        const RefineLevelStats stats = refine_once(mesh, *plane, {.relax_iterations = relax});
        EXPECT_GE(stats.fold_vertices, 1U);
        EXPECT_GE(stats.folds_fixed_by_ven, 1U);
        EXPECT_EQ(stats.folds_unresolved, 0U);
        EXPECT_EQ(stats.unprojected, 0U);
        EXPECT_EQ(stats.folded_faces, 0U);
        EXPECT_EQ(check_levels(mesh).folded, 0U);
        for (std::size_t v = mesh.vertex_count(0); v < mesh.vertex_count(); ++v)
            EXPECT_NEAR(plane->evaluate(mesh.world(static_cast<std::uint32_t>(v))).value, 0.0,
                        1e-6);
    }
    // The vertex of ab is where VEN put it, off the AW_FEN line through ab's midpoint (0).
    MultiresMesh mesh(base);
    refine_once(mesh, *plane, {.relax_iterations = 0});
    const Vec3d on_ab = mesh.positions()[mesh.edge_vertices(0)[0]];
    EXPECT_GT(on_ab.cross(aw_fen).norm(), 1e-3); // off the AW_FEN line through the midpoint 0
}

/// Child faces of the finest level with an angle under 20°.
std::size_t thin_faces(const MultiresMesh& mesh)
{
    const double bound = std::cos(20.0 * std::numbers::pi / 180.0);
    std::size_t count = 0;
    for (const Triangle& t : mesh.faces(mesh.level_count() - 1))
    {
        bool thin = false;
        for (std::size_t c = 0; c < 3; ++c)
        {
            const Vec3d u = mesh.world(t[(c + 1) % 3]) - mesh.world(t[c]);
            const Vec3d w = mesh.world(t[(c + 2) % 3]) - mesh.world(t[c]);
            thin = thin || u.dot(w) > bound * u.norm() * w.norm();
        }
        count += thin ? 1 : 0;
    }
    return count;
}

TEST(Refine, ThinTrianglesGetRoundsOfTheirOwn)
{
    // Base meshes of the unit sphere (an octahedron refined twice, edges of about 0.4) with
    // every third vertex pushed off by up to 0.2 on each axis: projected onto the sphere, their
    // children come out thin where the base triangles are skewed. Two levels on, the rounds of
    // the thin children's new vertices leave fewer of them over six such meshes (one of the six
    // gains a few), fold no more faces and keep every projected vertex on the sphere.
    const auto sphere = make_sphere(Vec3d::Zero(), 1.0);
    std::array<std::size_t, 2> thin{};
    std::array<std::size_t, 2> folded{};
    for (int variant = 0; variant < 6; ++variant)
    {
        MultiresMesh seed(octahedron());
        refine_once(seed, *sphere, {});
        refine_once(seed, *sphere, {});
        TriMesh base;
        for (std::size_t v = 0; v < seed.vertex_count(); ++v)
            base.vertices.positions.push_back(
                seed.world(static_cast<std::uint32_t>(v)).cast<float>());
        for (const Triangle& t : seed.faces(seed.level_count() - 1))
            base.triangles.push_back(t);
        std::mt19937_64 rng(static_cast<std::uint64_t>(variant));
        std::uniform_real_distribution<float> offset(-0.2F, 0.2F);
        for (std::size_t v = 6; v < base.vertices.positions.size(); v += 3)
            base.vertices.positions[v] += Vec3f(offset(rng), offset(rng), offset(rng));
        for (const int rounds : {0, 2})
        {
            const std::size_t r = rounds == 0 ? 0 : 1;
            MultiresMesh mesh(base);
            std::size_t unprojected = 0;
            for (int level = 0; level < 2; ++level)
            {
                const RefineLevelStats stats =
                    refine_once(mesh, *sphere, {.thin_relax_iterations = rounds});
                unprojected += stats.unprojected;
                folded[r] += stats.folded_faces;
            }
            std::size_t off = 0;
            for (std::size_t v = mesh.vertex_count(0); v < mesh.vertex_count(); ++v)
                off += std::abs(mesh.world(static_cast<std::uint32_t>(v)).norm() - 1.0) > 1e-6;
            EXPECT_EQ(off, unprojected) << "variant " << variant << ", " << rounds << " rounds";
            thin[r] += thin_faces(mesh);
        }
    }
    EXPECT_GT(thin[0], 100U);
    EXPECT_LT(static_cast<double>(thin[1]), 0.95 * static_cast<double>(thin[0]))
        << thin[0] << " thin faces without the rounds, " << thin[1] << " with";
    EXPECT_LE(folded[1], folded[0]) << "faces folded against their parent and the field";
}

TEST(Refine, SameResultWhateverTheThreadCount)
{
    const PointCloud samples = sampled_sphere(4000);
    const PointField field(samples);
    // Five levels from the octahedron: the last ones split their 512 and 2048 faces' edges into
    // several blocks of new vertices (512 a block) and of faces (1024 a block).
    const auto results = test::at_thread_counts(
        [&] {
            MultiresMesh mesh(octahedron());
            for (int level = 0; level < 5; ++level)
                refine_once(mesh, field,
                            {.predictor = Predictor::Butterfly, .relax_iterations = 2});
            return std::vector<Vec3d>(mesh.positions().begin(), mesh.positions().end());
        },
        {.min_multi_block_loops = 4});
    EXPECT_TRUE(results[0] == results[1]);
    EXPECT_TRUE(results[0] == results[2]);
}

TEST(Refine, RejectsBadInput)
{
    const auto sphere = make_sphere(Vec3d::Zero(), 1.0);
    MultiresMesh empty;
    EXPECT_THROW(refine_once(empty, *sphere), InvalidInput);
    MultiresMesh mesh(octahedron());
    EXPECT_THROW(refine_once(mesh, *sphere, {.search_scale = 0.0}), InvalidInput);
    EXPECT_THROW(refine_once(mesh, *sphere, {.relax_iterations = -1}), InvalidInput);
    EXPECT_THROW(refine_once(mesh, *sphere, {.thin_relax_iterations = -1}), InvalidInput);
    EXPECT_THROW(refine(mesh, *sphere, PointCloud{}), InvalidInput);
    EXPECT_EQ(mesh.level_count(), 1U); // nothing was added
    EXPECT_THROW((void)estimate_sampling_density(PointCloud{}), InvalidInput);
    EXPECT_THROW((void)parse_predictor("loop"), InvalidInput);
    EXPECT_EQ(parse_predictor("butterfly"), Predictor::Butterfly);
}

TEST(Refine, CancelRemovesTheNewLevel)
{
    const auto sphere = make_sphere(Vec3d::Zero(), 1.0);
    MultiresMesh mesh(octahedron());
    refine_once(mesh, *sphere);
    const auto cancel = [](std::string_view, double) {
        return false;
    };
    EXPECT_THROW(refine_once(mesh, *sphere, {.progress = cancel}), Cancelled);
    EXPECT_EQ(mesh.level_count(), 2U);
    EXPECT_NO_THROW(mesh.validate());
}

} // namespace
} // namespace pointform
