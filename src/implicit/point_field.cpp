// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/implicit/point_field.h"

#include "pointform/core/error.h"
#include "pointform/spatial/kd_tree.h"
#include "pointform/spatial/point_grid.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <string>

namespace pointform {

namespace {

constexpr std::size_t max_blend_k = 32;

/// Point-grid cell size over the median distance from a sample to its farthest query neighbour:
/// the fastest of 1.5, 2, 2.5 and 3 on a 1M-sample sphere queried within a marching-cubes cell
/// of the surface (bench/implicit). Smaller cells send more queries to the 3 × 3 × 3 block,
/// larger ones scan more points.
constexpr float grid_cell_scale = 2.5F;

void check_surfels(const PointCloud& cloud)
{
    if (cloud.empty())
    {
        throw InvalidInput("point field: the cloud has no samples");
    }
    if (!cloud.has_normals())
    {
        throw InvalidInput("point field: the samples have no normals (orient them first)");
    }
    if (!cloud.has_radii())
    {
        throw InvalidInput("point field: the samples have no influence radii");
    }
    for (std::size_t i = 0; i < cloud.size(); ++i)
    {
        const float norm = cloud.normals[i].norm();
        if (!cloud.positions[i].allFinite() || !std::isfinite(norm) || norm < 0.5F ||
            !(cloud.radii[i] > 0.0F) || !std::isfinite(cloud.radii[i]))
        {
            throw InvalidInput(
                "point field: sample " + std::to_string(i) +
                " has a non-finite position, a zero normal or a non-positive radius");
        }
    }
}

} // namespace

PlaneFit parse_plane_fit(std::string_view text)
{
    if (text == "raw")
    {
        return PlaneFit::Raw;
    }
    if (text == "centroid")
    {
        return PlaneFit::Centroid;
    }
    if (text == "blend")
    {
        return PlaneFit::Blend;
    }
    throw InvalidInput("unknown plane fit '" + std::string(text) +
                       "' (expected raw, centroid or blend)");
}

std::string_view to_string(PlaneFit fit)
{
    switch (fit)
    {
        case PlaneFit::Raw:
            return "raw";
        case PlaneFit::Centroid:
            return "centroid";
        case PlaneFit::Blend:
            return "blend";
    }
    return "?";
}

/// What the field reads of one sample, packed in the grid's order so that the samples a query
/// meets are next to each other in memory.
struct PackedSurfel
{
    Vec3f position;
    /// n·(c − s): the offset of the centroid plane along the normal (zero for Raw).
    float offset;
    Vec3f normal;
    float radius;

    /// Signed distance of `p` (relative to the cloud origin) to the sample's plane.
    [[nodiscard]] double plane_distance(const Vec3d& p) const
    {
        return (p - position.cast<double>()).dot(normal.cast<double>()) -
               static_cast<double>(offset);
    }
};

struct PointField::Impl
{
    PointCloud surfels;
    PointFieldOptions options;
    KdTree tree;
    std::unique_ptr<PointGrid> grid;
    std::vector<PackedSurfel> packed; ///< indexed by grid slot
    Aabb box;
    double median_radius = 0.0;
    double area = 0.0;

    Impl(PointCloud cloud, const PointFieldOptions& opts)
        : surfels(std::move(cloud)), options(opts), tree(surfels.positions)
    {}
};

PointField::PointField(PointCloud surfels, const PointFieldOptions& options)
{
    check_surfels(surfels);
    if (options.fit == PlaneFit::Blend && (options.blend_k < 2 || options.blend_k > max_blend_k))
    {
        throw InvalidInput("point field: blend_k must be between 2 and " +
                           std::to_string(max_blend_k));
    }
    if (options.fit != PlaneFit::Raw && options.centroid_k < 2)
    {
        throw InvalidInput("point field: centroid_k must be at least 2");
    }
    impl_ = std::make_unique<Impl>(std::move(surfels), options);
    Impl& m = *impl_;
    const std::size_t n = m.surfels.size();
    for (std::size_t i = 0; i < n; ++i)
    {
        m.surfels.normals[i].normalize();
    }

    std::vector<float> plane_offset(n, 0.0F);
    const std::size_t k = std::min(std::max<std::size_t>(options.centroid_k, 2) + 1, n);
    const KnnTable knn = knn_batch(m.tree, m.surfels.positions, k);
    double area = 0.0;
    for (std::size_t i = 0; i < n; ++i)
    {
        // The ball to the last neighbour holds k samples: π d² / k of surface per sample.
        area += std::numbers::pi * static_cast<double>(knn.distances2(i)[k - 1]) /
                static_cast<double>(k);
        if (options.fit == PlaneFit::Raw)
        {
            continue;
        }
        Vec3d centroid = Vec3d::Zero();
        for (const std::uint32_t j : knn.neighbors(i))
        {
            centroid += m.surfels.positions[j].cast<double>();
        }
        centroid /= static_cast<double>(k);
        plane_offset[i] = static_cast<float>((centroid - m.surfels.positions[i].cast<double>())
                                                 .dot(m.surfels.normals[i].cast<double>()));
    }
    m.area = area;

    // Grid cells of about twice a query's farthest neighbour, so that queries near the surface
    // find their neighbours in the 8 cells around them (PointGrid).
    const std::size_t query_k = options.fit == PlaneFit::Blend ? options.blend_k + 1 : 9;
    std::vector<float> reach(n);
    for (std::size_t i = 0; i < n; ++i)
    {
        reach[i] = knn.distances2(i)[std::min(query_k, k) - 1];
    }
    auto reach_middle = reach.begin() + static_cast<std::ptrdiff_t>(n / 2);
    std::nth_element(reach.begin(), reach_middle, reach.end());
    const float cell = grid_cell_scale * std::sqrt(*reach_middle);
    m.grid = std::make_unique<PointGrid>(m.surfels.positions, cell > 0.0F ? cell : 1.0F, m.tree);
    m.packed.resize(m.grid->slot_count());
    for (std::size_t slot = 0; slot < m.packed.size(); ++slot)
    {
        const std::uint32_t i = m.grid->original_index(static_cast<std::uint32_t>(slot));
        if (i != PointGrid::padding_slot)
        {
            m.packed[slot] = PackedSurfel{m.surfels.positions[i], plane_offset[i],
                                          m.surfels.normals[i], m.surfels.radii[i]};
        }
    }

    float max_radius = 0.0F;
    for (const float r : m.surfels.radii)
    {
        max_radius = std::max(max_radius, r);
    }
    m.box = m.surfels.bounds();
    m.box.min -= Vec3d::Constant(max_radius);
    m.box.max += Vec3d::Constant(max_radius);

    std::vector<float> radii = m.surfels.radii;
    auto middle = radii.begin() + static_cast<std::ptrdiff_t>(radii.size() / 2);
    std::nth_element(radii.begin(), middle, radii.end());
    m.median_radius = *middle;
}

PointField::~PointField() = default;

FieldSample PointField::evaluate(const Vec3d& world_point) const
{
    const Impl& m = *impl_;
    const Vec3d p = world_point - m.surfels.origin;
    const Vec3f query = p.cast<float>();
    FieldSample out;

    std::array<std::uint32_t, max_blend_k + 1> slot{};
    std::array<float, max_blend_k + 1> dist2{};
    if (m.options.fit != PlaneFit::Blend)
    {
        m.grid->knn(query, 1, slot, dist2);
        const PackedSurfel& nearest = m.packed[slot[0]];
        const double distance = (p - nearest.position.cast<double>()).norm();
        const double plane = nearest.plane_distance(p);
        out.defined = distance <= static_cast<double>(nearest.radius);
        out.value = out.defined ? plane : std::copysign(distance, plane);
        out.gradient = nearest.normal.cast<double>();
        return out;
    }

    // Blend: the blend_k nearest planes, weights vanishing at the (blend_k + 1)-th distance.
    const std::size_t want = std::min(m.options.blend_k + 1, m.surfels.size());
    const std::size_t found =
        m.grid->knn(query, want, std::span(slot.data(), want), std::span(dist2.data(), want));
    const PackedSurfel& nearest = m.packed[slot[0]];
    const double nearest_distance = (p - nearest.position.cast<double>()).norm();
    const double nearest_plane = nearest.plane_distance(p);
    // Defined inside the union of the blended samples' influence balls, so that a gap next to
    // a sample with a small radius is covered by its neighbours' balls.
    out.defined = false;
    for (std::size_t j = 0; j < found && !out.defined; ++j)
    {
        const auto r = static_cast<double>(m.packed[slot[j]].radius);
        out.defined = static_cast<double>(dist2[j]) <= r * r;
    }
    if (!out.defined)
    {
        out.value = std::copysign(nearest_distance, nearest_plane);
        out.gradient = nearest.normal.cast<double>();
        return out;
    }

    const std::size_t used = found == want && found > 1 ? found - 1 : found;
    // Bandwidth: the distance of the first sample not blended (or a little beyond the last).
    double bandwidth = std::sqrt(static_cast<double>(dist2[found - 1]));
    if (used == found)
    {
        bandwidth *= 1.5;
    }
    if (!(bandwidth > 0.0))
    {
        out.value = nearest_plane;
        out.gradient = nearest.normal.cast<double>();
        return out;
    }
    // One pass: with w_i the weights, d_i the plane distances and g_i = ∇w_i,
    // f = Σ w_i d_i / Σ w_i and ∇f = (Σ w_i n_i + Σ g_i d_i − f Σ g_i) / Σ w_i.
    const double inv_h = 1.0 / bandwidth;
    double weight_sum = 0.0;
    double value_sum = 0.0;
    Vec3d normal_sum = Vec3d::Zero();
    Vec3d weighted_gradient_sum = Vec3d::Zero();
    Vec3d gradient_sum = Vec3d::Zero();
    for (std::size_t j = 0; j < used; ++j)
    {
        const PackedSurfel& sample = m.packed[slot[j]];
        const Vec3d offset = p - sample.position.cast<double>();
        const double t = std::sqrt(static_cast<double>(dist2[j])) * inv_h;
        const double u = std::max(0.0, 1.0 - t);
        const double u3 = u * u * u;
        const double weight = u3 * u * (4.0 * t + 1.0); // Wendland's C² kernel (1 − t)⁴(4t + 1)
        // d/dp of (1 − t)⁴(4t + 1) with t = ‖p − s_i‖/h: −20 (1 − t)³ (p − s_i)/h².
        const Vec3d weight_gradient = (-20.0 * u3 * inv_h * inv_h) * offset;
        const Vec3d normal = sample.normal.cast<double>();
        const double plane = offset.dot(normal) - static_cast<double>(sample.offset);
        weight_sum += weight;
        value_sum += weight * plane;
        normal_sum += weight * normal;
        weighted_gradient_sum += plane * weight_gradient;
        gradient_sum += weight_gradient;
    }
    if (!(weight_sum > 1e-12))
    {
        out.value = nearest_plane;
        out.gradient = nearest.normal.cast<double>();
        return out;
    }
    out.value = value_sum / weight_sum;
    out.gradient = (normal_sum + weighted_gradient_sum - out.value * gradient_sum) / weight_sum;
    return out;
}

Aabb PointField::bounds() const
{
    return impl_->box;
}

void PointField::append_seeds(std::vector<Vec3d>& seeds) const
{
    const PointCloud& s = impl_->surfels;
    seeds.reserve(seeds.size() + s.size());
    for (std::size_t i = 0; i < s.size(); ++i)
    {
        seeds.push_back(s.world(i));
    }
}

const PointCloud& PointField::surfels() const
{
    return impl_->surfels;
}

const PointFieldOptions& PointField::options() const
{
    return impl_->options;
}

double PointField::median_radius() const
{
    return impl_->median_radius;
}

double PointField::estimated_area() const
{
    return impl_->area;
}

} // namespace pointform
