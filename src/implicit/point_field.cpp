// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/implicit/point_field.h"

#include "pointform/core/error.h"
#include "pointform/spatial/kd_tree.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <string>

namespace pointform {

namespace {

constexpr std::size_t max_blend_k = 32;

/// Wendland's C² kernel on [0, 1]: (1 − t)⁴ (4t + 1).
double wendland(double t)
{
    if (t >= 1.0)
    {
        return 0.0;
    }
    const double u = 1.0 - t;
    return u * u * u * u * (4.0 * t + 1.0);
}

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

struct PointField::Impl
{
    PointCloud surfels;
    PointFieldOptions options;
    KdTree tree;
    /// Per sample: n_k·(c_k − s_k), the offset of the centroid plane along the normal (zero for
    /// Raw).
    std::vector<float> plane_offset;
    Aabb box;
    double median_radius = 0.0;
    double area = 0.0;

    Impl(PointCloud cloud, const PointFieldOptions& opts)
        : surfels(std::move(cloud)), options(opts), tree(surfels.positions)
    {}

    /// Signed distance of `p` (relative to the cloud origin) to sample i's plane.
    [[nodiscard]] double plane_distance(std::size_t i, const Vec3d& p) const
    {
        const Vec3d n = surfels.normals[i].cast<double>();
        return (p - surfels.positions[i].cast<double>()).dot(n) -
               static_cast<double>(plane_offset[i]);
    }
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

    m.plane_offset.assign(n, 0.0F);
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
        m.plane_offset[i] = static_cast<float>((centroid - m.surfels.positions[i].cast<double>())
                                                   .dot(m.surfels.normals[i].cast<double>()));
    }
    m.area = area;

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

    if (m.options.fit != PlaneFit::Blend)
    {
        float d2 = 0.0F;
        const std::size_t nearest = m.tree.nearest(query, &d2).value;
        const double distance = (p - m.surfels.positions[nearest].cast<double>()).norm();
        const double plane = m.plane_distance(nearest, p);
        out.defined = distance <= static_cast<double>(m.surfels.radii[nearest]);
        out.value = out.defined ? plane : std::copysign(distance, plane);
        out.gradient = m.surfels.normals[nearest].cast<double>();
        return out;
    }

    // Blend: the blend_k nearest planes, weights vanishing at the (blend_k + 1)-th distance.
    std::array<std::uint32_t, max_blend_k + 1> index{};
    std::array<float, max_blend_k + 1> dist2{};
    const std::size_t want = std::min(m.options.blend_k + 1, m.surfels.size());
    const std::size_t found =
        m.tree.knn(query, want, std::span(index.data(), want), std::span(dist2.data(), want));
    const std::size_t nearest = index[0];
    const double nearest_distance = (p - m.surfels.positions[nearest].cast<double>()).norm();
    const double nearest_plane = m.plane_distance(nearest, p);
    // Defined inside the union of the blended samples' influence balls, so that a gap next to
    // a sample with a small radius is covered by its neighbours' balls.
    out.defined = false;
    for (std::size_t j = 0; j < found && !out.defined; ++j)
    {
        out.defined =
            static_cast<double>(dist2[j]) <= static_cast<double>(m.surfels.radii[index[j]]) *
                                                 static_cast<double>(m.surfels.radii[index[j]]);
    }
    if (!out.defined)
    {
        out.value = std::copysign(nearest_distance, nearest_plane);
        out.gradient = m.surfels.normals[nearest].cast<double>();
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
        out.gradient = m.surfels.normals[nearest].cast<double>();
        return out;
    }
    const double inv_h = 1.0 / bandwidth;
    double weight_sum = 0.0;
    double value_sum = 0.0;
    Vec3d normal_sum = Vec3d::Zero();
    std::array<double, max_blend_k + 1> plane{};
    std::array<double, max_blend_k + 1> weight{};
    std::array<Vec3d, max_blend_k + 1> weight_gradient{};
    for (std::size_t j = 0; j < used; ++j)
    {
        const std::size_t i = index[j];
        const Vec3d offset = p - m.surfels.positions[i].cast<double>();
        const double t = offset.norm() * inv_h;
        weight[j] = wendland(t);
        // d/dp of (1 − t)⁴(4t + 1) with t = ‖p − s_i‖/h: −20 (1 − t)³ (p − s_i)/h².
        const double u = std::max(0.0, 1.0 - t);
        weight_gradient[j] = (-20.0 * u * u * u * inv_h * inv_h) * offset;
        plane[j] = m.plane_distance(i, p);
        weight_sum += weight[j];
        value_sum += weight[j] * plane[j];
        normal_sum += weight[j] * m.surfels.normals[i].cast<double>();
    }
    if (!(weight_sum > 1e-12))
    {
        out.value = nearest_plane;
        out.gradient = m.surfels.normals[nearest].cast<double>();
        return out;
    }
    out.value = value_sum / weight_sum;
    Vec3d gradient = normal_sum;
    for (std::size_t j = 0; j < used; ++j)
    {
        gradient += weight_gradient[j] * (plane[j] - out.value);
    }
    out.gradient = gradient / weight_sum;
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
