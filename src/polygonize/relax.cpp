// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "relax.h"

#include "pointform/core/parallel.h"
#include "pointform/metrics/quality.h"
#include "pointform/polygonize/projection.h"
#include "pointform/spatial/triangle_bvh.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <vector>

namespace pointform::detail {
namespace {

/// Free vertices per parallel block.
constexpr std::size_t relax_block = 512;

Vec3d area_normal(const Vec3d& a, const Vec3d& b, const Vec3d& c)
{
    return (b - a).cross(c - b);
}

} // namespace

void relax_tangentially(std::span<Vec3d> x, std::span<const Triangle> faces,
                        std::span<const std::uint32_t> ring_offsets,
                        std::span<const std::uint32_t> ring_adjacent,
                        std::span<const std::uint32_t> free, int rounds, RelaxTarget target)
{
    std::vector<std::uint32_t> slot(x.size(), std::numeric_limits<std::uint32_t>::max());
    for (std::size_t i = 0; i < free.size(); ++i)
        slot[free[i]] = static_cast<std::uint32_t>(i);
    std::vector<std::uint32_t> touching;
    for (std::size_t f = 0; f < faces.size(); ++f)
        if (std::any_of(faces[f].begin(), faces[f].end(), [&slot](std::uint32_t v) {
                return slot[v] != std::numeric_limits<std::uint32_t>::max();
            }))
            touching.push_back(static_cast<std::uint32_t>(f));
    if (touching.empty())
        return;
    // The faired surface, which every moved vertex is put back on.
    TriMesh reference;
    {
        std::vector<std::uint32_t> local(x.size(), std::numeric_limits<std::uint32_t>::max());
        reference.triangles.reserve(touching.size());
        for (const std::uint32_t f : touching)
        {
            Triangle t{};
            for (std::size_t c = 0; c < 3; ++c)
            {
                const std::uint32_t v = faces[f][c];
                if (local[v] == std::numeric_limits<std::uint32_t>::max())
                {
                    local[v] = static_cast<std::uint32_t>(reference.vertices.positions.size());
                    reference.vertices.positions.push_back(x[v].cast<float>());
                }
                t[c] = local[v];
            }
            reference.triangles.push_back(t);
        }
    }
    const TriangleBvh surface(reference);
    std::vector<Vec3d> next(free.size());
    // RelaxTarget::face_centroids: each free vertex's faces' centroids, weighted by the faces'
    // areas (twice, as area_normal() gives them).
    const bool by_area = target == RelaxTarget::face_centroids;
    // Each free vertex's faces (indices into `faces`) in ascending order: the sums over them
    // below are made in the order of a pass over the faces, whatever the thread count.
    std::vector<std::uint32_t> first(free.size() + 1, 0);
    for (const std::uint32_t f : touching)
        for (const std::uint32_t v : faces[f])
            if (slot[v] != std::numeric_limits<std::uint32_t>::max())
                ++first[slot[v] + 1];
    for (std::size_t i = 0; i < free.size(); ++i)
        first[i + 1] += first[i];
    std::vector<std::uint32_t> around(first.back());
    {
        std::vector<std::uint32_t> filled(first.begin(), first.end() - 1);
        for (const std::uint32_t f : touching)
            for (const std::uint32_t v : faces[f])
                if (slot[v] != std::numeric_limits<std::uint32_t>::max())
                    around[filled[slot[v]]++] = f;
    }
    for (int round = 0; round < rounds; ++round)
    {
        const bool project = round + 1 == rounds;
        parallel_blocks(free.size(), relax_block, [&](std::size_t begin, std::size_t end) {
            for (std::size_t i = begin; i < end; ++i)
            {
                // The vertex's faces' area normals summed, and their centroids weighted by
                // their areas (face_centroids), in ascending face order.
                Vec3d face_normals = Vec3d::Zero();
                Vec3d centroids = Vec3d::Zero();
                double areas = 0.0;
                for (std::uint32_t e = first[i]; e < first[i + 1]; ++e)
                {
                    const Triangle& t = faces[around[e]];
                    const Vec3d n = area_normal(x[t[0]], x[t[1]], x[t[2]]);
                    face_normals += n;
                    if (by_area)
                    {
                        const double a = n.norm();
                        centroids += a * ((x[t[0]] + x[t[1]] + x[t[2]]) / 3.0);
                        areas += a;
                    }
                }
                const std::uint32_t v = free[i];
                next[i] = x[v];
                const double length = face_normals.norm();
                if (!(length > 0.0) || ring_offsets[v + 1] == ring_offsets[v])
                    continue;
                const Vec3d n = face_normals / length;
                Vec3d mean = Vec3d::Zero();
                for (std::uint32_t e = ring_offsets[v]; e < ring_offsets[v + 1]; ++e)
                    mean += x[ring_adjacent[e]];
                mean /= static_cast<double>(ring_offsets[v + 1] - ring_offsets[v]);
                if (by_area && areas > 0.0)
                    mean = centroids / areas;
                const Vec3d move = mean - x[v];
                next[i] = x[v] + move - move.dot(n) * n;
                if (project)
                {
                    const TriangleBvh::Hit hit = surface.closest(next[i]);
                    if (hit.found())
                        next[i] = hit.point;
                }
            }
        });
        for (std::size_t i = 0; i < free.size(); ++i)
            x[free[i]] = next[i];
    }
}

std::size_t depth_in_rings(std::span<const std::uint32_t> ring_offsets,
                           std::span<const std::uint32_t> ring_adjacent,
                           std::span<const char> inside)
{
    std::vector<std::uint32_t> depth(inside.size(), 0);
    std::vector<std::uint32_t> front;
    for (std::uint32_t v = 0; v < inside.size(); ++v)
    {
        if (inside[v] == 0)
            continue;
        for (std::uint32_t slot = ring_offsets[v]; slot < ring_offsets[v + 1]; ++slot)
            if (inside[ring_adjacent[slot]] == 0)
            {
                depth[v] = 1;
                front.push_back(v);
                break;
            }
    }
    std::size_t deepest = front.empty() ? 0 : 1;
    while (!front.empty())
    {
        std::vector<std::uint32_t> next;
        for (const std::uint32_t v : front)
            for (std::uint32_t slot = ring_offsets[v]; slot < ring_offsets[v + 1]; ++slot)
            {
                const std::uint32_t w = ring_adjacent[slot];
                if (inside[w] != 0 && depth[w] == 0)
                {
                    depth[w] = depth[v] + 1;
                    deepest = std::max<std::size_t>(deepest, depth[w]);
                    next.push_back(w);
                }
            }
        front = std::move(next);
    }
    return deepest;
}

int relax_membranes(std::span<Vec3d> x, std::span<const Triangle> faces,
                    std::span<const std::uint32_t> ring_offsets,
                    std::span<const std::uint32_t> ring_adjacent,
                    std::span<const std::uint32_t> free, std::size_t depth)
{
    std::vector<char> moving(x.size(), 0);
    for (const std::uint32_t v : free)
        moving[v] = 1;
    std::vector<std::uint32_t> around;
    for (std::size_t f = 0; f < faces.size(); ++f)
        if (moving[faces[f][0]] != 0 || moving[faces[f][1]] != 0 || moving[faces[f][2]] != 0)
            around.push_back(static_cast<std::uint32_t>(f));
    const double bound = default_sliver_degrees * std::numbers::pi / 180.0;
    const auto thin_share = [&] {
        if (around.empty())
            return 0.0;
        std::size_t thin = 0;
        for (const std::uint32_t f : around)
            if (triangle_min_angle(x[faces[f][0]], x[faces[f][1]], x[faces[f][2]]) < bound)
                ++thin;
        return static_cast<double>(thin) / static_cast<double>(around.size());
    };
    const std::size_t most =
        std::max<std::size_t>(depth * depth, static_cast<std::size_t>(faired_relax_rounds));
    double share = 1.0;
    int rounds = 0;
    while (static_cast<std::size_t>(rounds) < most)
    {
        relax_tangentially(x, faces, ring_offsets, ring_adjacent, free, faired_relax_rounds,
                           RelaxTarget::face_centroids);
        rounds += faired_relax_rounds;
        const double now = thin_share();
        if (!(now > membrane_thin_share) || !(now < (1.0 - membrane_round_gain) * share))
            break;
        share = now;
    }
    return rounds;
}

std::optional<Vec3d> project_from_centroid(const Field& field, const Vec3d& centre, double offset,
                                           double reach)
{
    const FieldSample at = field.evaluate(centre);
    if (!at.defined || !(std::abs(at.value) < 0.25 * offset) || !at.gradient.allFinite() ||
        !(at.gradient.squaredNorm() > 0.0))
        return std::nullopt;
    return project_to_zero(field, at, centre, at.gradient.normalized(), reach);
}

/// despike(): a vertex is a spike when it stands farther than this share of its mean
/// edge from the plane of its neighbours (their least-squares plane) ...
constexpr double spike_offset = 0.25;
/// ... and farther than this many times as far as the second farthest of its neighbours from
/// theirs (each neighbour's ring holds the spike, which raises its own offset; along a crease
/// two neighbours stand as far as the vertex, at a corner three).
constexpr double spike_isolation = 2.5;

std::size_t despike(std::span<Vec3d> x, const Vec3d& origin, const Field& field,
                    std::span<const std::uint32_t> ring_offsets,
                    std::span<const std::uint32_t> ring_adjacent,
                    std::span<const std::uint8_t> boundary)
{
    const std::size_t n = x.size();
    std::vector<Vec3d> centre(n, Vec3d::Zero());
    std::vector<double> offset(n, 0.0);
    std::vector<double> edge(n, 0.0);
    const auto ring = [&](std::size_t v) {
        return ring_adjacent.subspan(ring_offsets[v], ring_offsets[v + 1] - ring_offsets[v]);
    };
    parallel_blocks(n, 4096, [&](std::size_t begin, std::size_t end) {
        for (std::size_t v = begin; v < end; ++v)
        {
            const auto r = ring(v);
            if (r.size() < 3)
                continue;
            Vec3d c = Vec3d::Zero();
            double length = 0.0;
            for (const std::uint32_t w : r)
            {
                c += x[w];
                length += (x[w] - x[v]).norm();
            }
            c /= static_cast<double>(r.size());
            Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
            for (const std::uint32_t w : r)
                scatter += (x[w] - c) * (x[w] - c).transpose();
            Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen;
            eigen.computeDirect(scatter); // closed form: one per vertex of the finest level
            centre[v] = c;
            offset[v] = std::abs((x[v] - c).dot(eigen.eigenvectors().col(0)));
            edge[v] = length / static_cast<double>(r.size());
        }
    });
    std::vector<Vec3d> next(n);
    std::vector<char> moved(n, 0);
    parallel_blocks(n, 4096, [&](std::size_t begin, std::size_t end) {
        for (std::size_t v = begin; v < end; ++v)
        {
            const auto r = ring(v);
            if (r.size() < 3 || boundary[v] != 0 || !(offset[v] > spike_offset * edge[v]))
                continue;
            double most = 0.0;
            double second = 0.0;
            for (const std::uint32_t w : r)
            {
                second = std::max(second, std::min(most, offset[w]));
                most = std::max(most, offset[w]);
            }
            if (!(offset[v] > spike_isolation * second))
                continue;
            const std::optional<Vec3d> hit =
                project_from_centroid(field, origin + centre[v], offset[v], edge[v]);
            if (!hit)
                continue;
            next[v] = *hit - origin;
            moved[v] = 1;
        }
    });
    std::size_t count = 0;
    for (std::size_t v = 0; v < n; ++v)
        if (moved[v] != 0)
        {
            x[v] = next[v];
            ++count;
        }
    return count;
}

} // namespace pointform::detail
