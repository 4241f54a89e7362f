// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// Booleans and the other operators never lose a piece of their surface: sparse marching cubes
// from the operators' seeds gives meshes whose area, volume and component count match the
// analytic shapes, including pieces that hold no seed of any member.

#include "pointform/core/parallel.h"
#include "pointform/geometry/mesh_topology.h"
#include "pointform/implicit/operators.h"
#include "pointform/implicit/primitives.h"
#include "pointform/implicit/scene.h"
#include "pointform/implicit/transform.h"
#include "pointform/polygonize/marching_cubes.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace pointform {
namespace {

using FieldPtr = std::shared_ptr<const Field>;

constexpr double pi = std::numbers::pi;

struct Measured
{
    double area = 0.0;
    double volume = 0.0;
    std::size_t components = 0;
    bool closed = false;
    bool sparse = false; ///< polygonized from seeds, not densely
};

/// Marching cubes over the field's bounds with `cell`, from the field's seeds.
Measured measure(const Field& field, double cell)
{
    const MarchingCubesResult mc = marching_cubes(field, grid_over(field.bounds(), cell));
    Measured m;
    m.sparse = !mc.stats.dense;
    const TriMesh& mesh = mc.mesh;
    for (const auto& t : mesh.triangles)
    {
        const Vec3d a = mesh.vertices.world(t[0]);
        const Vec3d b = mesh.vertices.world(t[1]);
        const Vec3d c = mesh.vertices.world(t[2]);
        m.area += 0.5 * (b - a).cross(c - a).norm();
        m.volume += a.dot(b.cross(c)) / 6.0; // outward triangles: the enclosed volume
    }
    if (!mesh.triangles.empty())
    {
        const MeshTopology topo = analyze_topology(mesh);
        m.components = topo.components;
        m.closed = topo.is_closed() && topo.is_oriented_manifold();
    }
    return m;
}

/// The mesh of marching cubes with cell h is within O(h²) of a smooth surface and cuts sharp
/// edges by O(h): allow volume errors of h × area / 4 and area errors of h × (area / h_0)
/// with h_0 = 1/6 of the shape's size (a few percent at 40 cells across).
void expect_shape(const Measured& m, double area, double volume, std::size_t components,
                  double cell, double size)
{
    EXPECT_TRUE(m.sparse);
    EXPECT_TRUE(m.closed);
    EXPECT_EQ(m.components, components);
    EXPECT_NEAR(m.volume, volume, 0.25 * cell * area) << "area " << m.area << " vs " << area;
    EXPECT_NEAR(m.area, area, 6.0 * cell / size * area)
        << "volume " << m.volume << " vs " << volume;
}

/// A spherical cap of a ball of radius r, cut at height h above the centre (|h| < r): its
/// volume, its curved area and its flat disk's area.
struct Cap
{
    double volume;
    double curved;
    double disk;
};
Cap cap(double r, double h)
{
    const double height = r - h;
    return {.volume = pi * height * height * (3.0 * r - height) / 3.0,
            .curved = 2.0 * pi * r * height,
            .disk = pi * (r * r - h * h)};
}

/// Volume of {x, y, z ≥ a, |p| ≤ 1} by the midpoint rule over (y, z) of the exact chord in x.
double corner_of_ball_volume(double a)
{
    constexpr int n = 2000;
    const double top = std::sqrt(1.0 - 2.0 * a * a);
    const double h = (top - a) / n;
    double sum = 0.0;
    for (int i = 0; i < n; ++i)
    {
        const double y = a + (i + 0.5) * h;
        for (int j = 0; j < n; ++j)
        {
            const double z = a + (j + 0.5) * h;
            const double x2 = 1.0 - y * y - z * z;
            if (x2 > a * a)
            {
                sum += std::sqrt(x2) - a;
            }
        }
    }
    return sum * h * h;
}

TEST(BooleanPieces, IntersectionOfBallAndBoxWhereNoMemberSeedLiesOnTheResult)
{
    // The scene: no seed of the ball lies in the box nor the box's on the ball except
    // the ball's diagonal one; the corner of the ball that remains.
    const FieldPtr ball = make_sphere(Vec3d::Zero(), 1.0);
    const FieldPtr box = make_box(Vec3d::Constant(0.3), Vec3d::Constant(2.0));
    const double cell = 0.7 / 48.0;
    const Measured m = measure(*make_intersection({ball, box}), cell);
    EXPECT_TRUE(m.sparse);
    EXPECT_TRUE(m.closed);
    EXPECT_EQ(m.components, 1U);
    const double volume = corner_of_ball_volume(0.3);
    EXPECT_NEAR(m.volume, volume, 0.02 * volume);

    // Moved so that no seed of either lies on the result (the ball's diagonal seed is outside
    // the box): the sweep finds it.
    const FieldPtr far_box = make_box(Vec3d(0.3, 0.3, 0.3), Vec3d(2.0, 2.0, 0.45));
    const Measured slab = measure(*make_intersection({ball, far_box}), 0.01);
    EXPECT_TRUE(slab.sparse);
    EXPECT_EQ(slab.components, 1U);
    EXPECT_GT(slab.volume, 0.0);
}

TEST(BooleanPieces, IntersectionAndDifferenceOfBallAndHalfBoxAreCapsOfTheBall)
{
    const FieldPtr ball = make_sphere(Vec3d(0.1, -0.2, 0.3), 1.0);
    for (const double h : {-0.6, 0.0, 0.3, 0.8})
    {
        SCOPED_TRACE(h);
        const FieldPtr upper = make_box(Vec3d(-2.0, -2.0, 0.3 + h), Vec3d(2.0, 2.0, 2.0));
        const Cap c = cap(1.0, h);
        const double cell = 1.0 / 40.0;
        expect_shape(measure(*make_intersection({ball, upper}), cell), c.curved + c.disk, c.volume,
                     1, cell, 1.0);
        const Cap rest = cap(1.0, -h);
        expect_shape(measure(*make_difference(ball, upper), cell), rest.curved + rest.disk,
                     rest.volume, 1, cell, 1.0);
    }
}

TEST(BooleanPieces, DifferenceOfBoxAndInnerBallKeepsTheCavity)
{
    const FieldPtr box = make_box(Vec3d::Constant(-1.0), Vec3d::Constant(1.0));
    const FieldPtr ball = make_sphere(Vec3d(0.1, 0.0, -0.1), 0.5);
    const double cell = 2.0 / 60.0;
    // Two surfaces, one solid: the box's outside and the cavity's (inward) sphere.
    expect_shape(measure(*make_difference(box, ball), cell), 24.0 + pi, 8.0 - pi / 6.0, 2, cell,
                 2.0);
}

TEST(BooleanPieces, DifferenceThatLeavesTwoPiecesFindsBoth)
{
    // A slab through the ball's centre, at an angle to every axis: two caps remain.
    const FieldPtr ball = make_sphere(Vec3d::Zero(), 1.0);
    const Vec3d n = Vec3d(1.0, 2.0, 2.0) / 3.0;
    const Mat3d rotation = Eigen::Quaterniond::FromTwoVectors(Vec3d::UnitZ(), n).toRotationMatrix();
    const double half = 0.2;
    const FieldPtr slab =
        std::make_shared<const BoxField>(Vec3d::Zero(), Vec3d(2.0, 2.0, half), rotation, 0.0);
    const Cap c = cap(1.0, half);
    const double cell = 1.0 / 40.0;
    expect_shape(measure(*make_difference(ball, slab), cell), 2.0 * (c.curved + c.disk),
                 2.0 * c.volume, 2, cell, 1.0);

    // Three slabs cut the ball into 8 pieces, of which no axis seed of the ball lies on any.
    const FieldPtr cross = make_union({make_box(Vec3d(-2, -2, -0.1), Vec3d(2, 2, 0.1)),
                                       make_box(Vec3d(-2, -0.1, -2), Vec3d(2, 0.1, 2)),
                                       make_box(Vec3d(-0.1, -2, -2), Vec3d(0.1, 2, 2))});
    const Measured eight = measure(*make_difference(ball, cross), cell);
    EXPECT_TRUE(eight.closed);
    EXPECT_EQ(eight.components, 8U);
    const double corner = corner_of_ball_volume(0.1);
    EXPECT_NEAR(eight.volume, 8.0 * corner, 0.02 * 8.0 * corner);
}

TEST(BooleanPieces, UnionOfFarApartPrimitivesKeepsEach)
{
    const FieldPtr ball = make_sphere(Vec3d(-6.0, 0.0, 0.0), 1.0);
    const FieldPtr box = make_box(Vec3d(5.0, -1.0, -1.0), Vec3d(7.0, 1.0, 1.0));
    const FieldPtr torus = make_torus(Vec3d(0.0, 5.0, 0.0), Vec3d::UnitZ(), 1.0, 0.3);
    const double cell = 14.0 / 280.0;
    const double area = 4.0 * pi + 24.0 + 4.0 * pi * pi * 1.0 * 0.3;
    const double volume = 4.0 * pi / 3.0 + 8.0 + 2.0 * pi * pi * 1.0 * 0.09;
    const Measured m = measure(*make_union({ball, box, torus}), cell);
    EXPECT_EQ(m.components, 3U);
    expect_shape(m, area, volume, 3, cell, 0.6);
}

TEST(BooleanPieces, ThinShellCutOpenIsOneClosedHalfShell)
{
    const FieldPtr ball = make_sphere(Vec3d::Zero(), 1.0);
    const double t = 0.1;
    const FieldPtr shell = make_shell(ball, t);
    const FieldPtr upper = make_box(Vec3d(-2.0, -2.0, 0.0), Vec3d(2.0, 2.0, 2.0));
    const double ro = 1.0 + 0.5 * t;
    const double ri = 1.0 - 0.5 * t;
    const double area = 2.0 * pi * (ro * ro + ri * ri) + pi * (ro * ro - ri * ri);
    const double volume = 2.0 * pi / 3.0 * (ro * ro * ro - ri * ri * ri);
    const double cell = t / 4.0;
    expect_shape(measure(*make_difference(shell, upper), cell), area, volume, 1, cell, t);
}

/// Every operator keeps both pieces of a ball cut in two by a slab, and finds the corner of the
/// ball in the box that no member seed lies on.
TEST(BooleanPieces, OtherOperatorsKeepEveryPiece)
{
    const FieldPtr ball = make_sphere(Vec3d::Zero(), 1.0);
    const FieldPtr slab = make_box(Vec3d(-2.0, -2.0, -0.2), Vec3d(2.0, 2.0, 0.2));
    const FieldPtr two = make_difference(ball, slab);
    const FieldPtr box = make_box(Vec3d::Constant(0.3), Vec3d::Constant(2.0));
    const double cell = 1.0 / 32.0;
    struct Case
    {
        const char* name;
        FieldPtr field;
        std::size_t components;
    };
    const std::vector<Case> cases = {
        {"smooth difference", make_smooth_difference(ball, slab, 0.1), 2},
        {"smooth intersection", make_smooth_intersection(ball, box, 0.05), 1},
        {"smooth union",
         make_smooth_union(make_intersection({ball, box}), make_sphere(Vec3d(-3, 0, 0), 0.5), 0.1),
         2},
        {"linear blend", make_blend(BlendKind::Linear, {two}, 0.1), 2},
        {"super-elliptic blend", make_blend(BlendKind::SuperElliptic, {two, box}, 0.05), 2},
        {"hyperbolic blend", make_blend(BlendKind::Hyperbolic, {two}, 0.05), 2},
        {"offset", make_offset(two, 0.05), 2},
        {"inward offset", make_offset(make_intersection({ball, box}), -0.05), 1},
        {"shell", make_shell(two, 0.1), 4},
        {"morph", make_morph(two, make_intersection({ball, box}), 0.5), 1},
        {"morph of two",
         make_morph(two, make_difference(make_sphere(Vec3d::Zero(), 0.9), slab), 0.5), 2},
        {"translate", translate(make_intersection({ball, box}), Vec3d(5.0, -1.0, 2.0)), 1},
        {"rotate", rotate(two, Vec3d(1.0, 1.0, 0.0), 0.7), 2},
        {"scale", scale(make_intersection({ball, box}), Vec3d(2.0, 1.0, 0.5)), 1},
    };
    for (const Case& c : cases)
    {
        SCOPED_TRACE(c.name);
        const Measured m = measure(*c.field, cell);
        EXPECT_TRUE(m.sparse);
        EXPECT_TRUE(m.closed);
        EXPECT_EQ(m.components, c.components);
        EXPECT_GT(m.volume, 0.0);
    }
}

TEST(BooleanPieces, SharedBindingsGiveTheSameMeshWhateverTheThreadCount)
{
    // Bindings named several times are shared nodes that remember batches per thread: the mesh
    // is the same bytes with one thread and with several.
    const Scene scene = parse_scene(
        "let a = sphere([0, 0, 0], 1)\n"
        "let b = box([0.3, 0.3, 0.3], [2, 2, 2])\n"
        "let c = intersection(a, b)\n"
        "let d = union(c, translate(c, [-0.9, 0, 0]), c)\n"
        "difference(d, sphere([0.45, 0.45, 0.45], 0.1), translate(d, [0, 0, 1.5]))");
    const CellGrid grid = grid_over(scene.field->bounds(), 1.0 / 64.0);
    const int threads = thread_count();
    set_thread_count(1);
    const MarchingCubesResult one = marching_cubes(*scene.field, grid);
    set_thread_count(std::max(threads, 4));
    const MarchingCubesResult many = marching_cubes(*scene.field, grid);
    set_thread_count(0);
    ASSERT_FALSE(one.mesh.triangles.empty());
    ASSERT_EQ(one.mesh.vertex_count(), many.mesh.vertex_count());
    ASSERT_EQ(one.mesh.triangles, many.mesh.triangles);
    for (std::size_t v = 0; v < one.mesh.vertex_count(); ++v)
    {
        ASSERT_EQ(one.mesh.vertices.world(v), many.mesh.vertices.world(v));
    }
    // Two corners of the ball, one with a cavity: three surfaces.
    const Measured m = measure(*scene.field, 1.0 / 64.0);
    EXPECT_EQ(m.components, 3U);
    EXPECT_TRUE(m.closed);
}

TEST(BooleanPieces, SeedsLieOnTheResult)
{
    // A's seeds inside B are no seeds of A ∪ B.
    const FieldPtr a = make_sphere(Vec3d::Zero(), 1.0);
    const FieldPtr b = make_sphere(Vec3d(0.5, 0.0, 0.0), 1.0);
    const FieldPtr u = make_union({a, b});
    std::vector<Vec3d> seeds;
    u->append_seeds(seeds);
    ASSERT_FALSE(seeds.empty());
    for (const Vec3d& s : seeds)
    {
        EXPECT_NEAR(u->evaluate(s).value, 0.0, 1e-9) << s.transpose();
    }
    // A member given twice gives its seeds once.
    std::vector<Vec3d> once;
    a->append_seeds(once);
    std::vector<Vec3d> twice;
    make_union({a, a})->append_seeds(twice);
    EXPECT_EQ(twice.size(), once.size());
}

} // namespace
} // namespace pointform
