// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include "pointform/geometry/point_cloud.h"

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace pointform {

/// \brief Analytic shapes that can be sampled with their exact outward normals, for tests,
/// benchmarks and demos.
enum class Shape
{
    Sphere,     ///< radius 1 centred at 0
    Torus,      ///< major radius 1, minor radius 0.35, axis z
    TwoSpheres, ///< two disjoint unit spheres centred at (±1.6, 0, 0)
    Plate,      ///< closed thin box 2 × 2 × thickness, centred at 0
    /// The union of six overlapping spheres (a "blobby" shape): smooth parts meeting along
    /// concave creases, where sharp features test a reconstruction (blobby_spheres()).
    Blobby,
    /// A machined part: a block 2 × 1.2 × 0.6 with a cylindrical boss on top and a round hole
    /// through it: flat faces, convex and concave 90° creases and a genus-1 surface (part_solid()).
    Part,
    /// A closed cone as wide as it is high: a base disc of radius 1 at z = 0 and the apex at
    /// z = 1. Its rim is a crease sharper than a right angle (the base meets the side at 45°, the
    /// normals turn by 135°) and its apex a point: features that estimated normals blend the
    /// short way round and that test orientation and the field.
    Cone,
};

/// \brief A ball of the Blobby shape.
struct Ball
{
    Vec3d center;
    double radius = 0.0;
};

/// \brief The six balls whose union is Shape::Blobby.
[[nodiscard]] std::span<const Ball> blobby_spheres();

/// \brief Shape::Part as constructive solid geometry: the union of `added` minus the union of
/// `removed`, each an axis-aligned box or a capped cylinder along z.
struct PartPrimitive
{
    enum class Kind
    {
        Box,      ///< [min, max]
        Cylinder, ///< axis along z through (min.x, min.y), radius max.x, z in [min.z, max.z]
    };
    Kind kind = Kind::Box;
    Vec3d min = Vec3d::Zero();
    Vec3d max = Vec3d::Zero();
};
struct PartSolid
{
    std::vector<PartPrimitive> added;
    std::vector<PartPrimitive> removed;
};
[[nodiscard]] const PartSolid& part_solid();

/// \brief Options for sample_shape.
struct SampleOptions
{
    /// Number of samples before holes are cut.
    std::size_t count = 100000;
    /// Seed of the pseudo-random generator; the same seed gives the same samples.
    std::uint64_t seed = 1;
    /// Standard deviation of isotropic Gaussian position noise, as a fraction of the bounding
    /// box diagonal (0.002 = 0.2%). Normals stay those of the noiseless surface. 0 = clean.
    double noise = 0.0;
    /// Number of holes: balls around random samples whose points are removed. 0 = none.
    std::size_t holes = 0;
    /// Radius of each hole as a fraction of the bounding-box diagonal.
    double hole_radius = 0.05;
    /// Plate only: thickness of the plate (its side is 2).
    double thickness = 0.05;
    /// Stray points added, as a fraction of `count`: spread evenly through the samples'
    /// bounding box grown by 30% about its centre (inside the shape, near it and away from it,
    /// as a scanner's stray returns), after the samples. They have no surface: their normals
    /// point away from the box's centre. 0 = none.
    double strays = 0.0;
};

/// \brief Samples a shape area-uniformly and returns positions with exact outward unit normals.
/// \throw InvalidInput for count == 0 or negative noise, hole radius or thickness.
[[nodiscard]] PointCloud sample_shape(Shape shape, const SampleOptions& options = {});

/// \brief Parses "sphere", "torus", "two-spheres", "plate", "blobby", "part".
/// \throw InvalidInput otherwise.
[[nodiscard]] Shape parse_shape(const std::string& name);

} // namespace pointform
