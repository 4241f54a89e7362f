// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/metrics/quality.h"

#include "pointform/core/error.h"

#include <algorithm>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

namespace pointform {

double triangle_min_angle(const Vec3d& a, const Vec3d& b, const Vec3d& c)
{
    const auto angle = [](const Vec3d& u, const Vec3d& v) {
        return std::atan2(u.cross(v).norm(), u.dot(v));
    };
    const Vec3d ab = b - a;
    const Vec3d bc = c - b;
    const Vec3d ca = a - c;
    const double lab = ab.squaredNorm();
    const double lbc = bc.squaredNorm();
    const double lca = ca.squaredNorm();
    if (lab == 0.0 || lbc == 0.0 || lca == 0.0)
        return 0.0;
    // The smallest angle lies opposite the shortest side (law of sines): one atan2, not three.
    if (lbc <= lab && lbc <= lca)
        return angle(ab, Vec3d(-ca)); // at a
    if (lca <= lab)
        return angle(bc, Vec3d(-ab)); // at b
    return angle(ca, Vec3d(-bc));     // at c
}

AngleQuality angle_quality(const TriMesh& mesh, double sliver_degrees)
{
    const std::size_t vertex_count = mesh.vertex_count();
    for (std::size_t f = 0; f < mesh.face_count(); ++f)
        for (const std::uint32_t v : mesh.triangles[f])
            if (v >= vertex_count)
                throw InvalidInput("mesh quality: triangle " + std::to_string(f) +
                                   " refers to vertex " + std::to_string(v) + " but the mesh has " +
                                   std::to_string(vertex_count) + " vertices");
    // Boundary vertices: the ends of edges that one triangle uses.
    std::vector<std::pair<std::uint32_t, std::uint32_t>> edges;
    edges.reserve(3 * mesh.face_count());
    for (const Triangle& t : mesh.triangles)
        for (std::size_t k = 0; k < 3; ++k)
            edges.emplace_back(std::min(t[k], t[(k + 1) % 3]), std::max(t[k], t[(k + 1) % 3]));
    std::sort(edges.begin(), edges.end());
    std::vector<bool> on_boundary(vertex_count, false);
    for (std::size_t i = 0; i < edges.size();)
    {
        std::size_t j = i + 1;
        while (j < edges.size() && edges[j] == edges[i])
            ++j;
        if (j - i == 1)
            on_boundary[edges[i].first] = on_boundary[edges[i].second] = true;
        i = j;
    }

    constexpr double degrees = std::numbers::pi / 180.0;
    AngleQuality out;
    std::size_t slivers = 0;
    std::size_t interior_slivers = 0;
    double angle_sum = 0.0;
    for (const Triangle& t : mesh.triangles)
    {
        const auto& p = mesh.vertices.positions;
        const double angle = triangle_min_angle(p[t[0]].cast<double>(), p[t[1]].cast<double>(),
                                                p[t[2]].cast<double>()) /
                             degrees;
        const bool boundary = on_boundary[t[0]] || on_boundary[t[1]] || on_boundary[t[2]];
        out.min_degrees = std::min(out.min_degrees, angle);
        angle_sum += angle;
        slivers += angle < sliver_degrees ? 1 : 0;
        out.interior_faces += boundary ? 0 : 1;
        interior_slivers += !boundary && angle < sliver_degrees ? 1 : 0;
    }
    const auto share = [](std::size_t part, std::size_t whole) {
        return whole == 0 ? 0.0 : static_cast<double>(part) / static_cast<double>(whole);
    };
    out.faces = mesh.face_count();
    out.mean_min_degrees = share(1, out.faces) * angle_sum;
    out.sliver_share = share(slivers, out.faces);
    out.interior_sliver_share = share(interior_slivers, out.interior_faces);
    return out;
}

} // namespace pointform
