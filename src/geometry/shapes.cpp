// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/geometry/shapes.h"

#include "pointform/core/error.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

namespace pointform {
namespace {

constexpr double torus_major = 1.0;
constexpr double torus_minor = 0.35;
constexpr double spheres_offset = 1.6;

struct Sample
{
    Vec3d position;
    Vec3d normal;
};

Vec3d random_unit(std::mt19937_64& rng)
{
    std::normal_distribution<double> gauss;
    for (;;)
    {
        Vec3d v(gauss(rng), gauss(rng), gauss(rng));
        const double n = v.norm();
        if (n > 1e-12)
            return v / n;
    }
}

Sample sample_torus(std::mt19937_64& rng)
{
    std::uniform_real_distribution<double> uni(0.0, 1.0);
    // Area element is proportional to (R + r cos v): rejection-sample v.
    for (;;)
    {
        const double u = 2.0 * std::numbers::pi * uni(rng);
        const double v = 2.0 * std::numbers::pi * uni(rng);
        const double w = (torus_major + torus_minor * std::cos(v)) / (torus_major + torus_minor);
        if (uni(rng) > w)
            continue;
        const Vec3d n(std::cos(v) * std::cos(u), std::cos(v) * std::sin(u), std::sin(v));
        const Vec3d c(torus_major * std::cos(u), torus_major * std::sin(u), 0.0);
        return {c + torus_minor * n, n};
    }
}

Sample sample_plate(std::mt19937_64& rng, double thickness)
{
    std::uniform_real_distribution<double> uni(0.0, 1.0);
    const Vec3d half(1.0, 1.0, 0.5 * thickness);
    // Face areas: two of 2×2 (z), four of 2×t (x and y).
    const double area_z = 4.0;
    const double area_side = 2.0 * thickness;
    const double total = 2.0 * area_z + 4.0 * area_side;
    const double pick = uni(rng) * total;
    int axis = 2;
    double sign = 1.0;
    if (pick < 2.0 * area_z)
        sign = pick < area_z ? 1.0 : -1.0;
    else
    {
        const double rest = pick - 2.0 * area_z;
        const int face = std::min(3, static_cast<int>(rest / area_side));
        axis = face / 2;
        sign = face % 2 == 0 ? 1.0 : -1.0;
    }
    Vec3d p(half.x() * (2.0 * uni(rng) - 1.0), half.y() * (2.0 * uni(rng) - 1.0),
            half.z() * (2.0 * uni(rng) - 1.0));
    p[axis] = sign * half[axis];
    Vec3d n = Vec3d::Zero();
    n[axis] = sign;
    return {p, n};
}

Sample sample_one(Shape shape, std::mt19937_64& rng, const SampleOptions& options)
{
    switch (shape)
    {
        case Shape::Sphere:
        {
            const Vec3d n = random_unit(rng);
            return {n, n};
        }
        case Shape::Torus:
            return sample_torus(rng);
        case Shape::TwoSpheres:
        {
            const Vec3d n = random_unit(rng);
            const double side = std::uniform_int_distribution<int>(0, 1)(rng) == 0 ? -1.0 : 1.0;
            return {n + Vec3d(side * spheres_offset, 0.0, 0.0), n};
        }
        case Shape::Plate:
            return sample_plate(rng, options.thickness);
    }
    throw InvalidInput("unknown shape");
}

} // namespace

PointCloud sample_shape(Shape shape, const SampleOptions& options)
{
    if (options.count == 0)
        throw InvalidInput("sample_shape: count must be positive");
    if (!(options.noise >= 0.0) || !(options.hole_radius >= 0.0) || !(options.thickness > 0.0))
        throw InvalidInput(
            "sample_shape: noise, hole radius and thickness must be non-negative "
            "(thickness positive)");

    std::mt19937_64 rng(options.seed);
    std::vector<Sample> samples;
    samples.reserve(options.count);
    for (std::size_t i = 0; i < options.count; ++i)
        samples.push_back(sample_one(shape, rng, options));

    Aabb box;
    for (const auto& s : samples)
        box.extend(s.position);
    const double diagonal = box.diagonal();

    std::vector<Vec3d> hole_centers;
    for (std::size_t h = 0; h < options.holes; ++h)
    {
        const auto pick = std::uniform_int_distribution<std::size_t>(0, samples.size() - 1)(rng);
        hole_centers.push_back(samples[pick].position);
    }
    const double hole_r2 = std::pow(options.hole_radius * diagonal, 2);

    std::normal_distribution<double> gauss(0.0, options.noise * diagonal);
    PointCloud cloud;
    cloud.positions.reserve(samples.size());
    cloud.normals.reserve(samples.size());
    for (const auto& s : samples)
    {
        bool in_hole = false;
        for (const auto& c : hole_centers)
            in_hole = in_hole || (s.position - c).squaredNorm() < hole_r2;
        Vec3d p = s.position;
        if (options.noise > 0.0)
            p += Vec3d(gauss(rng), gauss(rng), gauss(rng));
        if (in_hole)
            continue;
        cloud.positions.emplace_back(p.cast<float>());
        cloud.normals.emplace_back(s.normal.cast<float>());
    }
    return cloud;
}

Shape parse_shape(const std::string& name)
{
    if (name == "sphere")
        return Shape::Sphere;
    if (name == "torus")
        return Shape::Torus;
    if (name == "two-spheres")
        return Shape::TwoSpheres;
    if (name == "plate")
        return Shape::Plate;
    throw InvalidInput("unknown shape '" + name +
                       "' (expected sphere, torus, two-spheres or plate)");
}

} // namespace pointform
