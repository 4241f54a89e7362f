// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <compare>
#include <cstdint>
#include <limits>

namespace pointform {

/// Storage type of positions and normals: 12 bytes a sample, as the paper counts them (§3).
using Vec3f = Eigen::Vector3f;
/// Arithmetic type for origins, covariances, projections and distances.
using Vec3d = Eigen::Vector3d;
using Mat3d = Eigen::Matrix3d;

/// \brief A 32-bit index with a type, so that a point index cannot be passed as a face index.
template <typename Tag>
struct Id
{
    static constexpr std::uint32_t invalid_value = std::numeric_limits<std::uint32_t>::max();

    std::uint32_t value = invalid_value;

    constexpr Id() = default;
    constexpr explicit Id(std::uint32_t v) : value(v) {}

    [[nodiscard]] constexpr bool is_valid() const { return value != invalid_value; }
    constexpr auto operator<=>(const Id&) const = default;
};

struct PointTag;
struct VertexTag;
struct FaceTag;

using PointId = Id<PointTag>;
using VertexId = Id<VertexTag>;
using FaceId = Id<FaceTag>;

/// \brief An 8-bit-per-channel colour.
struct Color
{
    std::uint8_t r = 0;
    std::uint8_t g = 0;
    std::uint8_t b = 0;

    constexpr auto operator<=>(const Color&) const = default;
};

} // namespace pointform
