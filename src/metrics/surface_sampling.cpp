// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/metrics/surface_sampling.h"

#include "pointform/core/error.h"
#include "pointform/core/parallel.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <string>

namespace pointform {
namespace {

constexpr std::size_t sample_block = 4096;

void check_indices(const TriMesh& mesh)
{
    const std::size_t v_count = mesh.vertex_count();
    for (std::size_t f = 0; f < mesh.face_count(); ++f)
        for (const std::uint32_t v : mesh.triangles[f])
            if (v >= v_count)
                throw InvalidInput("surface sampling: triangle " + std::to_string(f) +
                                   " refers to vertex " + std::to_string(v) + " but the mesh has " +
                                   std::to_string(v_count) + " vertices");
}

double triangle_area(const TriMesh& mesh, const Triangle& t)
{
    const Vec3d a = mesh.vertices.positions[t[0]].cast<double>();
    const Vec3d b = mesh.vertices.positions[t[1]].cast<double>();
    const Vec3d c = mesh.vertices.positions[t[2]].cast<double>();
    return 0.5 * (b - a).cross(c - a).norm();
}

/// SplitMix64 finaliser: decorrelates the seeds of consecutive blocks.
std::uint64_t mix(std::uint64_t x)
{
    x += 0x9E3779B97F4A7C15ULL;
    x = (x ^ (x >> 30U)) * 0xBF58476D1CE4E5B9ULL;
    x = (x ^ (x >> 27U)) * 0x94D049BB133111EBULL;
    return x ^ (x >> 31U);
}

/// Uniform double in [0, 1) from the top 53 bits, the same on every standard library.
double uniform01(std::mt19937_64& rng)
{
    return static_cast<double>(rng() >> 11U) * 0x1.0p-53;
}

} // namespace

double surface_area(const TriMesh& mesh)
{
    check_indices(mesh);
    double total = 0.0;
    for (const Triangle& t : mesh.triangles)
        total += triangle_area(mesh, t);
    return total;
}

PointCloud sample_surface(const TriMesh& mesh, const SurfaceSamplingOptions& options)
{
    if (mesh.face_count() == 0)
        throw InvalidInput("surface sampling: the mesh has no triangles");
    check_indices(mesh);
    if (!mesh.vertices.origin.allFinite())
        throw InvalidInput("surface sampling: the mesh origin is not finite");
    for (std::size_t i = 0; i < mesh.vertex_count(); ++i)
        if (!mesh.vertices.positions[i].allFinite())
            throw InvalidInput("surface sampling: vertex " + std::to_string(i) +
                               " has a non-finite coordinate");

    // Cumulative areas, summed in a fixed order.
    std::vector<double> cumulative(mesh.face_count());
    double total = 0.0;
    for (std::size_t f = 0; f < mesh.face_count(); ++f)
    {
        total += triangle_area(mesh, mesh.triangles[f]);
        cumulative[f] = total;
    }
    if (!(total > 0.0) || !std::isfinite(total))
        throw InvalidInput(
            "surface sampling: the mesh has zero total area (every triangle is "
            "degenerate)");

    PointCloud cloud;
    cloud.origin = mesh.vertices.origin;
    cloud.positions.resize(options.count);
    if (options.normals)
        cloud.normals.resize(options.count);
    parallel_blocks(options.count, sample_block, [&](std::size_t begin, std::size_t end) {
        std::mt19937_64 rng(mix(options.seed ^ mix(begin / sample_block)));
        for (std::size_t i = begin; i < end; ++i)
        {
            const double target = uniform01(rng) * total;
            // First triangle whose cumulative area exceeds the target: zero-area triangles,
            // whose cumulative area equals their predecessor's, are never chosen.
            auto it = std::upper_bound(cumulative.begin(), cumulative.end(), target);
            if (it == cumulative.end())
                it = std::prev(it);
            const Triangle& t = mesh.triangles[static_cast<std::size_t>(it - cumulative.begin())];
            const double r1 = std::sqrt(uniform01(rng));
            const double r2 = uniform01(rng);
            const Vec3d a = mesh.vertices.positions[t[0]].cast<double>();
            const Vec3d b = mesh.vertices.positions[t[1]].cast<double>();
            const Vec3d c = mesh.vertices.positions[t[2]].cast<double>();
            const Vec3d p = (1.0 - r1) * a + r1 * (1.0 - r2) * b + r1 * r2 * c;
            cloud.positions[i] = p.cast<float>();
            if (options.normals)
                cloud.normals[i] = (b - a).cross(c - a).normalized().cast<float>();
        }
    });

    if (options.include_vertices)
    {
        std::vector<bool> used(mesh.vertex_count(), false);
        std::vector<Vec3d> vertex_normals(options.normals ? mesh.vertex_count() : 0, Vec3d::Zero());
        for (const Triangle& t : mesh.triangles)
        {
            for (const std::uint32_t v : t)
                used[v] = true;
            if (options.normals)
            {
                const Vec3d a = mesh.vertices.positions[t[0]].cast<double>();
                const Vec3d cross = (mesh.vertices.positions[t[1]].cast<double>() - a)
                                        .cross(mesh.vertices.positions[t[2]].cast<double>() - a);
                for (const std::uint32_t v : t)
                    vertex_normals[v] += cross; // |cross| is twice the area: area-weighted
            }
        }
        for (std::size_t v = 0; v < mesh.vertex_count(); ++v)
            if (used[v])
            {
                cloud.positions.push_back(mesh.vertices.positions[v]);
                if (options.normals)
                {
                    const double norm = vertex_normals[v].norm();
                    cloud.normals.push_back(norm > 0.0
                                                ? Vec3f((vertex_normals[v] / norm).cast<float>())
                                                : Vec3f::Zero());
                }
            }
    }
    return cloud;
}

} // namespace pointform
