// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// Public functions that read or write spans the caller sized check the sizes in every build:
// a short (or long) buffer gets InvalidInput naming the function, never a write out of bounds.

#include "support/caller_buffers.h"

#include "pointform/core/error.h"
#include "pointform/geometry/shapes.h"
#include "pointform/implicit/operators.h"
#include "pointform/implicit/point_field.h"
#include "pointform/implicit/primitives.h"
#include "pointform/implicit/transform.h"
#include "pointform/spatial/kd_tree.h"
#include "pointform/spatial/point_grid.h"

#include <gtest/gtest.h>

#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace pointform {
namespace {

using test::expect_rejected;

const PointCloud& torus()
{
    return test::buffer_test_torus();
}

TEST(CallerBuffers, KdTreeKnn)
{
    const KdTree tree(torus().positions);
    std::vector<std::uint32_t> indices(8);
    std::vector<float> d2(8);
    EXPECT_EQ(tree.knn(torus().positions[0], 8, indices, d2), 8U);
    std::vector<std::uint32_t> short_indices(7);
    std::vector<float> short_d2(7);
    expect_rejected([&] { (void)tree.knn(torus().positions[0], 8, short_indices, d2); },
                    "KdTree::knn", "indices");
    expect_rejected([&] { (void)tree.knn(torus().positions[0], 8, indices, short_d2); },
                    "KdTree::knn", "squared_distances");
    // k beyond the tree's size needs only as many slots as there are points.
    const std::vector<Vec3f> three(torus().positions.begin(), torus().positions.begin() + 3);
    const KdTree small(three);
    std::vector<std::uint32_t> i3(3);
    std::vector<float> d3(3);
    EXPECT_EQ(small.knn(three[0], 10, i3, d3), 3U);
    expect_rejected(
        [&] {
            (void)tree.nearest_within_factor(torus().positions[0], 1.5F,
                                             PointId{static_cast<std::uint32_t>(tree.size())});
        },
        "KdTree::nearest_within_factor", "start");
    expect_rejected(
        [&] { (void)tree.nearest_within_factor(torus().positions[0], 1.5F, PointId{}); },
        "KdTree::nearest_within_factor", "start");
}

TEST(CallerBuffers, PointGridKnn)
{
    const KdTree tree(torus().positions);
    const PointGrid grid(torus().positions, 0.1F, tree);
    std::vector<std::uint32_t> slots(8);
    std::vector<float> d2(8);
    EXPECT_EQ(grid.knn(torus().positions[0], 8, slots, d2), 8U);
    std::vector<std::uint32_t> short_slots(7);
    std::vector<float> short_d2(7);
    expect_rejected([&] { (void)grid.knn(torus().positions[0], 8, short_slots, d2); },
                    "PointGrid::knn", "slots");
    expect_rejected([&] { (void)grid.knn_nearby(torus().positions[0], 8, slots, short_d2); },
                    "PointGrid::knn", "squared_distances");

    const std::vector<Vec3f> queries(torus().positions.begin(), torus().positions.begin() + 10);
    std::vector<std::uint32_t> batch_slots(80);
    std::vector<float> batch_d2(80);
    std::vector<std::uint32_t> found(10);
    grid.knn_nearby(queries, 8, batch_slots, batch_d2, found);
    EXPECT_LE(found[0], 8U); // 0 where the grid alone cannot answer
    std::vector<std::uint32_t> slots79(79);
    std::vector<float> d2_79(79);
    std::vector<std::uint32_t> found9(9);
    expect_rejected([&] { grid.knn_nearby(queries, 8, slots79, batch_d2, found); },
                    "PointGrid::knn_nearby", "slots");
    expect_rejected([&] { grid.knn_nearby(queries, 8, batch_slots, d2_79, found); },
                    "PointGrid::knn_nearby", "squared_distances");
    expect_rejected([&] { grid.knn_nearby(queries, 8, batch_slots, batch_d2, found9); },
                    "PointGrid::knn_nearby", "found");
    expect_rejected(
        [&] {
            grid.knn_nearby(queries, std::numeric_limits<std::size_t>::max() / 4, batch_slots,
                            batch_d2, found);
        },
        "PointGrid::knn_nearby", "overflows");
}

/// Every kind of field's batch evaluate() and evaluate_within() reject spans of other sizes.
TEST(CallerBuffers, FieldBatches)
{
    const auto sphere = make_sphere(Vec3d::Zero(), 1.0);
    const auto box = make_box(Vec3d(-0.5, -0.5, -0.5), Vec3d(0.5, 0.5, 2.0));
    PointCloud surfels = torus(); // with exact normals
    surfels.radii.assign(surfels.size(), 0.15F);
    const auto scan = std::make_shared<const PointField>(surfels);
    struct Case
    {
        std::string name;
        std::shared_ptr<const Field> field;
        std::string function; ///< how its evaluate_within()'s errors name it
    };
    const std::vector<Case> cases = {
        {"primitive", sphere, "Field::evaluate"},
        {"point field", scan, "PointField::evaluate"},
        {"transformed", translate(sphere, Vec3d(1, 0, 0)), "TransformedField::evaluate_within"},
        {"union", make_union({sphere, box}), "BooleanField::evaluate_within"},
        {"smooth union", make_smooth_union(sphere, box, 0.2),
         "SmoothBooleanField::evaluate_within"},
        {"offset", make_offset(scan, 0.1), "evaluate_within"},
        {"shell", make_shell(sphere, 0.1), "evaluate_within"},
    };
    const std::vector<Vec3d> points = {Vec3d(0, 0, 0), Vec3d(0.5, 0.5, 0.5), Vec3d(2, 0, 0)};
    const std::vector<double> lo(3, -1.0);
    const std::vector<double> hi(3, 1.0);
    const std::vector<double> two(2, 0.0);
    for (const Case& c : cases)
    {
        SCOPED_TRACE(c.name);
        std::vector<FieldSample> out(3);
        c.field->evaluate(points, out);
        c.field->evaluate_within(points, lo, hi, out);
        std::vector<FieldSample> short_out(2);
        std::vector<FieldSample> long_out(4);
        // Operators evaluate through Field::evaluate(), PointField through its own.
        expect_rejected([&] { c.field->evaluate(points, short_out); }, "Field::evaluate:", "out");
        expect_rejected([&] { c.field->evaluate(points, long_out); }, "Field::evaluate:", "out");
        expect_rejected([&] { c.field->evaluate_within(points, lo, hi, short_out); }, c.function,
                        "out");
        expect_rejected([&] { c.field->evaluate_within(points, two, hi, out); }, c.function, "lo");
        expect_rejected([&] { c.field->evaluate_within(points, lo, two, out); }, c.function, "hi");
    }
}

TEST(CallerBuffers, MessageNamesSizes)
{
    try
    {
        check_buffer_size("f", "out", 3, 5);
        ADD_FAILURE() << "no exception";
    }
    catch (const InvalidInput& e)
    {
        EXPECT_EQ(std::string(e.what()), "f: out has 3 entries, needs at least 5");
    }
    try
    {
        check_same_size("f", "out", 6, 5);
        ADD_FAILURE() << "no exception";
    }
    catch (const InvalidInput& e)
    {
        EXPECT_EQ(std::string(e.what()), "f: out has 6 entries, expected 5");
    }
    EXPECT_NO_THROW(check_buffer_size("f", "out", 6, 5));
    EXPECT_NO_THROW(check_same_size("f", "out", 5, 5));
}

} // namespace
} // namespace pointform
