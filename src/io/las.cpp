// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// ASPRS LAS 1.0 to 1.4, point data record formats 0 to 10, uncompressed. Coordinates are
// int32 X * scale + offset; colors (formats 2, 3, 5, 7, 8, 10) are 16-bit and become 8-bit.

#include "detail_readers.h"

#include <algorithm>
#include <cmath>

namespace pointform::detail {
namespace {

constexpr std::size_t header_size_1_0 = 227;
constexpr std::size_t header_size_1_4 = 375;

/// Bytes a record of each point format needs at least (LAS 1.4 R15, table of formats).
constexpr std::size_t min_record_length[11] = {20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67};

/// Offset of the red channel in a record, or 0 if the format has no colors.
constexpr std::size_t rgb_offset(unsigned format)
{
    switch (format)
    {
        case 2:
            return 20;
        case 3:
        case 5:
            return 28;
        case 7:
        case 8:
        case 10:
            return 30;
        default:
            return 0;
    }
}

struct LasHeader
{
    unsigned version_major = 0;
    unsigned version_minor = 0;
    std::size_t header_size = 0;
    std::uint64_t point_offset = 0;
    unsigned format = 0;
    std::size_t record_length = 0;
    std::uint64_t points = 0;
    Vec3d scale = Vec3d::Ones();
    Vec3d offset = Vec3d::Zero();
};

LasHeader parse_header(const std::filesystem::path& path, std::string_view bytes)
{
    ByteCursor cursor(path, bytes);
    cursor.require(4, "the file signature");
    if (bytes.substr(0, 4) != "LASF")
        fail(path, "not a LAS file (no LASF signature)", Location::at_byte(0));
    cursor.require(header_size_1_0, "the LAS header");

    LasHeader h;
    cursor.seek(24);
    h.version_major = cursor.read_le<std::uint8_t>("version");
    h.version_minor = cursor.read_le<std::uint8_t>("version");
    if (h.version_major != 1 || h.version_minor > 4)
        fail(path,
             "unsupported LAS version " + std::to_string(h.version_major) + "." +
                 std::to_string(h.version_minor) + " (1.0 to 1.4 are supported)",
             Location::at_byte(24));

    cursor.seek(94);
    h.header_size = cursor.read_le<std::uint16_t>("header size");
    h.point_offset = cursor.read_le<std::uint32_t>("offset to point data");
    cursor.skip(4, "number of variable length records");
    const std::size_t format_at = cursor.offset();
    const auto format_byte = cursor.read_le<std::uint8_t>("point data format");
    h.record_length = cursor.read_le<std::uint16_t>("point record length");
    const std::uint32_t legacy_points = cursor.read_le<std::uint32_t>("number of points");

    // LASzip marks compressed files by setting bit 7 (and 6) of the point format.
    if ((format_byte & 0xC0U) != 0)
        fail(path, "compressed LAZ not supported (decompress it to .las first)",
             Location::at_byte(format_at));
    h.format = format_byte;
    if (h.format > 10)
        fail(path, "unsupported LAS point data format " + std::to_string(h.format),
             Location::at_byte(format_at));
    if (h.record_length < min_record_length[h.format])
        fail(path,
             "point record length " + std::to_string(h.record_length) + " is too short for point " +
                 "format " + std::to_string(h.format) + " (needs " +
                 std::to_string(min_record_length[h.format]) + ")",
             Location::at_byte(format_at + 1));
    if (h.header_size < header_size_1_0)
        fail(path, "header size " + std::to_string(h.header_size) + " is smaller than 227",
             Location::at_byte(94));
    if (h.point_offset < h.header_size)
        fail(path, "offset to point data lies inside the header", Location::at_byte(96));

    cursor.seek(131);
    for (int axis = 0; axis < 3; ++axis)
        h.scale[axis] = cursor.read_le<double>("scale");
    for (int axis = 0; axis < 3; ++axis)
        h.offset[axis] = cursor.read_le<double>("offset");
    if (!h.scale.allFinite() || (h.scale.array() == 0.0).any() || !h.offset.allFinite())
        fail(path, "invalid scale or offset", Location::at_byte(131));

    h.points = legacy_points;
    if (h.version_minor >= 4 && h.header_size >= header_size_1_4)
    {
        cursor.seek(247);
        const std::uint64_t points = cursor.read_le<std::uint64_t>("number of point records");
        if (points != 0 || legacy_points == 0)
            h.points = points;
    }
    return h;
}

} // namespace

ReadResult read_las(const std::filesystem::path& path, std::string_view bytes,
                    NonFinitePolicy policy)
{
    const LasHeader h = parse_header(path, bytes);
    if (h.point_offset > bytes.size())
        fail(path,
             "file is truncated: point data should start at byte " + std::to_string(h.point_offset),
             Location::at_byte(bytes.size()));
    const std::size_t start = static_cast<std::size_t>(h.point_offset);
    const std::size_t available = (bytes.size() - start) / h.record_length;
    if (h.points > available)
        fail(path,
             "file is truncated: data ends in point record " + std::to_string(available) +
                 " of the " + std::to_string(h.points) + " the header declares",
             Location::at_byte(start + available * h.record_length));

    const char* records = bytes.data() + start;
    const std::size_t count = static_cast<std::size_t>(h.points);
    const std::size_t color_at = rgb_offset(h.format);
    const bool has_colors = color_at != 0;

    // 16-bit colors become 8-bit by their high byte, unless the file stores 8-bit values.
    unsigned shift = 0;
    if (has_colors)
    {
        std::uint16_t max_channel = 0;
        for (std::size_t i = 0; i < count; ++i)
            for (std::size_t c = 0; c < 3; ++c)
                max_channel =
                    std::max(max_channel,
                             load<std::uint16_t>(records + i * h.record_length + color_at + 2 * c,
                                                 ByteOrder::Little));
        shift = max_channel > 255 ? 8 : 0;
    }

    CloudBuilder builder(path, policy, {.colors = has_colors}, count);
    for (std::size_t i = 0; i < count; ++i)
    {
        const char* record = records + i * h.record_length;
        PointRecord point;
        for (std::size_t axis = 0; axis < 3; ++axis)
        {
            const auto raw = load<std::int32_t>(record + 4 * axis, ByteOrder::Little);
            point.position[axis] = static_cast<double>(raw) * h.scale[axis] + h.offset[axis];
        }
        if (has_colors)
        {
            const auto channel = [&](std::size_t c) {
                const auto v = load<std::uint16_t>(record + color_at + 2 * c, ByteOrder::Little);
                return static_cast<std::uint8_t>(v >> shift);
            };
            point.color = {channel(0), channel(1), channel(2)};
        }
        builder.add(point, Location::at_byte(start + i * h.record_length));
    }

    ReadResult result;
    result.dropped_points = builder.dropped();
    result.points = builder.take();
    result.description = "LAS " + std::to_string(h.version_major) + "." +
                         std::to_string(h.version_minor) + " point format " +
                         std::to_string(h.format);
    return result;
}

} // namespace pointform::detail
