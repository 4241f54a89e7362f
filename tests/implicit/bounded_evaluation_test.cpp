// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// Field::evaluate_within: every operator gives evaluate()'s sample, bit for bit, where the value
// lies in the range asked, and a value on the right side of it elsewhere; one by one and in
// batches alike, whatever the thread count. Marching cubes, which asks for ranges, makes the same
// mesh as with exact values everywhere.

#include "pointform/core/parallel.h"
#include "pointform/geometry/shapes.h"
#include "pointform/hermite/radius.h"
#include "pointform/implicit/operators.h"
#include "pointform/implicit/point_field.h"
#include "pointform/implicit/primitives.h"
#include "pointform/implicit/transform.h"
#include "pointform/polygonize/marching_cubes.h"
#include "pointform/spatial/kd_tree.h"

#include "support/thread_counts.h"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <vector>

namespace pointform {
namespace {

constexpr double inf = std::numeric_limits<double>::infinity();

/// A sampled shape with exact normals and automatic radii, moved by `offset`.
std::shared_ptr<const PointField> scan(Shape shape, std::size_t count, const Vec3d& offset)
{
    PointCloud cloud = sample_shape(shape, {.count = count, .seed = 3});
    cloud.origin = offset;
    cloud.normals.resize(cloud.size());
    for (std::size_t i = 0; i < cloud.size(); ++i)
    {
        const Vec3f p = cloud.positions[i];
        const Vec3f core =
            shape == Shape::Torus ? Vec3f(p.x(), p.y(), 0.0F).normalized() : Vec3f::Zero();
        cloud.normals[i] = (p - core).normalized();
    }
    const KdTree tree(cloud.positions);
    cloud.radii = influence_radii(knn_batch(tree, cloud.positions, 17), 1.5);
    return std::make_shared<const PointField>(std::move(cloud));
}

struct Case
{
    std::string name;
    std::shared_ptr<const Field> field;
};

/// Every operator that bounds its members, over scans and primitives, alone and nested.
std::vector<Case> cases()
{
    const auto a = scan(Shape::Sphere, 6000, Vec3d(0.0, 0.0, 0.0));
    const auto b = scan(Shape::Torus, 6000, Vec3d(0.9, 0.0, 0.0));
    const auto ball = make_sphere(Vec3d(0.0, 0.0, 1.0), 0.3);
    const auto slab = make_box(Vec3d(-0.2, -1.5, 0.3), Vec3d(0.2, 1.5, 1.5));
    const auto rod = make_cylinder(Vec3d(-2.0, 0.0, 0.0), Vec3d(2.0, 0.0, 0.0), 0.15);
    const auto moved = translate(rotate(scale(b, Vec3d(1.5, 1.2, 1.5)), Vec3d(0.0, 0.0, 1.0), 0.7),
                                 Vec3d(0.1, 0.2, 0.0));
    return {
        {"union", make_union({a, b, ball})},
        {"intersection", make_intersection({a, b})},
        {"difference",
         std::make_shared<const BooleanField>(
             BooleanOp::Difference, std::vector<std::shared_ptr<const Field>>{a, ball, rod})},
        {"smooth union", make_smooth_union(a, b, 0.1)},
        {"smooth intersection", make_smooth_intersection(ball, a, 0.2)},
        {"smooth difference", make_smooth_difference(a, rod, 0.1)},
        {"offset out", make_offset(a, 0.15)},
        {"offset in", make_offset(b, -0.05)},
        {"shell", make_shell(a, 0.1)},
        {"transform", moved},
        {"scene", make_difference(make_union({make_smooth_union(a, moved, 0.1), ball}),
                                  make_union({slab, rod}))},
        {"union of itself", make_union({a, a})},
    };
}

/// Points over a box a little larger than the field's bounds.
std::vector<Vec3d> points_around(const Field& field, std::size_t count)
{
    const Aabb box = field.bounds();
    const Vec3d margin = 0.3 * (box.max - box.min);
    std::mt19937_64 rng(11);
    std::vector<Vec3d> points(count);
    for (Vec3d& p : points)
    {
        for (int j = 0; j < 3; ++j)
        {
            std::uniform_real_distribution<double> u(box.min[j] - margin[j],
                                                     box.max[j] + margin[j]);
            p[j] = u(rng);
        }
    }
    return points;
}

struct Range
{
    double lo;
    double hi;
};

/// Ranges around, above, below and at the exact value, empty ones and unbounded ones.
Range range_for(double exact, std::size_t i)
{
    const double w = 0.02 * static_cast<double>(i % 7);
    switch (i % 8)
    {
        case 0:
            return {-inf, inf};
        case 1:
            return {exact - w, exact + w};
        case 2:
            return {exact + 0.01 + w, inf}; // all above: the value must come back below lo
        case 3:
            return {-inf, exact - 0.01 - w}; // all below: the value must come back above hi
        case 4:
            return {-0.05, 0.05};
        case 5:
            return {exact, exact};
        case 6:
            return {0.1, -0.1}; // empty
        default:
            return {-w, 3.0 * w};
    }
}

void expect_within(const FieldSample& exact, const FieldSample& got, const Range& r,
                   const std::string& what)
{
    if (exact.value >= r.lo && exact.value <= r.hi)
    {
        ASSERT_EQ(std::bit_cast<std::uint64_t>(got.value),
                  std::bit_cast<std::uint64_t>(exact.value))
            << what << ": " << got.value << " vs " << exact.value;
        ASSERT_EQ(got.gradient, exact.gradient) << what;
        ASSERT_EQ(got.defined, exact.defined) << what;
    }
    else if (r.lo > r.hi)
    {
        ASSERT_TRUE(got.value < r.lo || got.value > r.hi) << what;
    }
    else if (exact.value < r.lo)
    {
        ASSERT_LT(got.value, r.lo) << what << ": exact " << exact.value;
    }
    else
    {
        ASSERT_GT(got.value, r.hi) << what << ": exact " << exact.value;
    }
}

TEST(BoundedEvaluation, EveryOperatorIsExactWithinItsRangeAndKeepsTheSideBeyond)
{
    for (const Case& c : cases())
    {
        const std::vector<Vec3d> points = points_around(*c.field, 1200);
        std::vector<FieldSample> exact(points.size());
        std::vector<double> lo(points.size());
        std::vector<double> hi(points.size());
        for (std::size_t i = 0; i < points.size(); ++i)
        {
            exact[i] = c.field->evaluate(points[i]);
            const Range r = range_for(exact[i].value, i);
            lo[i] = r.lo;
            hi[i] = r.hi;
            expect_within(exact[i], c.field->evaluate_within(points[i], r.lo, r.hi), r,
                          c.name + " at point " + std::to_string(i));
        }
        // Batches give the same samples as one by one, with any number of threads.
        for (const int threads : {1, 2, 3})
        {
            set_thread_count(threads);
            reset_parallel_stats();
            std::vector<FieldSample> batch(points.size());
            c.field->evaluate_within(points, lo, hi, batch);
            std::vector<FieldSample> plain(points.size());
            c.field->evaluate(points, plain);
            test::expect_parallel_run(threads, {.min_multi_block_loops = 2});
            for (std::size_t i = 0; i < points.size(); ++i)
            {
                const FieldSample one = c.field->evaluate_within(points[i], lo[i], hi[i]);
                ASSERT_EQ(std::bit_cast<std::uint64_t>(batch[i].value),
                          std::bit_cast<std::uint64_t>(one.value))
                    << c.name << " batch at " << i;
                ASSERT_EQ(batch[i].gradient, one.gradient) << c.name;
                ASSERT_EQ(batch[i].defined, one.defined) << c.name;
                ASSERT_EQ(std::bit_cast<std::uint64_t>(plain[i].value),
                          std::bit_cast<std::uint64_t>(exact[i].value))
                    << c.name << " exact batch at " << i;
            }
        }
        set_thread_count(0);
    }
}

TEST(BoundedEvaluation, FarOutsideAScanAnswersFromALowerBound)
{
    const auto sphere = scan(Shape::Sphere, 6000, Vec3d(0.0, 0.0, 0.0));
    for (const Vec3d& p : {Vec3d(1.6, 0.0, 0.0), Vec3d(0.0, -1.3, 0.9), Vec3d(4.0, 3.0, -2.0)})
    {
        const double truth = p.norm() - 1.0;
        const FieldSample exact = sphere->evaluate(p);
        EXPECT_FALSE(exact.defined);
        EXPECT_NEAR(exact.value, truth, 0.01 * truth + 0.01); // samples are ~0.03 apart
        const double cap = 0.5 * truth;
        const FieldSample bounded = sphere->evaluate_within(p, -inf, cap);
        EXPECT_GT(bounded.value, cap);
        EXPECT_LE(bounded.value, exact.value); // a lower bound on the distance
    }
    // Deep inside, the value stays negative whatever the cap.
    EXPECT_LT(sphere->evaluate_within(Vec3d(0.1, 0.0, 0.0), -inf, -2.0).value, -0.5);
}

/// The field that it wraps, without ever bounding its members: exact values everywhere.
class ExactOnly final : public Field
{
public:
    explicit ExactOnly(std::shared_ptr<const Field> inner) : inner_(std::move(inner)) {}
    [[nodiscard]] FieldSample evaluate(const Vec3d& p) const override
    {
        return inner_->evaluate(p);
    }
    using Field::evaluate;
    [[nodiscard]] Aabb bounds() const override { return inner_->bounds(); }
    void append_seeds(std::vector<Vec3d>& seeds) const override { inner_->append_seeds(seeds); }

private:
    std::shared_ptr<const Field> inner_;
};

TEST(BoundedEvaluation, MarchingCubesMakesTheMeshThatExactValuesMake)
{
    const std::vector<Case> all = cases();
    for (const Case& c : all)
    {
        if (c.name != "scene" && c.name != "shell" && c.name != "smooth difference")
        {
            continue;
        }
        const Aabb box = c.field->bounds();
        const CellGrid grid = grid_over(box, cell_for_resolution(box, 48));
        const MarchingCubesResult bounded = marching_cubes(*c.field, grid);
        const ExactOnly exact_field(c.field);
        const MarchingCubesResult exact = marching_cubes(exact_field, grid);
        ASSERT_GT(exact.mesh.face_count(), 100U) << c.name;
        ASSERT_EQ(bounded.mesh.triangles, exact.mesh.triangles) << c.name;
        ASSERT_EQ(bounded.mesh.vertices.positions, exact.mesh.vertices.positions) << c.name;
        ASSERT_EQ(bounded.mesh.vertices.normals, exact.mesh.vertices.normals) << c.name;
        // Fewer exact evaluations of the members is the point; the corners are all visited.
        EXPECT_EQ(bounded.stats.cells_visited, exact.stats.cells_visited) << c.name;
    }
}

} // namespace
} // namespace pointform
