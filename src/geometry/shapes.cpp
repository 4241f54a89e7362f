// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/geometry/shapes.h"

#include "pointform/core/error.h"

#include <algorithm>
#include <array>
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

// A large ball with five smaller ones sunk into it: five concave creases where the normals turn
// by 82° to 95°, the small balls at least 0.12 apart from each other.
const std::array<Ball, 6> blobby = {{
    {Vec3d(0.0, 0.0, 0.0), 0.8},
    {Vec3d(0.95, 0.1, 0.0), 0.5},
    {Vec3d(-0.8, 0.45, 0.15), 0.55},
    {Vec3d(0.1, 0.9, -0.35), 0.45},
    {Vec3d(0.05, -0.35, 0.9), 0.45},
    {Vec3d(-0.35, -0.85, -0.3), 0.5},
}};

bool inside_ball(const Ball& b, const Vec3d& p)
{
    return (p - b.center).squaredNorm() < b.radius * b.radius;
}

/// Area-uniform sample of the union of balls: a ball picked by area, a point on it, kept unless
/// it lies inside another ball.
Sample sample_blobby(std::mt19937_64& rng)
{
    double total = 0.0;
    for (const Ball& b : blobby)
        total += b.radius * b.radius;
    std::uniform_real_distribution<double> uni(0.0, total);
    for (;;)
    {
        double pick = uni(rng);
        std::size_t i = 0;
        while (i + 1 < blobby.size() && pick >= blobby[i].radius * blobby[i].radius)
        {
            pick -= blobby[i].radius * blobby[i].radius;
            ++i;
        }
        const Vec3d n = random_unit(rng);
        const Vec3d p = blobby[i].center + blobby[i].radius * n;
        bool covered = false;
        for (std::size_t j = 0; j < blobby.size() && !covered; ++j)
            covered = j != i && inside_ball(blobby[j], p);
        if (!covered)
            return {p, n};
    }
}

PartSolid make_part()
{
    using Kind = PartPrimitive::Kind;
    PartSolid solid;
    solid.added.push_back({Kind::Box, Vec3d(-1.0, -0.6, -0.3), Vec3d(1.0, 0.6, 0.3)});
    // A boss of radius 0.35 rising 0.4 above the top face (its foot inside the block).
    solid.added.push_back({Kind::Cylinder, Vec3d(0.5, 0.0, 0.1), Vec3d(0.35, 0.0, 0.7)});
    // A hole of radius 0.25 through the block.
    solid.removed.push_back({Kind::Cylinder, Vec3d(-0.5, 0.0, -1.0), Vec3d(0.25, 0.0, 1.0)});
    return solid;
}

bool inside_primitive(const PartPrimitive& q, const Vec3d& p)
{
    if (q.kind == PartPrimitive::Kind::Box)
        return (p.array() > q.min.array()).all() && (p.array() < q.max.array()).all();
    const double dx = p.x() - q.min.x();
    const double dy = p.y() - q.min.y();
    return p.z() > q.min.z() && p.z() < q.max.z() && dx * dx + dy * dy < q.max.x() * q.max.x();
}

double primitive_area(const PartPrimitive& q)
{
    if (q.kind == PartPrimitive::Kind::Box)
    {
        const Vec3d e = q.max - q.min;
        return 2.0 * (e.x() * e.y() + e.y() * e.z() + e.z() * e.x());
    }
    const double r = q.max.x();
    return 2.0 * std::numbers::pi * r * (q.max.z() - q.min.z()) + 2.0 * std::numbers::pi * r * r;
}

Sample sample_primitive(const PartPrimitive& q, std::mt19937_64& rng)
{
    std::uniform_real_distribution<double> uni(0.0, 1.0);
    if (q.kind == PartPrimitive::Kind::Box)
    {
        const Vec3d e = q.max - q.min;
        const double areas[3] = {e.y() * e.z(), e.z() * e.x(), e.x() * e.y()};
        double pick = uni(rng) * 2.0 * (areas[0] + areas[1] + areas[2]);
        int axis = 0;
        while (axis < 2 && pick >= 2.0 * areas[axis])
        {
            pick -= 2.0 * areas[axis];
            ++axis;
        }
        const bool upper = pick >= areas[axis];
        Vec3d p(q.min.x() + e.x() * uni(rng), q.min.y() + e.y() * uni(rng),
                q.min.z() + e.z() * uni(rng));
        p[axis] = upper ? q.max[axis] : q.min[axis];
        Vec3d n = Vec3d::Zero();
        n[axis] = upper ? 1.0 : -1.0;
        return {p, n};
    }
    const double r = q.max.x();
    const double height = q.max.z() - q.min.z();
    const double side = 2.0 * std::numbers::pi * r * height;
    const double cap = std::numbers::pi * r * r;
    const double pick = uni(rng) * (side + 2.0 * cap);
    if (pick < side)
    {
        const double a = 2.0 * std::numbers::pi * uni(rng);
        const Vec3d n(std::cos(a), std::sin(a), 0.0);
        return {Vec3d(q.min.x() + r * n.x(), q.min.y() + r * n.y(), q.min.z() + height * uni(rng)),
                n};
    }
    const bool top = pick >= side + cap;
    const double a = 2.0 * std::numbers::pi * uni(rng);
    const double rho = r * std::sqrt(uni(rng));
    return {Vec3d(q.min.x() + rho * std::cos(a), q.min.y() + rho * std::sin(a),
                  top ? q.max.z() : q.min.z()),
            Vec3d(0.0, 0.0, top ? 1.0 : -1.0)};
}

/// Area-uniform sample of the part's surface: a primitive picked by area, a point on it, kept
/// where it bounds the solid (an added primitive's point outside every other primitive; a
/// removed one's inside an added one and outside the other removed ones, its normal reversed).
Sample sample_part(std::mt19937_64& rng)
{
    const PartSolid& solid = part_solid();
    std::vector<const PartPrimitive*> all;
    double total = 0.0;
    for (const auto& q : solid.added)
    {
        all.push_back(&q);
        total += primitive_area(q);
    }
    for (const auto& q : solid.removed)
    {
        all.push_back(&q);
        total += primitive_area(q);
    }
    std::uniform_real_distribution<double> uni(0.0, total);
    for (;;)
    {
        double pick = uni(rng);
        std::size_t i = 0;
        while (i + 1 < all.size() && pick >= primitive_area(*all[i]))
        {
            pick -= primitive_area(*all[i]);
            ++i;
        }
        Sample s = sample_primitive(*all[i], rng);
        const bool removed = i >= solid.added.size();
        bool keep = true;
        bool in_added = false;
        for (std::size_t j = 0; j < solid.added.size(); ++j)
            if (j != i && inside_primitive(solid.added[j], s.position))
                in_added = true;
        for (std::size_t j = 0; j < solid.removed.size(); ++j)
            if (j + solid.added.size() != i && inside_primitive(solid.removed[j], s.position))
                keep = false;
        keep = keep && (removed ? in_added : !in_added);
        if (!keep)
            continue;
        if (removed)
            s.normal = -s.normal;
        return s;
    }
}

/// Area-uniform sample of Shape::Cone: the side (area π√2) or the base (area π) picked by area,
/// the distance from the apex or the centre as √u of the radius.
Sample sample_cone(std::mt19937_64& rng)
{
    std::uniform_real_distribution<double> uni(0.0, 1.0);
    const double slant = std::sqrt(2.0);
    const double pick = uni(rng) * (slant + 1.0);
    const double t = std::sqrt(uni(rng));
    const double angle = 2.0 * std::numbers::pi * uni(rng);
    const double c = std::cos(angle);
    const double s = std::sin(angle);
    if (pick < slant)
        return {Vec3d(t * c, t * s, 1.0 - t), Vec3d(c, s, 1.0) / slant};
    return {Vec3d(t * c, t * s, 0.0), Vec3d(0.0, 0.0, -1.0)};
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
        case Shape::Blobby:
            return sample_blobby(rng);
        case Shape::Part:
            return sample_part(rng);
        case Shape::Cone:
            return sample_cone(rng);
    }
    throw InvalidInput("unknown shape");
}

} // namespace

std::span<const Ball> blobby_spheres()
{
    return blobby;
}

const PartSolid& part_solid()
{
    static const PartSolid solid = make_part();
    return solid;
}

PointCloud sample_shape(Shape shape, const SampleOptions& options)
{
    if (options.count == 0)
        throw InvalidInput("sample_shape: count must be positive");
    if (!(options.noise >= 0.0) || !(options.hole_radius >= 0.0) || !(options.thickness > 0.0) ||
        !(options.strays >= 0.0) || !(options.strays <= 1.0))
        throw InvalidInput(
            "sample_shape: noise, hole radius and thickness must be non-negative "
            "(thickness positive), strays a fraction from 0 to 1");

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
    const auto strays =
        static_cast<std::size_t>(std::llround(options.strays * static_cast<double>(options.count)));
    const Vec3d centre = box.center();
    const Vec3d half = 0.65 * (box.max - box.min);
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    for (std::size_t i = 0; i < strays; ++i)
    {
        const Vec3d offset(half.x() * unit(rng), half.y() * unit(rng), half.z() * unit(rng));
        cloud.positions.emplace_back((centre + offset).cast<float>());
        const double length = offset.norm();
        cloud.normals.emplace_back(length > 0.0 ? Vec3f((offset / length).cast<float>())
                                                : Vec3f(Vec3f::UnitZ()));
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
    if (name == "blobby")
        return Shape::Blobby;
    if (name == "part")
        return Shape::Part;
    if (name == "cone")
        return Shape::Cone;
    throw InvalidInput("unknown shape '" + name +
                       "' (expected sphere, torus, two-spheres, plate, blobby, part or cone)");
}

} // namespace pointform
