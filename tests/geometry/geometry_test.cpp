// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/core/error.h"
#include "pointform/geometry/point_cloud.h"
#include "pointform/geometry/shapes.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace pointform {
namespace {

TEST(Aabb, ExtendContainsAndDiagonal)
{
    Aabb box;
    EXPECT_TRUE(box.is_empty());
    EXPECT_EQ(box.diagonal(), 0.0);
    box.extend(Vec3d(1, 2, 3));
    box.extend(Vec3d(4, 6, 3));
    EXPECT_FALSE(box.is_empty());
    EXPECT_DOUBLE_EQ(box.diagonal(), 5.0);
    EXPECT_TRUE(box.contains(Vec3d(2, 3, 3)));
    EXPECT_FALSE(box.contains(Vec3d(2, 3, 3.5)));
    EXPECT_EQ(box.center(), Vec3d(2.5, 4, 3));
}

TEST(PointCloud, OriginKeepsGeoreferencedPrecision)
{
    // UTM-like coordinates with millimetre detail: float alone would keep about 0.25 m.
    const Vec3d first(512345.678, 4212345.123, 310.456);
    const Vec3d origin = choose_origin(first);
    EXPECT_EQ(origin, Vec3d(512346, 4212345, 310));
    PointCloud cloud;
    cloud.origin = origin;
    cloud.positions.push_back((first - origin).cast<float>());
    EXPECT_LT((cloud.world(0) - first).norm(), 1e-6);
    EXPECT_EQ(choose_origin(Vec3d(0.12, -0.3, 0.49)), Vec3d::Zero());

    const Aabb box = cloud.bounds();
    EXPECT_LT((box.min - first).norm(), 1e-6);
}

TEST(PointCloud, ValidateRejectsMismatchedAttributes)
{
    PointCloud cloud;
    cloud.positions.assign(3, Vec3f::Zero());
    EXPECT_NO_THROW(validate(cloud));
    cloud.normals.assign(2, Vec3f::UnitZ());
    EXPECT_THROW(validate(cloud), InvalidInput);
    cloud.normals.assign(3, Vec3f::UnitZ());
    cloud.radii.assign(4, 1.0F);
    EXPECT_THROW(validate(cloud), InvalidInput);
}

/// Distance from a point to each analytic surface, to check samples lie on it.
double surface_distance(Shape shape, const Vec3d& p, double thickness)
{
    switch (shape)
    {
        case Shape::Sphere:
            return std::abs(p.norm() - 1.0);
        case Shape::Torus:
            return std::abs(std::hypot(std::hypot(p.x(), p.y()) - 1.0, p.z()) - 0.35);
        case Shape::TwoSpheres:
            return std::abs((p - Vec3d(p.x() > 0 ? 1.6 : -1.6, 0, 0)).norm() - 1.0);
        case Shape::Plate:
        {
            const Vec3d half(1.0, 1.0, 0.5 * thickness);
            const Vec3d q = p.cwiseAbs() - half;
            return std::abs(q.maxCoeff());
        }
        case Shape::Blobby:
        case Shape::Part:
        case Shape::Cone:
            break;
    }
    return 1e9;
}

/// Exact signed distance of a box or capped z-cylinder of Shape::Part (negative inside).
double primitive_distance(const PartPrimitive& q, const Vec3d& p)
{
    Eigen::Vector2d d;
    if (q.kind == PartPrimitive::Kind::Box)
    {
        const Vec3d c = 0.5 * (q.min + q.max);
        const Vec3d e = (p - c).cwiseAbs() - 0.5 * (q.max - q.min);
        return e.cwiseMax(0.0).norm() + std::min(e.maxCoeff(), 0.0);
    }
    d.x() = std::hypot(p.x() - q.min.x(), p.y() - q.min.y()) - q.max.x();
    d.y() = std::abs(p.z() - 0.5 * (q.min.z() + q.max.z())) - 0.5 * (q.max.z() - q.min.z());
    return d.cwiseMax(0.0).norm() + std::min(d.maxCoeff(), 0.0);
}

/// A signed function of the Blobby and Part solids, zero exactly on their surface, negative
/// inside (min and max of exact signed distances: a bound away from the surface).
double solid_value(Shape shape, const Vec3d& p)
{
    double value = 1e9;
    if (shape == Shape::Blobby)
    {
        for (const Ball& b : blobby_spheres())
            value = std::min(value, (p - b.center).norm() - b.radius);
        return value;
    }
    const PartSolid& solid = part_solid();
    for (const PartPrimitive& q : solid.added)
        value = std::min(value, primitive_distance(q, p));
    for (const PartPrimitive& q : solid.removed)
        value = std::max(value, -primitive_distance(q, p));
    return value;
}

TEST(PointCloud, KeepPointsKeepsEveryAttributeInOrder)
{
    PointCloud cloud;
    for (int i = 0; i < 5; ++i)
    {
        const auto f = static_cast<float>(i);
        cloud.positions.emplace_back(f, 0.0F, 0.0F);
        cloud.normals.emplace_back(0.0F, f, 0.0F);
        cloud.colors.push_back({static_cast<std::uint8_t>(i), 0, 0});
    }
    const std::vector<std::uint8_t> keep = {0, 1, 0, 1, 1};
    EXPECT_EQ(keep_points(cloud, keep), 2U);
    ASSERT_EQ(cloud.size(), 3U);
    EXPECT_TRUE(cloud.radii.empty()); // absent attributes stay absent
    const int kept[] = {1, 3, 4};
    for (std::size_t i = 0; i < 3; ++i)
    {
        EXPECT_EQ(cloud.positions[i].x(), static_cast<float>(kept[i]));
        EXPECT_EQ(cloud.normals[i].y(), static_cast<float>(kept[i]));
        EXPECT_EQ(cloud.colors[i].r, kept[i]);
    }
    validate(cloud);
}

TEST(PointCloud, ReorderPointsMovesEveryAttribute)
{
    PointCloud cloud;
    for (int i = 0; i < 4; ++i)
    {
        const auto f = static_cast<float>(i);
        cloud.positions.emplace_back(f, 0.0F, 0.0F);
        cloud.radii.push_back(10.0F + f);
        cloud.colors.push_back({static_cast<std::uint8_t>(i), 0, 0});
    }
    const std::vector<std::uint32_t> order = {2, 0, 3, 1};
    reorder_points(cloud, order);
    ASSERT_EQ(cloud.size(), 4U);
    EXPECT_TRUE(cloud.normals.empty()); // absent attributes stay absent
    for (std::size_t j = 0; j < 4; ++j)
    {
        EXPECT_EQ(cloud.positions[j].x(), static_cast<float>(order[j]));
        EXPECT_EQ(cloud.radii[j], 10.0F + static_cast<float>(order[j]));
        EXPECT_EQ(cloud.colors[j].r, order[j]);
    }
    validate(cloud);
}

TEST(Shapes, BlobbyAndPartSamplesLieOnTheSolidsSurfaceWithOutwardNormals)
{
    for (const Shape shape : {Shape::Blobby, Shape::Part})
    {
        const PointCloud cloud = sample_shape(shape, {.count = 20000, .seed = 3});
        ASSERT_EQ(cloud.size(), 20000U);
        std::size_t outward = 0;
        for (std::size_t i = 0; i < cloud.size(); ++i)
        {
            const Vec3d p = cloud.positions[i].cast<double>();
            const Vec3d n = cloud.normals[i].cast<double>();
            ASSERT_LT(std::abs(solid_value(shape, p)), 1e-6);
            EXPECT_NEAR(n.norm(), 1.0, 1e-6);
            // A small step along the normal leaves the solid and one against it enters it
            // (but for samples within the step of a crease).
            outward +=
                solid_value(shape, p + 1e-3 * n) > 0.0 && solid_value(shape, p - 1e-3 * n) < 0.0
                    ? 1
                    : 0;
        }
        EXPECT_GT(static_cast<double>(outward), 0.995 * static_cast<double>(cloud.size()));
    }
}

TEST(Shapes, PartSamplingIsAreaUniform)
{
    // The part's top face, z = 0.3, is the block's top (2 × 1.2) less the boss's and the hole's
    // discs; its share of the samples is its share of the whole area, computed piece by piece.
    const double pi = std::numbers::pi;
    const double block = 2.0 * (2.0 * 1.2 + 1.2 * 0.6 + 0.6 * 2.0);
    const double boss_r = 0.35;
    const double hole_r = 0.25;
    const double top = 2.0 * 1.2 - pi * boss_r * boss_r - pi * hole_r * hole_r;
    const double total = block - pi * boss_r * boss_r - 2.0 * pi * hole_r * hole_r // faces cut
                         + 2.0 * pi * boss_r * 0.4 + pi * boss_r * boss_r          // boss
                         + 2.0 * pi * hole_r * 0.6;                                // hole wall
    const PointCloud part = sample_shape(Shape::Part, {.count = 200000, .seed = 4});
    std::size_t on_top = 0;
    for (std::size_t i = 0; i < part.size(); ++i)
        on_top += std::abs(part.positions[i].z() - 0.3F) < 1e-6F && part.normals[i].z() > 0.5F;
    EXPECT_NEAR(static_cast<double>(on_top) / static_cast<double>(part.size()), top / total, 0.004);
}

TEST(Shapes, SamplesLieOnTheSurfaceWithUnitOutwardNormals)
{
    for (const Shape shape : {Shape::Sphere, Shape::Torus, Shape::TwoSpheres, Shape::Plate})
    {
        const PointCloud cloud = sample_shape(shape, {.count = 5000, .seed = 3});
        ASSERT_EQ(cloud.size(), 5000U);
        ASSERT_EQ(cloud.normals.size(), 5000U);
        for (std::size_t i = 0; i < cloud.size(); ++i)
        {
            const Vec3d p = cloud.positions[i].cast<double>();
            EXPECT_LT(surface_distance(shape, p, 0.05), 1e-5);
            EXPECT_NEAR(cloud.normals[i].norm(), 1.0F, 1e-5F);
            // Outward: a small step along the normal moves away from the surface's inside.
            const Vec3d out = p + 1e-3 * cloud.normals[i].cast<double>();
            EXPECT_NEAR(surface_distance(shape, out, 0.05), 1e-3, 1e-4);
        }
    }
}

// Strays follow the samples: as many as the fraction asks, spread through the box grown by 30%
// (some within it, some past it on every side), with unit normals; the samples before them are
// the same as without them. A fraction outside 0-1 is refused.
TEST(Shapes, StraysFollowTheSamplesThroughTheGrownBox)
{
    const PointCloud plain = sample_shape(Shape::Sphere, {.count = 5000, .seed = 3});
    const PointCloud cloud = sample_shape(Shape::Sphere, {.count = 5000, .seed = 3, .strays = 0.1});
    ASSERT_EQ(cloud.size(), 5500U);
    ASSERT_EQ(cloud.normals.size(), 5500U);
    for (std::size_t i = 0; i < 5000; ++i)
        ASSERT_EQ(cloud.positions[i], plain.positions[i]) << i;
    std::size_t past = 0;
    std::size_t off = 0;
    for (std::size_t i = 5000; i < cloud.size(); ++i)
    {
        const Vec3f p = cloud.positions[i];
        EXPECT_LE(p.cwiseAbs().maxCoeff(), 1.3F + 1e-4F);
        past += p.cwiseAbs().maxCoeff() > 1.0F ? 1 : 0;
        off += std::abs(p.norm() - 1.0F) > 0.05F ? 1 : 0;
        EXPECT_NEAR(cloud.normals[i].norm(), 1.0F, 1e-5F);
    }
    EXPECT_GT(past, 200U); // 1 - (1/1.3)^3 of them, 272 on average
    EXPECT_GT(off, 400U);
    EXPECT_THROW((void)sample_shape(Shape::Sphere, {.strays = 1.5}), InvalidInput);
    EXPECT_THROW((void)sample_shape(Shape::Sphere, {.strays = -0.1}), InvalidInput);
}

/// The cone's signed distance bound: max(−z, (r + z − 1)/√2), zero on its surface, negative
/// inside, the exact distance off a face (away from the rim and the apex).
double cone_value(const Vec3d& p)
{
    return std::max(-p.z(), (std::hypot(p.x(), p.y()) + p.z() - 1.0) / std::sqrt(2.0));
}

TEST(Shapes, ConeSamplesLieOnItsSurfaceWithOutwardNormalsAndUniformArea)
{
    const PointCloud cone = sample_shape(Shape::Cone, {.count = 100000, .seed = 5});
    ASSERT_EQ(cone.size(), 100000U);
    std::size_t outward = 0;
    std::size_t base = 0;
    for (std::size_t i = 0; i < cone.size(); ++i)
    {
        const Vec3d p = cone.positions[i].cast<double>();
        const Vec3d n = cone.normals[i].cast<double>();
        ASSERT_LT(std::abs(cone_value(p)), 1e-6);
        ASSERT_GE(p.z(), -1e-7);
        EXPECT_NEAR(n.norm(), 1.0, 1e-6);
        outward += cone_value(p + 1e-3 * n) > 0.0 && cone_value(p - 1e-3 * n) < 0.0 ? 1 : 0;
        base += p.z() == 0.0 ? 1 : 0;
    }
    EXPECT_GT(static_cast<double>(outward), 0.995 * static_cast<double>(cone.size()));
    // The base's share of the area: π / (π + π√2).
    EXPECT_NEAR(static_cast<double>(base) / static_cast<double>(cone.size()),
                1.0 / (1.0 + std::sqrt(2.0)), 0.005);
    EXPECT_EQ(parse_shape("cone"), Shape::Cone);
}

TEST(Shapes, TorusSamplingIsAreaUniform)
{
    // The outer half of the tube (cos v > 0, farther than R from the axis) holds the area share
    // ∫ (R + r cos v) dv over cos v > 0 / ∫ (R + r cos v) dv = 1/2 + r/(πR).
    const PointCloud torus = sample_shape(Shape::Torus, {.count = 200000, .seed = 4});
    std::size_t outer_half = 0;
    for (std::size_t i = 0; i < torus.size(); ++i)
    {
        const Vec3f& p = torus.positions[i];
        if (std::hypot(p.x(), p.y()) > 1.0F)
            ++outer_half;
    }
    const double expected = 0.5 + 0.35 / M_PI;
    EXPECT_NEAR(static_cast<double>(outer_half) / static_cast<double>(torus.size()), expected,
                0.005);
}

TEST(Shapes, NoiseAndHolesAreDeterministic)
{
    const SampleOptions options{.count = 20000, .seed = 9, .noise = 0.01, .holes = 5};
    const PointCloud a = sample_shape(Shape::Sphere, options);
    const PointCloud b = sample_shape(Shape::Sphere, options);
    EXPECT_EQ(a.positions, b.positions);
    EXPECT_LT(a.size(), 20000U);
    double mean_offset = 0.0;
    for (const auto& p : a.positions)
        mean_offset += std::abs(p.cast<double>().norm() - 1.0);
    mean_offset /= static_cast<double>(a.size());
    // |N(0, σ)| along the normal has mean σ√(2/π); σ = 0.01 × diagonal (2√3).
    EXPECT_NEAR(mean_offset, 0.01 * 2.0 * std::sqrt(3.0) * std::sqrt(2.0 / M_PI), 0.005);

    EXPECT_THROW((void)sample_shape(Shape::Sphere, {.count = 0}), InvalidInput);
    EXPECT_THROW((void)sample_shape(Shape::Sphere, {.noise = -1.0}), InvalidInput);
    EXPECT_THROW((void)parse_shape("cube"), InvalidInput);
}

} // namespace
} // namespace pointform
