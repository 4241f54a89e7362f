// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/multires/lattice.h"

#include "pointform/core/error.h"
#include "pointform/core/parallel.h"
#include "pointform/multires/details.h"
#include "pointform/multires/level_of_detail.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>

namespace pointform {

namespace {

/// The Bernstein basis of degree `degree` at u, by de Casteljau's recurrence (a partition of
/// unity to within rounding).
void bernstein(std::size_t degree, double u, double* out)
{
    out[0] = 1.0;
    for (std::size_t k = 1; k <= degree; ++k)
    {
        out[k] = u * out[k - 1];
        for (std::size_t i = k - 1; i > 0; --i)
            out[i] = (1.0 - u) * out[i] + u * out[i - 1];
        out[0] *= 1.0 - u;
    }
}

/// The number of control points of a lattice over [min, max] of this degree, after checking
/// the box and the degrees.
std::size_t checked_point_count(const Vec3d& min, const Vec3d& max,
                                const std::array<std::size_t, 3>& degree)
{
    if (!min.allFinite() || !max.allFinite())
        throw InvalidInput("lattice: the box corners must be finite");
    if ((min.array() >= max.array()).any())
        throw InvalidInput("lattice: the box needs min < max on every axis");
    std::size_t points = 1;
    for (int axis = 0; axis < 3; ++axis)
    {
        const std::size_t d = degree[static_cast<std::size_t>(axis)];
        if (d < 1 || d > max_lattice_degree)
            throw InvalidInput("lattice: degree " + std::to_string(d) + " along axis " +
                               std::string(1, static_cast<char>('x' + axis)) + " is outside 1 to " +
                               std::to_string(max_lattice_degree));
        points *= d + 1;
    }
    if (points > max_lattice_points)
        throw InvalidInput("lattice: " + std::to_string(points) + " control points, more than " +
                           std::to_string(max_lattice_points));
    return points;
}

} // namespace

void validate_lattice(const Lattice& lattice)
{
    const std::size_t points = checked_point_count(lattice.min, lattice.max, lattice.degree);
    if (lattice.control_points.size() != points)
        throw InvalidInput("lattice: a lattice of degree " + std::to_string(lattice.degree[0]) +
                           " x " + std::to_string(lattice.degree[1]) + " x " +
                           std::to_string(lattice.degree[2]) + " needs " + std::to_string(points) +
                           " control points, not " + std::to_string(lattice.control_points.size()));
    for (std::size_t i = 0; i < points; ++i)
        if (!lattice.control_points[i].allFinite())
            throw InvalidInput("lattice: control point " + std::to_string(i) + " is not finite");
}

Lattice rest_lattice(const Vec3d& min, const Vec3d& max, const std::array<std::size_t, 3>& degree)
{
    Lattice lattice;
    lattice.min = min;
    lattice.max = max;
    lattice.degree = degree;
    const Vec3d extent = max - min;
    lattice.control_points.resize(checked_point_count(min, max, degree));
    for (std::size_t k = 0; k <= degree[2]; ++k)
        for (std::size_t j = 0; j <= degree[1]; ++j)
            for (std::size_t i = 0; i <= degree[0]; ++i)
            {
                const Vec3d u(static_cast<double>(i) / static_cast<double>(degree[0]),
                              static_cast<double>(j) / static_cast<double>(degree[1]),
                              static_cast<double>(k) / static_cast<double>(degree[2]));
                lattice.control_points[lattice.index(i, j, k)] = min + u.cwiseProduct(extent);
            }
    return lattice;
}

Vec3d evaluate_lattice(const Lattice& lattice, const Vec3d& x)
{
    const Vec3d u = (x - lattice.min).cwiseQuotient(lattice.max - lattice.min);
    if ((u.array() < 0.0).any() || (u.array() > 1.0).any() || !u.allFinite())
        return x;
    double bx[max_lattice_degree + 1];
    double by[max_lattice_degree + 1];
    double bz[max_lattice_degree + 1];
    bernstein(lattice.degree[0], u.x(), bx);
    bernstein(lattice.degree[1], u.y(), by);
    bernstein(lattice.degree[2], u.z(), bz);
    Vec3d out = Vec3d::Zero();
    for (std::size_t k = 0; k <= lattice.degree[2]; ++k)
    {
        Vec3d plane = Vec3d::Zero();
        for (std::size_t j = 0; j <= lattice.degree[1]; ++j)
        {
            Vec3d line = Vec3d::Zero();
            const Vec3d* row = &lattice.control_points[lattice.index(0, j, k)];
            for (std::size_t i = 0; i <= lattice.degree[0]; ++i)
                line += bx[i] * row[i];
            plane += by[j] * line;
        }
        out += bz[k] * plane;
    }
    return out;
}

DeformReport apply_lattice(MultiresMesh& mesh, const Lattice& lattice, std::size_t level,
                           LatticeMode mode)
{
    validate_lattice(lattice);
    if (mesh.level_count() == 0)
        throw InvalidInput("lattice: the hierarchy is empty");
    check_level(mesh, level);
    const MultiresMesh before = mesh;
    const std::size_t j = mode == LatticeMode::Plain ? mesh.finest_level() : level;
    const std::size_t n = mesh.vertex_count(j);
    std::optional<DetailSynthesizer> synthesizer;
    MultiresDetails details;
    if (j < mesh.finest_level())
    {
        synthesizer.emplace(mesh);
        details = synthesizer->analyze(mesh);
    }
    const std::span<Vec3d> x = mesh.mutable_positions();
    std::vector<std::uint8_t> moved(x.size(), 0);
    const Vec3d origin = mesh.origin();
    parallel_blocks(n, 4096, [&](std::size_t begin, std::size_t end) {
        for (std::size_t v = begin; v < end; ++v)
        {
            const Vec3d p = evaluate_lattice(lattice, origin + x[v]) - origin;
            moved[v] = p != x[v] ? 1 : 0;
            x[v] = p;
        }
    });
    for (const Vec3d& p : x.first(n))
        if (!p.allFinite())
        {
            mesh = before;
            throw InvalidInput("lattice: the deformation gave a non-finite position");
        }
    if (synthesizer)
        synthesizer->synthesize(mesh, details, j, &moved);

    DeformReport report;
    report.level = j;
    report.region_vertices = n;
    report.levels = level_motion(before, mesh);
    for (const LevelMotion& motion : report.levels)
        report.largest_displacement = std::max(report.largest_displacement, motion.largest);
    return report;
}

} // namespace pointform
