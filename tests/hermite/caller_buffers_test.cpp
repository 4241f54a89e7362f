// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// Public functions of hermite that take caller-built index lists and neighbour tables check them
// in every build: a bad one gets InvalidInput naming the function, never a read out of bounds.

#include "support/caller_buffers.h"

#include "pointform/core/error.h"
#include "pointform/geometry/shapes.h"
#include "pointform/hermite/normals.h"
#include "pointform/hermite/orientation.h"
#include "pointform/hermite/radius.h"
#include "pointform/spatial/kd_tree.h"

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

TEST(CallerBuffers, FitPlane)
{
    const std::vector<std::uint32_t> good = {0, 1, 2, 3};
    EXPECT_FALSE(fit_plane(torus().positions, good).degenerate);
    const std::vector<std::uint32_t> bad = {0, 1, static_cast<std::uint32_t>(torus().size())};
    expect_rejected([&] { (void)fit_plane(torus().positions, bad); }, "fit_plane",
                    std::to_string(torus().size()));
    expect_rejected([&] { (void)fit_plane(torus().positions, {}); }, "fit_plane", "no indices");
}

/// Neighbour tables built by hand are checked before normals, radii or orientation use them.
TEST(CallerBuffers, NeighbourTables)
{
    const PointCloud& cloud = torus();
    const KdTree tree(cloud.positions);
    const KnnTable good = knn_batch(tree, cloud.positions, 8);
    EXPECT_EQ(estimate_normals(cloud.positions, good).normals.size(), cloud.size());

    KnnTable out_of_range = good;
    out_of_range.indices[5 * 8 + 3] = static_cast<std::uint32_t>(cloud.size());
    expect_rejected([&] { (void)estimate_normals(cloud.positions, out_of_range); },
                    "estimate_normals", "row 5");
    KnnTable ragged = good;
    ragged.indices.pop_back();
    expect_rejected([&] { (void)estimate_normals(cloud.positions, ragged); }, "estimate_normals",
                    "whole rows");
    KnnTable few_distances = good;
    few_distances.squared_distances.pop_back();
    expect_rejected([&] { (void)estimate_normals(cloud.positions, few_distances); },
                    "estimate_normals", "squared_distances");
    expect_rejected([&] { (void)influence_radii(few_distances); }, "influence_radii",
                    "squared_distances");

    const Normals normals = estimate_normals(cloud.positions, good);
    EXPECT_EQ(orient_normals_mst(cloud.positions, normals.normals, good).normals.size(),
              cloud.size());
    expect_rejected(
        [&] { (void)orient_normals_mst(cloud.positions, normals.normals, out_of_range); },
        "orientation", "out of range");
    expect_rejected(
        [&] { (void)riemannian_spanning_forest(cloud.positions, normals.normals, out_of_range); },
        "orientation", "out of range");
    expect_rejected(
        [&] { (void)riemannian_spanning_forest(cloud.positions, normals.normals, few_distances); },
        "orientation", "squared_distances");
}

} // namespace
} // namespace pointform
