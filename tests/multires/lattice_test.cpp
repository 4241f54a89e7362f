// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// Global free-form deformation (Sederberg and Parry): Bernstein lattices at rest and under
// affine maps, in plain mode and with the details riding along.

#include "pointform/multires/lattice.h"

#include "pointform/core/error.h"
#include "pointform/multires/details.h"

#include "multires_fixtures.h"
#include "support/thread_counts.h"

#include <gtest/gtest.h>

namespace pointform {
namespace {

/// A lattice box around every vertex of `mesh` (a margin of 10%).
std::pair<Vec3d, Vec3d> box_around(const MultiresMesh& mesh)
{
    Vec3d lo = Vec3d::Constant(1e300);
    Vec3d hi = Vec3d::Constant(-1e300);
    for (std::uint32_t v = 0; v < mesh.vertex_count(); ++v)
    {
        lo = lo.cwiseMin(mesh.world(v));
        hi = hi.cwiseMax(mesh.world(v));
    }
    const Vec3d margin = 0.1 * (hi - lo);
    return {lo - margin, hi + margin};
}

TEST(Lattice, AtRestIsTheIdentity)
{
    const MultiresMesh original = test::relief_sphere(3);
    const auto [lo, hi] = box_around(original);
    const Lattice lattice = rest_lattice(lo, hi, {3, 2, 4});
    for (const LatticeMode mode : {LatticeMode::Plain, LatticeMode::Details})
    {
        MultiresMesh mesh = original;
        (void)apply_lattice(mesh, lattice, 1, mode);
        EXPECT_LE(test::largest_difference(mesh, original), 1e-12 * test::diagonal(original));
    }
}

TEST(Lattice, AffineControlPointsGiveTheAffineMap)
{
    const MultiresMesh original = test::relief_plate(3);
    const auto [lo, hi] = box_around(original);
    Lattice lattice = rest_lattice(lo, hi, {2, 3, 2});
    const Eigen::Matrix4d rigid = test::rigid_motion();
    Eigen::Matrix3d linear = rigid.topLeftCorner<3, 3>();
    linear(0, 1) += 0.3; // a shear: affine, not rigid
    const Vec3d shift = rigid.topRightCorner<3, 1>();
    for (Vec3d& p : lattice.control_points)
        p = linear * p + shift;
    MultiresMesh mesh = original;
    (void)apply_lattice(mesh, lattice, 0, LatticeMode::Plain);
    double worst = 0.0;
    for (std::uint32_t v = 0; v < original.vertex_count(); ++v)
        worst = std::max(worst, (mesh.world(v) - (linear * original.world(v) + shift)).norm());
    EXPECT_LE(worst, 1e-12 * test::diagonal(original));
    EXPECT_EQ(evaluate_lattice(lattice, hi + Vec3d::Ones()), hi + Vec3d::Ones()); // outside

    // A rigid lattice with the details riding along: the same rigid motion at every level.
    Lattice moved = rest_lattice(lo, hi, {2, 3, 2});
    for (Vec3d& p : moved.control_points)
        p = rigid.topLeftCorner<3, 3>() * p + shift;
    MultiresMesh riding = original;
    (void)apply_lattice(riding, moved, 1, LatticeMode::Details);
    worst = 0.0;
    for (std::uint32_t v = 0; v < original.vertex_count(); ++v)
        worst = std::max(
            worst,
            (riding.world(v) - (rigid.topLeftCorner<3, 3>() * original.world(v) + shift)).norm());
    EXPECT_LE(worst, 1e-9 * test::diagonal(original));
}

TEST(Lattice, DetailsModeBendsTheReliefInsteadOfShearingIt)
{
    // Bend the plate: lift the lattice's middle plane of control points. With the details riding
    // along, the relief keeps its height along the bent normal; plain FFD changes it.
    const MultiresMesh original = test::relief_plate(3);
    const auto [lo, hi] = box_around(original);
    Lattice lattice = rest_lattice(lo, hi, {2, 1, 1});
    for (std::size_t k = 0; k <= 1; ++k)
        for (std::size_t j = 0; j <= 1; ++j)
            lattice.control_points[lattice.index(1, j, k)].z() += 0.8;
    MultiresMesh riding = original;
    MultiresMesh plain = original;
    (void)apply_lattice(riding, lattice, 0, LatticeMode::Details);
    (void)apply_lattice(plain, lattice, 0, LatticeMode::Plain);
    const MultiresDetails before = analyze_details(original);
    const MultiresDetails kept = analyze_details(riding);
    const MultiresDetails sheared = analyze_details(plain);
    double kept_error = 0.0;
    double plain_error = 0.0;
    for (std::size_t k = 0; k < before.coefficients.size(); ++k)
    {
        kept_error = std::max(kept_error, (kept.coefficients[k] - before.coefficients[k]).norm());
        plain_error =
            std::max(plain_error, (sheared.coefficients[k] - before.coefficients[k]).norm());
    }
    EXPECT_LE(kept_error, 1e-12 * test::diagonal(original));
    EXPECT_GT(plain_error, 1e-3);
    EXPECT_NO_THROW(riding.validate());
}

TEST(Lattice, BadLatticesAreRefused)
{
    MultiresMesh mesh = test::relief_sphere(1);
    const MultiresMesh original = mesh;
    Lattice lattice = rest_lattice(Vec3d::Constant(-2), Vec3d::Constant(2), {2, 2, 2});
    EXPECT_THROW((void)apply_lattice(mesh, lattice, 2), InvalidInput); // no level 2
    Lattice short_of_one = lattice;
    short_of_one.control_points.pop_back();
    EXPECT_THROW((void)apply_lattice(mesh, short_of_one, 0), InvalidInput);
    Lattice nan = lattice;
    nan.control_points[4].y() = std::nan("");
    EXPECT_THROW((void)apply_lattice(mesh, nan, 0), InvalidInput);
    EXPECT_THROW((void)rest_lattice(Vec3d::Zero(), Vec3d::Zero(), {1, 1, 1}), InvalidInput);
    EXPECT_THROW((void)rest_lattice(Vec3d::Zero(), Vec3d::Ones(), {0, 1, 1}), InvalidInput);
    EXPECT_THROW((void)rest_lattice(Vec3d::Zero(), Vec3d::Ones(), {25, 1, 1}), InvalidInput);
    EXPECT_THROW((void)rest_lattice(Vec3d::Zero(), Vec3d::Ones(), {24, 24, 24}), InvalidInput);
    EXPECT_TRUE(
        std::equal(mesh.positions().begin(), mesh.positions().end(), original.positions().begin()));
}

TEST(Lattice, SameBytesAtEveryThreadCount)
{
    const MultiresMesh original = test::relief_sphere(4);
    const auto [lo, hi] = box_around(original);
    Lattice lattice = rest_lattice(lo, hi, {3, 3, 3});
    for (std::size_t i = 0; i < lattice.control_points.size(); ++i)
        lattice.control_points[i] +=
            0.05 * Vec3d(std::sin(double(i)), std::cos(3.0 * double(i)), 0.5);
    const auto runs = test::at_thread_counts([&] {
        MultiresMesh mesh = original;
        (void)apply_lattice(mesh, lattice, 3, LatticeMode::Details);
        (void)apply_lattice(mesh, lattice, 0, LatticeMode::Plain);
        return std::vector<Vec3d>(mesh.positions().begin(), mesh.positions().end());
    });
    for (std::size_t i = 1; i < runs.size(); ++i)
        EXPECT_TRUE(runs[i] == runs[0]) << "run " << i;
}

} // namespace
} // namespace pointform
