// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/implicit/primitives.h"

#include "pointform/core/error.h"
#include "pointform/geometry/mesh_topology.h"
#include "pointform/geometry/shapes.h"
#include "pointform/implicit/point_field.h"
#include "pointform/implicit/transform.h"
#include "pointform/polygonize/marching_cubes.h"

#include "field_test_util.h"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

namespace pointform {
namespace {

using test::numeric_gradient;
using test::random_points;

constexpr double pi = std::numbers::pi;

Aabb enlarged(const Aabb& box, double factor)
{
    const Vec3d margin = (factor - 1.0) * 0.5 * box.size();
    return {.min = box.min - margin, .max = box.max + margin};
}

/// The analytic gradient matches central differences away from creases (a few points per field
/// may straddle a crease; at most 2% are allowed to).
void expect_gradient_matches(const Field& f, int count, std::uint64_t seed)
{
    int mismatches = 0;
    for (const Vec3d& p : random_points(enlarged(f.bounds(), 1.6), count, seed))
    {
        const FieldSample s = f.evaluate(p);
        ASSERT_TRUE(s.defined);
        if ((s.gradient - numeric_gradient(f, p)).norm() > 1e-5)
        {
            ++mismatches;
        }
    }
    EXPECT_LE(mismatches, count / 50);
}

/// Polygonizes an analytic field over its own bounds from its seeds.
MarchingCubesResult polygonize(const Field& f, int resolution)
{
    const Aabb box = f.bounds();
    return marching_cubes(f, grid_over(box, cell_for_resolution(box, resolution)));
}

TEST(Primitives, SphereIsTheExactDistance)
{
    const SphereField s(Vec3d(1.0, 2.0, 3.0), 0.5);
    EXPECT_NEAR(s.evaluate(Vec3d(1.0, 2.0, 3.0)).value, -0.5, 1e-15);
    EXPECT_NEAR(s.evaluate(Vec3d(1.5, 2.0, 3.0)).value, 0.0, 1e-15);
    EXPECT_NEAR(s.evaluate(Vec3d(1.0, 4.0, 3.0)).value, 1.5, 1e-15);
    EXPECT_NEAR((s.evaluate(Vec3d(1.0, 4.0, 3.0)).gradient - Vec3d::UnitY()).norm(), 0.0, 1e-15);
    expect_gradient_matches(s, 200, 1);
}

TEST(Primitives, BoxDistanceInsideOutsideAndNearEdgesAndCorners)
{
    const BoxField box(Aabb{.min = Vec3d(-1.0, -2.0, -3.0), .max = Vec3d(1.0, 2.0, 3.0)});
    EXPECT_NEAR(box.evaluate(Vec3d::Zero()).value, -1.0, 1e-15); // nearest face: x
    EXPECT_NEAR(box.evaluate(Vec3d(0.5, 0.0, 2.8)).value, -0.2, 1e-15);
    EXPECT_NEAR(box.evaluate(Vec3d(1.0, 0.5, 0.5)).value, 0.0, 1e-15);
    EXPECT_NEAR(box.evaluate(Vec3d(3.0, 0.0, 0.0)).value, 2.0, 1e-15);
    EXPECT_NEAR(box.evaluate(Vec3d(2.0, 3.0, 0.0)).value, std::sqrt(2.0), 1e-15);   // edge
    EXPECT_NEAR(box.evaluate(Vec3d(-2.0, -3.0, 4.0)).value, std::sqrt(3.0), 1e-15); // corner
    EXPECT_NEAR(
        (box.evaluate(Vec3d(-2.0, -3.0, 4.0)).gradient - Vec3d(-1.0, -1.0, 1.0).normalized())
            .norm(),
        0.0, 1e-15);
    EXPECT_NEAR((box.evaluate(Vec3d(0.1, -1.9, 0.0)).gradient + Vec3d::UnitY()).norm(), 0.0, 1e-15);
    expect_gradient_matches(box, 300, 2);

    // Rounded: same outer extent, corners and edges rounded with radius 0.5.
    const BoxField rounded(Aabb{.min = Vec3d(-1.0, -2.0, -3.0), .max = Vec3d(1.0, 2.0, 3.0)}, 0.5);
    EXPECT_NEAR(rounded.evaluate(Vec3d(1.0, 0.0, 0.0)).value, 0.0, 1e-15);
    EXPECT_NEAR(rounded.evaluate(Vec3d(0.0, 0.0, 0.0)).value, -1.0, 1e-15);
    EXPECT_NEAR(rounded.evaluate(Vec3d(2.0, 3.0, 4.0)).value, std::sqrt(3.0 * 1.5 * 1.5) - 0.5,
                1e-14);
    // The corner of the sharp box is now outside, by the distance to the corner sphere.
    EXPECT_NEAR(rounded.evaluate(Vec3d(1.0, 2.0, 3.0)).value, std::sqrt(3.0) * 0.5 - 0.5, 1e-14);
    expect_gradient_matches(rounded, 300, 3);
}

TEST(Primitives, OrientedBoxIsTheAxisAlignedBoxRotated)
{
    const Mat3d r = Eigen::AngleAxisd(0.7, Vec3d(1.0, 2.0, -0.5).normalized()).toRotationMatrix();
    const Vec3d c(0.3, -0.2, 1.0);
    const Vec3d half(0.5, 1.0, 0.25);
    const BoxField oriented(c, half, r, 0.1);
    const BoxField aligned(c, half, Mat3d::Identity(), 0.1);
    for (const Vec3d& q : random_points(enlarged(aligned.bounds(), 2.0), 200, 4))
    {
        const FieldSample a = aligned.evaluate(q);
        const FieldSample o = oriented.evaluate(c + r * (q - c));
        EXPECT_NEAR(o.value, a.value, 1e-12);
        EXPECT_NEAR((o.gradient - r * a.gradient).norm(), 0.0, 1e-12);
    }
    // A point along the rotated long axis, 0.5 beyond its face.
    EXPECT_NEAR(oriented.evaluate(c + 1.5 * r.col(1)).value, 0.5, 1e-12);
    expect_gradient_matches(oriented, 300, 5);
}

TEST(Primitives, CylinderSideCapsAndRim)
{
    const auto cylinder = make_cylinder(Vec3d::Zero(), Vec3d(0.0, 0.0, 2.0), 1.0);
    const auto value = [&](double x, double y, double z) {
        return cylinder->evaluate(Vec3d(x, y, z)).value;
    };
    EXPECT_NEAR(value(2.0, 0.0, 1.0), 1.0, 1e-14);            // side
    EXPECT_NEAR(value(0.0, 0.0, 1.0), -1.0, 1e-14);           // axis, middle
    EXPECT_NEAR(value(0.5, 0.0, 1.0), -0.5, 1e-14);           // nearest the side
    EXPECT_NEAR(value(0.0, 0.0, 1.9), -0.1, 1e-14);           // nearest the top cap
    EXPECT_NEAR(value(0.0, 0.0, 3.0), 1.0, 1e-14);            // above the top cap
    EXPECT_NEAR(value(0.5, 0.3, -0.5), 0.5, 1e-14);           // below the bottom cap
    EXPECT_NEAR(value(0.0, 2.0, 3.0), std::sqrt(2.0), 1e-14); // beyond the rim
    EXPECT_NEAR(value(0.6, 0.8, 2.0), 0.0, 1e-14);            // on the rim
    EXPECT_NEAR((cylinder->evaluate(Vec3d(0.1, 0.0, 2.5)).gradient - Vec3d::UnitZ()).norm(), 0.0,
                1e-14);

    // A tilted cylinder against the textbook formula in its own frame.
    const Vec3d a(0.2, -0.4, 0.1);
    const Vec3d b(1.0, 0.5, 1.2);
    const double radius = 0.3;
    const auto tilted = make_cylinder(a, b, radius);
    const Vec3d axis = (b - a).normalized();
    const double half = 0.5 * (b - a).norm();
    for (const Vec3d& p : random_points(enlarged(tilted->bounds(), 1.8), 300, 6))
    {
        const Vec3d v = p - 0.5 * (a + b);
        const double h = v.dot(axis);
        const double rho = (v - h * axis).norm();
        const Eigen::Vector2d d(rho - radius, std::abs(h) - half);
        const double expected = std::min(std::max(d.x(), d.y()), 0.0) + d.cwiseMax(0.0).norm();
        EXPECT_NEAR(tilted->evaluate(p).value, expected, 1e-12);
    }
    expect_gradient_matches(*tilted, 300, 7);
}

TEST(Primitives, ConeAgainstDenseSamplesOfItsMeridianTrapezoid)
{
    // Apex cone: base radius 1 at z = 0, apex at z = 1.
    const auto apex = make_cone(Vec3d::Zero(), Vec3d::UnitZ(), 1.0, 0.0);
    EXPECT_NEAR(apex->evaluate(Vec3d(0.0, 0.0, 2.0)).value, 1.0, 1e-14);
    EXPECT_NEAR(apex->evaluate(Vec3d(0.0, 0.0, -1.0)).value, 1.0, 1e-14);
    EXPECT_NEAR(apex->evaluate(Vec3d(1.0, 0.0, 1.0)).value, 1.0 / std::sqrt(2.0), 1e-14);
    EXPECT_NEAR(apex->evaluate(Vec3d(0.0, 0.5, 0.5)).value, 0.0, 1e-14);

    // A frustum: the exact distance is the distance in the meridian plane to its trapezoid.
    const Vec3d a(0.1, 0.2, -0.3);
    const Vec3d b(-0.5, 0.9, 0.8);
    const double ra = 0.6;
    const double rb = 0.2;
    const CappedConeField cone(a, b, ra, rb);
    const Vec3d axis = (b - a).normalized();
    const double length = (b - a).norm();
    std::vector<Eigen::Vector2d> outline; // the meridian outline (ρ ≥ 0), densely sampled
    const int n = 4000;
    for (int i = 0; i <= n; ++i)
    {
        const double t = static_cast<double>(i) / n;
        outline.emplace_back(t * ra, 0.0);                    // base cap
        outline.emplace_back(ra + t * (rb - ra), t * length); // side
        outline.emplace_back(t * rb, length);                 // top cap
    }
    for (const Vec3d& p : random_points(enlarged(cone.bounds(), 1.8), 200, 8))
    {
        const double h = (p - a).dot(axis);
        const double rho = (p - a - h * axis).norm();
        double best = 1e300;
        for (const Eigen::Vector2d& o : outline)
        {
            best = std::min(best, (Eigen::Vector2d(rho, h) - o).norm());
        }
        const bool inside = h >= 0.0 && h <= length && rho <= ra + (rb - ra) * h / length;
        const double spacing = length / n;
        EXPECT_NEAR(cone.evaluate(p).value, inside ? -best : best, spacing);
    }
    expect_gradient_matches(cone, 300, 9);
}

TEST(Primitives, TorusDistance)
{
    const TorusField torus(Vec3d::Zero(), Vec3d::UnitZ(), 2.0, 0.5);
    EXPECT_NEAR(torus.evaluate(Vec3d(2.5, 0.0, 0.0)).value, 0.0, 1e-15);
    EXPECT_NEAR(torus.evaluate(Vec3d(0.0, -2.0, 0.0)).value, -0.5, 1e-15);
    EXPECT_NEAR(torus.evaluate(Vec3d::Zero()).value, 1.5, 1e-15);
    EXPECT_NEAR(torus.evaluate(Vec3d(0.0, 3.0, 0.0)).value, 0.5, 1e-15);
    EXPECT_NEAR(torus.evaluate(Vec3d(2.0, 0.0, 1.0)).value, 0.5, 1e-15);
    EXPECT_NEAR((torus.evaluate(Vec3d(2.0, 0.0, 1.0)).gradient - Vec3d::UnitZ()).norm(), 0.0,
                1e-15);

    // A tilted torus is the z-axis torus rotated.
    const Mat3d r = Eigen::AngleAxisd(1.1, Vec3d(0.3, 1.0, 0.2).normalized()).toRotationMatrix();
    const Vec3d c(0.5, -1.0, 2.0);
    const TorusField tilted(c, r * Vec3d::UnitZ(), 2.0, 0.5);
    for (const Vec3d& q : random_points(enlarged(torus.bounds(), 1.5), 200, 10))
    {
        EXPECT_NEAR(tilted.evaluate(c + r * q).value, torus.evaluate(q).value, 1e-12);
    }
    expect_gradient_matches(tilted, 300, 11);
}

TEST(Primitives, HalfSpaceIsTheSignedPlaneDistanceAndUnbounded)
{
    const HalfSpaceField h(Vec3d(0.0, 0.0, 1.0), Vec3d(0.0, 0.0, 2.0));
    EXPECT_NEAR(h.evaluate(Vec3d(5.0, -3.0, 3.0)).value, 2.0, 1e-15);
    EXPECT_NEAR(h.evaluate(Vec3d(5.0, -3.0, 0.0)).value, -1.0, 1e-15);
    const Aabb box = h.bounds();
    EXPECT_EQ(box.max.z(), 1.0); // the solid lies below z = 1
    EXPECT_TRUE(std::isinf(box.min.z()) && std::isinf(box.max.x()) && std::isinf(box.min.y()));
    const HalfSpaceField tilted(Vec3d::Zero(), Vec3d(1.0, 1.0, 0.0));
    EXPECT_NEAR(tilted.evaluate(Vec3d(1.0, 1.0, 7.0)).value, std::sqrt(2.0), 1e-15);
    EXPECT_TRUE(tilted.bounds().min.array().isInf().all());
    EXPECT_TRUE(tilted.bounds().max.array().isInf().all());
}

TEST(Primitives, SeedsLieOnTheSurfaceAndMeshesAreClosedWithTheRightTopology)
{
    struct Case
    {
        std::shared_ptr<const Field> field;
        std::int64_t euler;
    };
    const Mat3d r = Eigen::AngleAxisd(0.4, Vec3d(1.0, 1.0, 0.0).normalized()).toRotationMatrix();
    const std::vector<Case> cases = {
        {make_sphere(Vec3d(0.1, 0.2, 0.3), 0.7), 2},
        {make_box(Vec3d(-1.0, -0.5, -0.2), Vec3d(1.0, 0.5, 0.2), 0.1), 2},
        {make_oriented_box(Vec3d::Zero(), Vec3d(0.6, 0.3, 0.4), r), 2},
        {make_cylinder(Vec3d(0.0, 0.0, -1.0), Vec3d(0.5, 0.3, 1.0), 0.4), 2},
        {make_cone(Vec3d(0.0, 0.0, -1.0), Vec3d(0.0, 0.2, 1.0), 0.6, 0.0), 2},
        {make_torus(Vec3d::Zero(), Vec3d(0.0, 1.0, 1.0), 1.0, 0.3), 0},
    };
    for (const Case& c : cases)
    {
        SCOPED_TRACE(&c - cases.data());
        std::vector<Vec3d> seeds;
        c.field->append_seeds(seeds);
        ASSERT_FALSE(seeds.empty());
        const Aabb box = c.field->bounds();
        for (const Vec3d& s : seeds)
        {
            EXPECT_NEAR(c.field->evaluate(s).value, 0.0, 1e-12 * box.diagonal());
        }
        const MarchingCubesResult mc = polygonize(*c.field, 48);
        EXPECT_FALSE(mc.stats.dense);
        const MeshTopology topo = analyze_topology(mc.mesh);
        EXPECT_TRUE(topo.is_closed());
        EXPECT_TRUE(topo.is_oriented_manifold());
        EXPECT_EQ(topo.components, 1U);
        EXPECT_EQ(topo.euler_characteristic, c.euler);
        // The whole surface lies inside bounds(), which is tight: the mesh spans it (to within
        // the tip of a cone that marching cubes cuts off).
        Aabb mesh_box;
        for (std::size_t v = 0; v < mc.mesh.vertex_count(); ++v)
        {
            mesh_box.extend(mc.mesh.vertices.world(v));
        }
        const double cell = cell_for_resolution(box, 48);
        EXPECT_LE((box.min - mesh_box.min).maxCoeff(), 1e-3 * cell);
        EXPECT_LE((mesh_box.max - box.max).maxCoeff(), 1e-3 * cell);
        EXPECT_LE((mesh_box.min - box.min).cwiseAbs().maxCoeff(), 2.0 * cell);
        EXPECT_LE((mesh_box.max - box.max).cwiseAbs().maxCoeff(), 2.0 * cell);
    }
}

TEST(Primitives, BadInputIsRejected)
{
    EXPECT_THROW((void)make_sphere(Vec3d::Zero(), -1.0), InvalidInput);
    EXPECT_THROW((void)make_sphere(Vec3d(0.0, std::nan(""), 0.0), 1.0), InvalidInput);
    EXPECT_THROW((void)make_box(Vec3d::Zero(), Vec3d(1.0, 0.0, 1.0)), InvalidInput);
    EXPECT_THROW((void)make_box(Vec3d::Zero(), Vec3d::Ones(), 0.6), InvalidInput);
    EXPECT_THROW((void)make_oriented_box(Vec3d::Zero(), Vec3d::Ones(), 2.0 * Mat3d::Identity()),
                 InvalidInput);
    EXPECT_THROW((void)make_cylinder(Vec3d::Zero(), Vec3d::Zero(), 1.0), InvalidInput);
    EXPECT_THROW((void)make_cylinder(Vec3d::Zero(), Vec3d::UnitX(), 0.0), InvalidInput);
    EXPECT_THROW((void)make_cone(Vec3d::Zero(), Vec3d::UnitX(), 0.0, 0.0), InvalidInput);
    EXPECT_THROW((void)make_torus(Vec3d::Zero(), Vec3d::Zero(), 1.0, 0.1), InvalidInput);
    EXPECT_THROW((void)make_torus(Vec3d::Zero(), Vec3d::UnitZ(), 1.0, -0.1), InvalidInput);
    EXPECT_THROW((void)make_half_space(Vec3d::Zero(), Vec3d::Zero()), InvalidInput);
}

// ---------------------------------------------------------------------------------------------
// Transforms

TEST(Transform, MovedRotatedAndScaledSphereIsTheSphereWithMovedCentreAndRadius)
{
    const Vec3d c(0.2, -0.1, 0.4);
    const auto sphere = make_sphere(c, 0.5);
    const Vec3d t(1.0, 2.0, -3.0);
    const Vec3d pivot(-0.3, 0.5, 0.1);
    const Mat3d r = Eigen::AngleAxisd(0.9, Vec3d(1.0, -1.0, 2.0).normalized()).toRotationMatrix();
    struct Case
    {
        std::shared_ptr<const Field> moved;
        std::shared_ptr<const SphereField> expected;
    };
    const std::vector<Case> cases = {
        {translate(sphere, t), std::make_shared<const SphereField>(c + t, 0.5)},
        {rotate(sphere, Vec3d(1.0, -1.0, 2.0), 0.9, pivot),
         std::make_shared<const SphereField>(pivot + r * (c - pivot), 0.5)},
        {rotate(sphere, r), std::make_shared<const SphereField>(r * c, 0.5)},
        {scale(sphere, 2.5, pivot),
         std::make_shared<const SphereField>(pivot + 2.5 * (c - pivot), 1.25)},
        {translate(scale(rotate(sphere, r), 0.5), t),
         std::make_shared<const SphereField>(0.5 * r * c + t, 0.25)},
    };
    for (const Case& k : cases)
    {
        for (const Vec3d& p : random_points(enlarged(k.expected->bounds(), 3.0), 100, 12))
        {
            const FieldSample got = k.moved->evaluate(p);
            const FieldSample want = k.expected->evaluate(p);
            EXPECT_NEAR(got.value, want.value, 1e-12);
            EXPECT_NEAR((got.gradient - want.gradient).norm(), 0.0, 1e-12);
            EXPECT_TRUE(got.defined);
        }
        const Aabb got = k.moved->bounds();
        const Aabb want = k.expected->bounds();
        // A rotated box's box is larger than the sphere's, never smaller.
        EXPECT_TRUE((got.min.array() <= want.min.array() + 1e-12).all());
        EXPECT_TRUE((got.max.array() >= want.max.array() - 1e-12).all());
        std::vector<Vec3d> seeds;
        k.moved->append_seeds(seeds);
        for (const Vec3d& s : seeds)
        {
            EXPECT_NEAR(k.expected->evaluate(s).value, 0.0, 1e-12);
        }
    }
}

TEST(Transform, NonUniformScaleKeepsTheZeroSetAndADistanceBound)
{
    // The unit sphere scaled by (2, 1, 0.5) is the ellipsoid (x/2)² + y² + (z/0.5)² = 1.
    const auto ellipsoid = scale(make_sphere(Vec3d::Zero(), 1.0), Vec3d(2.0, 1.0, 0.5));
    std::mt19937_64 rng(13);
    std::normal_distribution<double> gauss;
    std::vector<Vec3d> surface;
    for (int i = 0; i < 20000; ++i)
    {
        const Vec3d u = Vec3d(gauss(rng), gauss(rng), gauss(rng)).normalized();
        surface.emplace_back(2.0 * u.x(), u.y(), 0.5 * u.z());
    }
    for (std::size_t i = 0; i < 200; ++i)
    {
        EXPECT_NEAR(ellipsoid->evaluate(surface[i]).value, 0.0, 1e-12);
    }
    // |f| never exceeds the distance to the surface (here: to a dense sample of it).
    for (const Vec3d& p :
         random_points(Aabb{.min = Vec3d(-3, -2, -1.5), .max = Vec3d(3, 2, 1.5)}, 100, 14))
    {
        double nearest = 1e300;
        for (const Vec3d& s : surface)
        {
            nearest = std::min(nearest, (p - s).norm());
        }
        EXPECT_LE(std::abs(ellipsoid->evaluate(p).value), nearest + 1e-9);
    }
    expect_gradient_matches(*ellipsoid, 200, 15);
    const auto box =
        rotate(scale(make_box(Vec3d(-1, -1, -1), Vec3d(1, 1, 1), 0.2), Vec3d(0.5, 2.0, 1.0)),
               Vec3d(1.0, 1.0, 1.0), 0.5);
    expect_gradient_matches(*box, 300, 16);
    const MarchingCubesResult mc = polygonize(*box, 40);
    EXPECT_TRUE(analyze_topology(mc.mesh).is_closed());
    EXPECT_EQ(analyze_topology(mc.mesh).euler_characteristic, 2);
}

TEST(Transform, AppliesToPointFields)
{
    PointCloud cloud = sample_shape(Shape::Sphere, {.count = 3000, .seed = 3});
    cloud.radii.assign(cloud.size(), 0.15F);
    const auto field = std::make_shared<const PointField>(cloud);
    const Vec3d t(0.5, -1.0, 2.0);
    const auto moved = translate(scale(field, 2.0), t);
    for (const Vec3d& q :
         random_points(Aabb{.min = Vec3d::Constant(-1.5), .max = Vec3d::Constant(1.5)}, 100, 17))
    {
        const FieldSample a = field->evaluate(q);
        const FieldSample b = moved->evaluate(2.0 * q + t);
        EXPECT_NEAR(b.value, 2.0 * a.value, 1e-12);
        EXPECT_NEAR((b.gradient - a.gradient).norm(), 0.0, 1e-12);
        EXPECT_EQ(a.defined, b.defined);
    }
    // The moved scan polygonizes to a sphere of radius 2 around t.
    const Aabb box = moved->bounds();
    const double cell = 2.0 * default_cell_size(*field);
    const MarchingCubesResult mc = marching_cubes(*moved, grid_over(box, cell));
    ASSERT_GT(mc.mesh.vertex_count(), 100U);
    for (std::size_t v = 0; v < mc.mesh.vertex_count(); ++v)
    {
        EXPECT_NEAR((mc.mesh.vertices.world(v) - t).norm(), 2.0, cell);
    }
}

TEST(Transform, BadInputIsRejected)
{
    const auto s = make_sphere(Vec3d::Zero(), 1.0);
    EXPECT_THROW((void)scale(s, 0.0), InvalidInput);
    EXPECT_THROW((void)scale(s, Vec3d(1.0, -1.0, 1.0)), InvalidInput);
    EXPECT_THROW((void)rotate(s, Vec3d::Zero(), 1.0), InvalidInput);
    EXPECT_THROW((void)rotate(s, Mat3d(Vec3d(1.0, 1.0, -1.0).asDiagonal())), InvalidInput);
    EXPECT_THROW((void)transform(s, Mat3d::Zero(), Vec3d::Zero()), InvalidInput);
    EXPECT_THROW((void)translate(nullptr, Vec3d::Zero()), InvalidInput);
    EXPECT_NO_THROW((void)rotate(s, Vec3d::UnitZ(), pi));
}

} // namespace
} // namespace pointform
