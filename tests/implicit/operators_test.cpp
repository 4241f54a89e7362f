// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/implicit/operators.h"

#include "pointform/core/error.h"
#include "pointform/geometry/mesh_topology.h"
#include "pointform/geometry/shapes.h"
#include "pointform/implicit/point_field.h"
#include "pointform/implicit/primitives.h"
#include "pointform/implicit/transform.h"
#include "pointform/polygonize/marching_cubes.h"

#include "field_test_util.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

namespace pointform {
namespace {

using test::numeric_gradient;
using test::random_points;

using FieldPtr = std::shared_ptr<const Field>;

/// A sphere of radius `radius` around `center`, sampled exactly with its true normals, as a
/// point field (influence radius `influence`).
FieldPtr sampled_sphere(const Vec3d& center, double radius, float influence,
                        std::size_t count = 4000, std::uint64_t seed = 3)
{
    PointCloud cloud = sample_shape(Shape::Sphere, {.count = count, .seed = seed});
    for (Vec3f& p : cloud.positions)
    {
        p *= static_cast<float>(radius);
    }
    cloud.origin += center;
    cloud.radii.assign(cloud.size(), influence);
    return std::make_shared<const PointField>(std::move(cloud));
}

void expect_gradient_matches(const Field& f, const Aabb& box, int count, std::uint64_t seed)
{
    int mismatches = 0;
    for (const Vec3d& p : random_points(box, count, seed))
    {
        if ((f.evaluate(p).gradient - numeric_gradient(f, p)).norm() > 1e-5)
        {
            ++mismatches;
        }
    }
    EXPECT_LE(mismatches, count / 50); // points straddling a crease of min/max
}

MarchingCubesResult polygonize(const Field& f, double cell)
{
    return marching_cubes(f, grid_over(f.bounds(), cell));
}

std::vector<Vec3d> vertices(const TriMesh& mesh)
{
    std::vector<Vec3d> out;
    for (std::size_t v = 0; v < mesh.vertex_count(); ++v)
    {
        out.push_back(mesh.vertices.world(v));
    }
    return out;
}

/// One closed, oriented, genus-0 piece.
void expect_one_closed_sphere(const TriMesh& mesh)
{
    ASSERT_FALSE(mesh.triangles.empty());
    const MeshTopology topo = analyze_topology(mesh);
    EXPECT_TRUE(topo.is_closed());
    EXPECT_TRUE(topo.is_oriented_manifold());
    EXPECT_EQ(topo.components, 1U);
    EXPECT_EQ(topo.euler_characteristic, 2);
}

const Aabb scene{.min = Vec3d(-2.5, -2.0, -2.0), .max = Vec3d(2.5, 2.0, 2.0)};

// ---------------------------------------------------------------------------------------------
// Booleans

TEST(Boolean, ValuesAreMinMaxAndTheDifferenceOfTable2)
{
    const FieldPtr a = make_sphere(Vec3d(-0.4, 0.0, 0.0), 1.0);
    const FieldPtr b = make_box(Vec3d(-0.2, -0.5, -0.5), Vec3d(1.5, 0.5, 0.5));
    const FieldPtr c = make_torus(Vec3d(0.3, 0.0, 0.0), Vec3d::UnitX(), 0.8, 0.2);
    const FieldPtr u = make_union({a, b, c});
    const FieldPtr i = make_intersection({a, b, c});
    const FieldPtr d = make_difference(a, b);
    for (const Vec3d& p : random_points(scene, 300, 1))
    {
        const double fa = a->evaluate(p).value;
        const double fb = b->evaluate(p).value;
        const double fc = c->evaluate(p).value;
        EXPECT_EQ(u->evaluate(p).value, std::min({fa, fb, fc}));
        EXPECT_EQ(i->evaluate(p).value, std::max({fa, fb, fc}));
        EXPECT_EQ(d->evaluate(p).value, std::max(fa, -fb));
        EXPECT_TRUE(u->evaluate(p).defined && d->evaluate(p).defined);
    }
    expect_gradient_matches(*u, scene, 300, 2);
    expect_gradient_matches(*i, scene, 300, 3);
    expect_gradient_matches(*d, scene, 300, 4);

    const Aabb ua = u->bounds();
    EXPECT_NEAR((ua.min - Vec3d(-1.4, -1.0, -1.0)).norm(), 0.0, 1e-12);
    EXPECT_NEAR((ua.max - Vec3d(1.5, 1.0, 1.0)).norm(), 0.0, 1e-12);
    const Aabb ia = make_intersection({a, b})->bounds();
    EXPECT_NEAR((ia.min - Vec3d(-0.2, -0.5, -0.5)).norm(), 0.0, 1e-12);
    EXPECT_NEAR((ia.max - Vec3d(0.6, 0.5, 0.5)).norm(), 0.0, 1e-12);
    EXPECT_NEAR((d->bounds().max - a->bounds().max).norm(), 0.0, 0.0);
    // A half-space cut by a bounded shape is bounded.
    const Aabb cut =
        make_intersection({a, make_half_space(Vec3d::Zero(), Vec3d(1, 1, 0))})->bounds();
    EXPECT_TRUE(cut.min.allFinite() && cut.max.allFinite());
}

/// A ∪ A = A, A ∩ B ⊆ A (and ⊆ B), A ⊆ A ∪ B by sampling; A \ A has no surface.
void check_boolean_identities(const FieldPtr& a, const FieldPtr& b, double cell)
{
    const FieldPtr aa = make_union({a, a});
    const FieldPtr ab_and = make_intersection({a, b});
    const FieldPtr ab_or = make_union({a, b});
    std::size_t inside_intersection = 0;
    for (const Vec3d& p : random_points(scene, 4000, 5))
    {
        const FieldSample fa = a->evaluate(p);
        const FieldSample faa = aa->evaluate(p);
        EXPECT_EQ(faa.value, fa.value);
        EXPECT_EQ(faa.defined, fa.defined);
        const double fb = b->evaluate(p).value;
        if (ab_and->evaluate(p).value <= 0.0)
        {
            ++inside_intersection;
            EXPECT_LE(fa.value, 0.0);
            EXPECT_LE(fb, 0.0);
        }
        if (fa.value <= 0.0)
        {
            EXPECT_LE(ab_or->evaluate(p).value, 0.0);
        }
    }
    EXPECT_GT(inside_intersection, 0U);
    const MarchingCubesResult empty = polygonize(*make_difference(a, a), cell);
    EXPECT_EQ(empty.mesh.triangles.size(), 0U);
    EXPECT_GT(empty.stats.cells_visited, 0U); // the seeds were visited
}

TEST(Boolean, IdentitiesOnPrimitives)
{
    check_boolean_identities(make_sphere(Vec3d(-0.4, 0.0, 0.0), 1.0),
                             make_cylinder(Vec3d(0.0, -1.5, 0.0), Vec3d(0.0, 1.5, 0.2), 0.6), 0.05);
}

TEST(Boolean, IdentitiesOnSampledSpheres)
{
    check_boolean_identities(sampled_sphere(Vec3d(-0.5, 0.0, 0.0), 1.0, 0.15F),
                             sampled_sphere(Vec3d(0.5, 0.0, 0.0), 1.0, 0.15F, 4000, 4), 0.04);
}

TEST(Boolean, UnionOfOverlappingSampledSpheresHasNoInnerSurface)
{
    const Vec3d ca(-0.5, 0.0, 0.0);
    const Vec3d cb(0.5, 0.1, 0.0);
    const FieldPtr a = sampled_sphere(ca, 1.0, 0.15F);
    const FieldPtr b = sampled_sphere(cb, 1.0, 0.15F, 4000, 4);
    const double cell = 0.04;
    const MarchingCubesResult mc = polygonize(*make_union({a, b}), cell);
    expect_one_closed_sphere(mc.mesh);
    for (const Vec3d& v : vertices(mc.mesh))
    {
        EXPECT_GE((v - ca).norm(), 1.0 - 0.5 * cell);
        EXPECT_GE((v - cb).norm(), 1.0 - 0.5 * cell);
        EXPECT_LE(std::min((v - ca).norm(), (v - cb).norm()), 1.0 + 0.5 * cell);
    }
}

TEST(Boolean, DifferenceOfSampledSpheresCutsCleanly)
{
    const Vec3d ca(-0.5, 0.0, 0.0);
    const Vec3d cb(0.5, 0.1, 0.0);
    const FieldPtr a = sampled_sphere(ca, 1.0, 0.15F);
    const FieldPtr b = sampled_sphere(cb, 1.0, 0.15F, 4000, 4);
    const double cell = 0.04;
    const MarchingCubesResult mc = polygonize(*make_difference(a, b), cell);
    expect_one_closed_sphere(mc.mesh);
    for (const Vec3d& v : vertices(mc.mesh))
    {
        EXPECT_GE((v - cb).norm(), 1.0 - 0.5 * cell); // nothing left inside B
        EXPECT_LE((v - ca).norm(), 1.0 + 0.5 * cell); // nothing outside A
    }
    // The cut face exists: some vertices lie on B's sphere well inside A.
    const std::vector<Vec3d> points = vertices(mc.mesh);
    const auto on_cut = std::count_if(points.begin(), points.end(),
                                      [&](const Vec3d& v) { return (v - ca).norm() < 0.8; });
    EXPECT_GT(on_cut, 100);
}

// ---------------------------------------------------------------------------------------------
// Smooth Booleans and Table-3 blends

TEST(SmoothBoolean, EqualsTheBooleanOutsideTheBandAndStaysWithinIt)
{
    const FieldPtr a = make_sphere(Vec3d(-0.6, 0.0, 0.0), 1.0);
    const FieldPtr b = make_box(Vec3d(-0.3, -0.6, -0.6), Vec3d(1.2, 0.6, 0.6));
    const double k = 0.3;
    const FieldPtr su = make_smooth_union(a, b, k);
    const FieldPtr si = make_smooth_intersection(a, b, k);
    const FieldPtr sd = make_smooth_difference(a, b, k);
    for (const Vec3d& p : random_points(scene, 2000, 6))
    {
        const double fa = a->evaluate(p).value;
        const double fb = b->evaluate(p).value;
        const double vu = su->evaluate(p).value;
        const double vi = si->evaluate(p).value;
        const double vd = sd->evaluate(p).value;
        if (std::abs(fa - fb) >= k)
        {
            EXPECT_EQ(vu, std::min(fa, fb));
            EXPECT_EQ(vi, std::max(fa, fb));
        }
        EXPECT_LE(vu, std::min(fa, fb));
        EXPECT_GE(vu, std::min(fa, fb) - 0.25 * k);
        EXPECT_GE(vi, std::max(fa, fb));
        EXPECT_LE(vi, std::max(fa, fb) + 0.25 * k);
        EXPECT_GE(vd, std::max(fa, -fb));
        EXPECT_LE(vd, std::max(fa, -fb) + 0.25 * k);
        // Distance-like: the gradient never exceeds 1.
        EXPECT_LE(su->evaluate(p).gradient.norm(), 1.0 + 1e-12);
    }
    expect_gradient_matches(*su, scene, 300, 7);
    expect_gradient_matches(*si, scene, 300, 8);
    expect_gradient_matches(*sd, scene, 300, 9);
    for (const FieldPtr& f : {su, si, sd})
    {
        expect_one_closed_sphere(polygonize(*f, 0.04).mesh);
    }
}

struct BlendCase
{
    const char* name;
    FieldPtr field;
    double range;   ///< how far outside the union the blend can reach
    bool exact_far; ///< equals the members far from the junction
};

TEST(Blend, JoinsTwoSpheresBetweenTheirUnionAndItsOffset)
{
    // Two unit spheres 0.4 apart: every blend below bridges the gap.
    const Vec3d ca(-1.2, 0.0, 0.0);
    const Vec3d cb(1.2, 0.0, 0.0);
    const FieldPtr a = make_sphere(ca, 1.0);
    const FieldPtr b = make_sphere(cb, 1.0);
    const FieldPtr both = make_union({a, b});
    const double range = 0.8;
    const std::vector<BlendCase> cases = {
        {"linear", make_blend(BlendKind::Linear, {a, b}, range), range, true},
        {"super-elliptic", make_blend(BlendKind::SuperElliptic, {a, b}, range, 2.0), range, true},
        {"super-elliptic β=1.5", make_blend(BlendKind::SuperElliptic, {a, b}, range, 1.5), range,
         true},
        {"hyperbolic", make_blend(BlendKind::Hyperbolic, {a, b}, range), range, false},
        {"smooth union", make_smooth_union(a, b, 1.0), 0.25, true},
    };
    const double cell = 0.06;
    const double tol = 1e-3;
    for (const BlendCase& c : cases)
    {
        SCOPED_TRACE(c.name);
        expect_gradient_matches(*c.field, scene, 150, 10);
        // The gap's midpoint is inside: the spheres are joined.
        EXPECT_LT(c.field->evaluate(Vec3d::Zero()).value, 0.0);
        const MarchingCubesResult mc = polygonize(*c.field, cell);
        expect_one_closed_sphere(mc.mesh);
        double far_deviation = 0.0;
        for (const Vec3d& v : vertices(mc.mesh))
        {
            const double fu = both->evaluate(v).value;
            EXPECT_GE(fu, -tol);          // the blend only adds material
            EXPECT_LE(fu, c.range + tol); // within the blend range of the union
            if (v.x() < ca.x() - 0.3 || v.x() > cb.x() + 0.3)
            {
                far_deviation = std::max(far_deviation, fu);
                if (!c.exact_far)
                {
                    // The hyperbolic blend approaches each member as 1/distance to the other.
                    const double fa = a->evaluate(v).value;
                    const double fb = b->evaluate(v).value;
                    EXPECT_LE(std::min(fa, fb), range * range / std::max(fa, fb) + tol);
                }
            }
        }
        if (c.exact_far)
        {
            EXPECT_LE(far_deviation, tol);
        }
        else
        {
            EXPECT_GT(far_deviation, tol); // not exact, as documented
        }
    }
}

TEST(Blend, OneMemberIsTheMemberAndParametersAreChecked)
{
    const FieldPtr a = make_torus(Vec3d::Zero(), Vec3d::UnitZ(), 1.0, 0.3);
    const BlendField linear(BlendKind::Linear, {a}, {2.0});
    const BlendField elliptic(BlendKind::SuperElliptic, {a}, {2.0}, 3.0);
    for (const Vec3d& p : random_points(scene, 500, 11))
    {
        const double f = a->evaluate(p).value;
        // Within the range 1/α = 0.5 the value is the member's; beyond, it keeps growing.
        EXPECT_NEAR(linear.evaluate(p).value, f, 1e-12);
        EXPECT_NEAR(elliptic.evaluate(p).value, f, 1e-12);
    }
    EXPECT_THROW(BlendField(BlendKind::SuperElliptic, {a, a}, {1.0}, 0.5), InvalidInput);
    EXPECT_THROW(BlendField(BlendKind::Linear, {a, a}, {1.0, 1.0, 1.0}), InvalidInput);
    EXPECT_THROW(BlendField(BlendKind::Linear, {a, a}, {1.0, -1.0}), InvalidInput);
    EXPECT_THROW((void)make_blend(BlendKind::Hyperbolic, {a, a}, 0.0), InvalidInput);
    EXPECT_THROW((void)make_blend(BlendKind::Hyperbolic, {}, 1.0), InvalidInput);
}

TEST(Blend, JoinsAScanAndAPrimitiveBeyondTheScansInfluenceRadius)
{
    // The fillet lies up to the blend range (0.4) from the scan, beyond its influence radius
    // (0.15): the scan's fallback distance is trusted outside it.
    const FieldPtr scan = sampled_sphere(Vec3d(-1.1, 0.0, 0.0), 1.0, 0.15F);
    const FieldPtr ball = make_sphere(Vec3d(1.1, 0.0, 0.0), 1.0);
    const FieldPtr blend = make_blend(BlendKind::SuperElliptic, {scan, ball}, 0.4, 2.0);
    const MarchingCubesResult mc = polygonize(*blend, 0.04);
    expect_one_closed_sphere(mc.mesh);
    EXPECT_EQ(mc.stats.undefined_cells, 0U);
}

// ---------------------------------------------------------------------------------------------
// Offset, shell, morph

TEST(Offset, SampledSphereOffsetIsTheSphereOfRadiusRPlusD)
{
    const double radius = 1.0;
    const FieldPtr scan = sampled_sphere(Vec3d(0.2, 0.0, -0.1), radius, 0.15F);
    const double cell = 0.04;
    // 0.3: beyond the influence radius (trusted outside); inwards the corners must stay within it.
    for (const double d : {0.1, 0.3, -0.03})
    {
        SCOPED_TRACE(d);
        const MarchingCubesResult mc = polygonize(*make_offset(scan, d), cell);
        expect_one_closed_sphere(mc.mesh);
        for (const Vec3d& v : vertices(mc.mesh))
        {
            EXPECT_NEAR((v - Vec3d(0.2, 0.0, -0.1)).norm(), radius + d, cell);
        }
    }
    // Exact on a primitive; bounds grow by d.
    const FieldPtr box = make_box(Vec3d::Zero(), Vec3d::Ones());
    const FieldPtr grown = make_offset(box, 0.2);
    EXPECT_NEAR(grown->evaluate(Vec3d(2.0, 0.5, 0.5)).value, 0.8, 1e-15);
    EXPECT_NEAR((grown->bounds().min - Vec3d::Constant(-0.2)).norm(), 0.0, 1e-15);
}

TEST(Offset, ShellHasTwoSurfacesAtPlusMinusHalfTheThickness)
{
    const FieldPtr ball = make_sphere(Vec3d::Zero(), 1.0);
    const double t = 0.3;
    const double cell = 0.04;
    const MarchingCubesResult mc = polygonize(*make_shell(ball, t), cell);
    const MeshTopology topo = analyze_topology(mc.mesh);
    EXPECT_TRUE(topo.is_closed());
    EXPECT_EQ(topo.components, 2U);
    EXPECT_EQ(topo.euler_characteristic, 4);
    std::size_t inner = 0;
    for (const Vec3d& v : vertices(mc.mesh))
    {
        const double r = v.norm();
        EXPECT_NEAR(std::min(std::abs(r - 1.15), std::abs(r - 0.85)), 0.0, 1e-3);
        inner += r < 1.0 ? 1 : 0;
    }
    EXPECT_GT(inner, 100U);
    EXPECT_THROW((void)make_shell(ball, 0.0), InvalidInput);
}

TEST(Morph, EndsReproduceTheInputsAndTheMiddleInterpolates)
{
    const FieldPtr a = make_sphere(Vec3d(0.1, 0.0, 0.0), 1.0);
    const FieldPtr b = make_box(Vec3d(-0.5, -0.8, -0.6), Vec3d(0.7, 0.8, 0.6));
    const FieldPtr m0 = make_morph(a, b, 0.0);
    const FieldPtr m1 = make_morph(a, b, 1.0);
    const double t = 0.3;
    const FieldPtr mt = make_morph(a, b, t);
    for (const Vec3d& p : random_points(scene, 300, 12))
    {
        const FieldSample fa = a->evaluate(p);
        const FieldSample fb = b->evaluate(p);
        EXPECT_EQ(m0->evaluate(p).value, fa.value);
        EXPECT_EQ(m1->evaluate(p).value, fb.value);
        EXPECT_EQ((m0->evaluate(p).gradient - fa.gradient).norm(), 0.0);
        // The paper's form f₁ + t'·f₂, t' = t/(1 − t), has the same sign (and zero set).
        const double paper = fa.value + t / (1.0 - t) * fb.value;
        EXPECT_NEAR(mt->evaluate(p).value, (1.0 - t) * paper, 1e-12);
    }
    const MarchingCubesResult mesh0 = polygonize(*m0, 0.04);
    for (const Vec3d& v : vertices(mesh0.mesh))
    {
        EXPECT_NEAR(a->evaluate(v).value, 0.0, 1e-3);
    }
    const MarchingCubesResult mesh1 = polygonize(*m1, 0.04);
    for (const Vec3d& v : vertices(mesh1.mesh))
    {
        EXPECT_NEAR(b->evaluate(v).value, 0.0, 1e-3);
    }
    expect_one_closed_sphere(mesh0.mesh);
    expect_one_closed_sphere(mesh1.mesh);
    expect_one_closed_sphere(polygonize(*mt, 0.04).mesh);
    expect_gradient_matches(*mt, scene, 300, 13);
}

TEST(Morph, BetweenTwoConcentricScansIsTheSphereOfTheMeanRadius)
{
    // The surfaces are 0.4 apart, beyond the influence radius (0.15): the morph reads the
    // scans' fallback distances (UndefinedPolicy::Ignore).
    const FieldPtr small = sampled_sphere(Vec3d::Zero(), 1.0, 0.15F);
    const FieldPtr large = sampled_sphere(Vec3d::Zero(), 1.4, 0.15F, 6000, 5);
    const double cell = 0.05;
    const MarchingCubesResult mc = polygonize(*make_morph(small, large, 0.5), cell);
    expect_one_closed_sphere(mc.mesh);
    for (const Vec3d& v : vertices(mc.mesh))
    {
        EXPECT_NEAR(v.norm(), 1.2, cell);
    }
    const FieldPtr far = make_sphere(Vec3d(10.0, 0.0, 0.0), 1.0);
    EXPECT_THROW((void)make_morph(small, far, 0.5), InvalidInput);
    EXPECT_THROW((void)make_morph(small, large, 1.5), InvalidInput);
}

TEST(Operators, BadInputIsRejected)
{
    const FieldPtr a = make_sphere(Vec3d::Zero(), 1.0);
    EXPECT_THROW((void)make_union({}), InvalidInput);
    EXPECT_THROW((void)make_union({a, nullptr}), InvalidInput);
    EXPECT_THROW((void)make_difference(a, nullptr), InvalidInput);
    EXPECT_THROW(BooleanField(BooleanOp::Difference, {a}), InvalidInput);
    EXPECT_THROW((void)make_smooth_union(a, a, 0.0), InvalidInput);
    EXPECT_THROW((void)make_offset(a, std::nan("")), InvalidInput);
    EXPECT_THROW((void)make_offset(nullptr, 1.0), InvalidInput);
}

} // namespace
} // namespace pointform
