// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/geometry/point_cloud.h"

#include "pointform/core/error.h"
#include "pointform/core/parallel.h"

#include <cmath>
#include <string>
#include <type_traits>
#include <utility>

namespace pointform {

Aabb bounding_box(std::span<const Vec3f> positions, const Vec3d& origin)
{
    Aabb box;
    if (positions.empty())
        return box;
    Eigen::Vector3f lo = positions[0];
    Eigen::Vector3f hi = positions[0];
    for (const auto& p : positions)
    {
        lo = lo.cwiseMin(p);
        hi = hi.cwiseMax(p);
    }
    box.min = origin + lo.cast<double>();
    box.max = origin + hi.cast<double>();
    return box;
}

PointCloud to_point_cloud(const PointCloudView& view)
{
    PointCloud cloud;
    cloud.origin = view.origin;
    cloud.positions.assign(view.positions.begin(), view.positions.end());
    cloud.normals.assign(view.normals.begin(), view.normals.end());
    cloud.colors.assign(view.colors.begin(), view.colors.end());
    cloud.radii.assign(view.radii.begin(), view.radii.end());
    cloud.sensor = view.sensor;
    return cloud;
}

std::size_t keep_points(PointCloud& cloud, std::span<const std::uint8_t> keep)
{
    PF_ASSERT(keep.size() == cloud.size());
    const auto compact = [&](auto& values) {
        if (values.empty())
            return;
        std::size_t kept = 0;
        for (std::size_t i = 0; i < keep.size(); ++i)
            if (keep[i] != 0)
                values[kept++] = values[i];
        values.resize(kept);
    };
    const std::size_t before = cloud.size();
    compact(cloud.positions);
    compact(cloud.normals);
    compact(cloud.colors);
    compact(cloud.radii);
    return before - cloud.size();
}

void reorder_points(PointCloud& cloud, std::span<const std::uint32_t> order)
{
    PF_ASSERT(order.size() == cloud.size());
    const auto gather = [&](auto& values) {
        if (values.empty())
            return;
        std::remove_reference_t<decltype(values)> out(values.size());
        parallel_blocks(order.size(), std::size_t{1} << 16U,
                        [&](std::size_t begin, std::size_t end) {
                            for (std::size_t j = begin; j < end; ++j)
                                out[j] = values[order[j]];
                        });
        values = std::move(out);
    };
    gather(cloud.positions);
    gather(cloud.normals);
    gather(cloud.colors);
    gather(cloud.radii);
}

Vec3d choose_origin(const Vec3d& first)
{
    return {std::round(first.x()), std::round(first.y()), std::round(first.z())};
}

void validate(const PointCloudView& cloud)
{
    const auto check = [&](std::size_t size, const char* name) {
        if (size != 0 && size != cloud.size())
            throw InvalidInput(std::string("point cloud has ") + std::to_string(cloud.size()) +
                               " positions but " + std::to_string(size) + " " + name);
    };
    check(cloud.normals.size(), "normals");
    check(cloud.colors.size(), "colors");
    check(cloud.radii.size(), "radii");
}

} // namespace pointform
