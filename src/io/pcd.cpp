// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// PCD (Point Cloud Library) v0.6/v0.7 with DATA ascii, binary (one record a point) and
// binary_compressed (LZF over the fields laid out one after another, "structure of arrays").

#include "detail_readers.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>

namespace pointform::detail {
namespace {

struct PcdField
{
    std::string name;
    char type = 'F'; ///< F (float), I (signed), U (unsigned)
    std::size_t size = 4;
    std::size_t count = 1;
    Field field = Field::None; ///< where a single value goes in the point
    bool packed_rgb = false;   ///< a single 4-byte rgb or rgba value: the color as 0x00RRGGBB
    // Where the values are once the data is in memory: value of point i at base + i * stride.
    const char* base = nullptr;
    std::size_t stride = 0;
};

enum class PcdData
{
    Ascii,
    Binary,
    BinaryCompressed,
};

struct PcdHeader
{
    std::vector<PcdField> fields;
    std::uint64_t width = 0;
    std::uint64_t height = 1;
    std::uint64_t points = 0;
    PcdData data = PcdData::Ascii;
    std::size_t data_offset = 0;
    std::uint64_t header_lines = 0;
    AttributeSet attributes;
    /// VIEWPOINT's translation (tx ty tz), where the header gives one.
    std::optional<Vec3d> viewpoint;

    [[nodiscard]] std::size_t point_size() const
    {
        std::size_t size = 0;
        for (const auto& f : fields)
            size += f.size * f.count;
        return size;
    }
    [[nodiscard]] std::size_t values_per_point() const
    {
        std::size_t n = 0;
        for (const auto& f : fields)
            n += f.count;
        return n;
    }
};

/// PCD field names we read one value from (the packed rgb field is told apart separately).
constexpr FieldName pcd_field_names[] = {
    {"x", Field::X},         {"y", Field::Y},         {"z", Field::Z},
    {"normal_x", Field::Nx}, {"normal_y", Field::Ny}, {"normal_z", Field::Nz},
};

/// Reads all values of a header line into `out`; returns how many there were.
std::size_t split(std::string_view rest, std::vector<std::string_view>& out)
{
    out.clear();
    std::string_view token;
    while (next_token(rest, token))
        out.push_back(token);
    return out.size();
}

PcdHeader parse_header(const std::filesystem::path& path, std::string_view bytes)
{
    PcdHeader header;
    LineReader lines(bytes);
    std::string_view line;
    std::vector<std::string_view> values;
    bool have_points = false;
    bool have_width = false;
    bool have_fields = false;
    std::uint64_t size_line = 0;
    std::uint64_t type_line = 0;
    std::uint64_t count_line = 0;
    std::vector<std::size_t> sizes;
    std::vector<char> types;
    std::vector<std::size_t> counts;

    while (true)
    {
        if (!lines.next(line))
            fail(path, "header has no DATA line", Location::at_line(lines.line_number()));
        const Location here = Location::at_line(lines.line_number());
        std::string_view rest = trim(line);
        std::string_view keyword;
        if (rest.empty() || rest.front() == '#' || !next_token(rest, keyword))
            continue;
        split(rest, values);
        const auto integer = [&](std::string_view token) {
            std::uint64_t v = 0;
            if (!parse_integer(token, v))
                fail(path, "malformed number " + quote(token) + " in " + std::string(keyword),
                     here);
            return v;
        };
        if (keyword == "VERSION")
        {
            continue;
        }
        if (keyword == "VIEWPOINT")
        {
            // tx ty tz qw qx qy qz: the sensor's pose. Its position is what orients the normals
            // of a depth image; the rotation plays no part, but must be numbers too.
            if (values.size() != 7)
                fail(path, "VIEWPOINT needs 7 values (tx ty tz qw qx qy qz)", here);
            std::array<double, 7> pose{};
            for (std::size_t a = 0; a < pose.size(); ++a)
                if (!parse_double(values[a], pose[a]) || !std::isfinite(pose[a]))
                    fail(path, "malformed number " + quote(values[a]) + " in VIEWPOINT", here);
            header.viewpoint = Vec3d(pose[0], pose[1], pose[2]);
            continue;
        }
        if (keyword == "FIELDS" || keyword == "COLUMNS")
        {
            header.fields.clear();
            for (const auto name : values)
            {
                PcdField field;
                field.name = std::string(name);
                header.fields.push_back(std::move(field));
            }
            have_fields = true;
        }
        else if (keyword == "SIZE")
        {
            sizes.clear();
            for (const auto v : values)
                sizes.push_back(static_cast<std::size_t>(integer(v)));
            size_line = here.line.value_or(0);
        }
        else if (keyword == "TYPE")
        {
            types.clear();
            for (const auto v : values)
            {
                if (v.size() != 1 || (v[0] != 'F' && v[0] != 'I' && v[0] != 'U'))
                    fail(path, "unknown field type " + quote(v) + " (expected F, I or U)", here);
                types.push_back(v[0]);
            }
            type_line = here.line.value_or(0);
        }
        else if (keyword == "COUNT")
        {
            counts.clear();
            for (const auto v : values)
                counts.push_back(static_cast<std::size_t>(integer(v)));
            count_line = here.line.value_or(0);
        }
        else if (keyword == "WIDTH" || keyword == "HEIGHT" || keyword == "POINTS")
        {
            if (values.size() != 1)
                fail(path, std::string(keyword) + " needs one value", here);
            const std::uint64_t v = integer(values[0]);
            if (keyword == "WIDTH")
            {
                header.width = v;
                have_width = true;
            }
            else if (keyword == "HEIGHT")
            {
                header.height = v;
            }
            else
            {
                header.points = v;
                have_points = true;
            }
        }
        else if (keyword == "DATA")
        {
            if (values.size() != 1)
                fail(path, "DATA needs one value", here);
            if (values[0] == "ascii")
                header.data = PcdData::Ascii;
            else if (values[0] == "binary")
                header.data = PcdData::Binary;
            else if (values[0] == "binary_compressed")
                header.data = PcdData::BinaryCompressed;
            else
                fail(path, "unknown DATA kind " + quote(values[0]), here);
            break;
        }
        else
        {
            fail(path, "unknown header line " + quote(line), here);
        }
    }
    header.data_offset = lines.offset();
    header.header_lines = lines.line_number();
    const Location data_line = Location::at_line(header.header_lines);

    const std::size_t n = header.fields.size();
    if (!have_fields || n == 0)
        fail(path, "header has no FIELDS", data_line);
    if (sizes.size() != n)
        fail(path,
             "SIZE has " + std::to_string(sizes.size()) + " values for " + std::to_string(n) +
                 " fields",
             Location::at_line(size_line != 0 ? size_line : header.header_lines));
    if (types.size() != n)
        fail(path,
             "TYPE has " + std::to_string(types.size()) + " values for " + std::to_string(n) +
                 " fields",
             Location::at_line(type_line != 0 ? type_line : header.header_lines));
    if (count_line != 0 && counts.size() != n)
        fail(path,
             "COUNT has " + std::to_string(counts.size()) + " values for " + std::to_string(n) +
                 " fields",
             Location::at_line(count_line));
    if (!have_width)
        fail(path, "header has no WIDTH", data_line);
    if (!have_points)
        header.points = header.width * header.height;
    if (header.height == 0 ||
        header.width > std::numeric_limits<std::uint64_t>::max() / header.height ||
        header.points != header.width * header.height)
        fail(path,
             "POINTS " + std::to_string(header.points) + " does not match WIDTH x HEIGHT = " +
                 std::to_string(header.width) + " x " + std::to_string(header.height),
             data_line);

    FieldSet found;
    bool found_rgb = false;
    for (std::size_t i = 0; i < n; ++i)
    {
        PcdField& field = header.fields[i];
        field.size = sizes[i];
        field.type = types[i];
        field.count = count_line != 0 ? counts[i] : 1;
        const bool valid_size = field.type == 'F' ? (field.size == 4 || field.size == 8)
                                                  : (field.size == 1 || field.size == 2 ||
                                                     field.size == 4 || field.size == 8);
        if (!valid_size)
            fail(path,
                 "field " + field.name + " has type " + std::string(1, field.type) +
                     " with unsupported size " + std::to_string(field.size),
                 data_line);
        if (field.count > 1'000'000)
            fail(path, "field " + field.name + " has an unreasonable COUNT", data_line);
        if (field.count == 1)
        {
            field.field = field_named(field.name, pcd_field_names);
            field.packed_rgb = (field.name == "rgb" || field.name == "rgba") && field.size == 4;
        }
        found.add(field.field);
        found_rgb = found_rgb || field.packed_rgb;
    }
    if (!found.has_position())
        fail(path, "FIELDS has no x, y and z", data_line);
    header.attributes.normals = found.attributes().normals;
    header.attributes.colors = found_rgb; // PCD colors come packed, never as separate channels
    return header;
}

/// Value of a binary field (little-endian, as PCL writes it on every platform it runs on).
double binary_value(const char* p, char type, std::size_t size)
{
    constexpr ByteOrder order = ByteOrder::Little;
    if (type == 'F')
        return size == 4 ? static_cast<double>(load<float>(p, order)) : load<double>(p, order);
    if (type == 'I')
    {
        switch (size)
        {
            case 1:
                return load<std::int8_t>(p, order);
            case 2:
                return load<std::int16_t>(p, order);
            case 4:
                return load<std::int32_t>(p, order);
            default:
                return static_cast<double>(load<std::int64_t>(p, order));
        }
    }
    switch (size)
    {
        case 1:
            return load<std::uint8_t>(p, order);
        case 2:
            return load<std::uint16_t>(p, order);
        case 4:
            return load<std::uint32_t>(p, order);
        default:
            return static_cast<double>(load<std::uint64_t>(p, order));
    }
}

Color unpack_rgb(std::uint32_t packed)
{
    return {static_cast<std::uint8_t>((packed >> 16U) & 0xFFU),
            static_cast<std::uint8_t>((packed >> 8U) & 0xFFU),
            static_cast<std::uint8_t>(packed & 0xFFU)};
}

/// Fills a point from the field values of point i, found through each field's base and stride.
PointRecord binary_point(const std::vector<PcdField>& fields, std::size_t i)
{
    PointRecord point;
    for (const PcdField& field : fields)
    {
        if (field.field == Field::None && !field.packed_rgb)
            continue;
        const char* p = field.base + i * field.stride;
        if (field.packed_rgb)
            point.color = unpack_rgb(load<std::uint32_t>(p, ByteOrder::Little));
        else
            set_field(point, field.field, binary_value(p, field.type, field.size));
    }
    return point;
}

void read_ascii(const std::filesystem::path& path, std::string_view bytes, const PcdHeader& header,
                CloudBuilder& builder)
{
    LineReader lines(bytes, header.data_offset, header.header_lines);
    const std::size_t expected = header.values_per_point();
    std::string_view line;
    std::uint64_t read = 0;
    while (lines.next(line))
    {
        if (trim(line).empty())
            continue;
        const Location where = Location::at_line(lines.line_number());
        if (read == header.points)
            fail(path,
                 "more data lines than the " + std::to_string(header.points) +
                     " POINTS the header declares",
                 where);
        PointRecord point;
        std::string_view rest = line;
        std::string_view token;
        std::size_t values = 0;
        for (const PcdField& field : header.fields)
        {
            for (std::size_t k = 0; k < field.count; ++k)
            {
                if (!next_token(rest, token))
                    fail(path,
                         "line has " + std::to_string(values) + " values, expected " +
                             std::to_string(expected),
                         where);
                ++values;
                // PCL writes packed colors as an unsigned integer; older files print the float
                // whose bits hold the color.
                std::uint32_t packed = 0;
                if (field.packed_rgb && parse_integer(token, packed))
                {
                    point.color = unpack_rgb(packed);
                    continue;
                }
                double v = 0.0;
                if (!parse_double(token, v))
                    fail(path, "malformed number " + quote(token), where);
                if (field.packed_rgb)
                    point.color = unpack_rgb(std::bit_cast<std::uint32_t>(static_cast<float>(v)));
                else
                    set_field(point, field.field, v);
            }
        }
        if (next_token(rest, token))
            fail(path, "line has more than the " + std::to_string(expected) + " values expected",
                 where);
        builder.add(point, where);
        ++read;
    }
    if (read != header.points)
        fail(path,
             "file ends after " + std::to_string(read) + " of the " +
                 std::to_string(header.points) + " POINTS the header declares",
             Location::at_line(lines.line_number() + 1));
}

} // namespace

bool lzf_decompress(std::string_view input, std::span<char> output)
{
    const auto* in = reinterpret_cast<const unsigned char*>(input.data());
    const unsigned char* const in_end = in + input.size();
    char* out = output.data();
    char* const out_begin = output.data();
    char* const out_end = output.data() + output.size();
    while (in < in_end)
    {
        const unsigned control = *in++;
        if (control < 32U)
        {
            // Literal run of control + 1 bytes.
            const std::size_t length = control + 1U;
            if (length > static_cast<std::size_t>(in_end - in) ||
                length > static_cast<std::size_t>(out_end - out))
                return false;
            std::memcpy(out, in, length);
            in += length;
            out += length;
            continue;
        }
        // Back reference: length in the top 3 bits (7 means a length byte follows), then a
        // 13-bit distance.
        std::size_t length = control >> 5U;
        if (length == 7)
        {
            if (in == in_end)
                return false;
            length += *in++;
        }
        length += 2;
        if (in == in_end)
            return false;
        const std::size_t distance = ((control & 0x1FU) << 8U) + *in++ + 1U;
        if (distance > static_cast<std::size_t>(out - out_begin) ||
            length > static_cast<std::size_t>(out_end - out))
            return false;
        const char* from = out - distance;
        for (std::size_t k = 0; k < length; ++k) // may overlap: copy forward byte by byte
            *out++ = *from++;
    }
    return out == out_end;
}

ReadResult read_pcd(const std::filesystem::path& path, std::string_view bytes,
                    NonFinitePolicy policy)
{
    PcdHeader header = parse_header(path, bytes);
    const std::size_t point_size = header.point_size();
    ByteCursor cursor(path, bytes, header.data_offset);

    const std::size_t min_bytes = header.data == PcdData::Ascii ? 2 * header.values_per_point() : 1;
    CloudBuilder builder(path, policy, header.attributes,
                         capped_reserve(header.points, cursor.remaining(), min_bytes));
    std::string kind;
    std::vector<char> decompressed;
    switch (header.data)
    {
        case PcdData::Ascii:
            kind = "ascii";
            read_ascii(path, bytes, header, builder);
            break;
        case PcdData::Binary:
        {
            kind = "binary";
            const std::size_t complete = cursor.remaining() / point_size;
            if (header.points > complete)
                fail(path,
                     "file is truncated: data ends in point " + std::to_string(complete) +
                         " of the " + std::to_string(header.points) + " POINTS the header declares",
                     Location::at_byte(header.data_offset + complete * point_size));
            std::size_t offset = 0;
            for (PcdField& field : header.fields)
            {
                field.base = cursor.data() + offset;
                field.stride = point_size;
                offset += field.size * field.count;
            }
            for (std::size_t i = 0; i < header.points; ++i)
                builder.add(binary_point(header.fields, i),
                            Location::at_byte(header.data_offset + i * point_size));
            const std::size_t extra = cursor.remaining() - header.points * point_size;
            if (extra != 0)
                fail(path,
                     std::to_string(extra) + " bytes after the " + std::to_string(header.points) +
                         " POINTS the header declares",
                     Location::at_byte(header.data_offset + header.points * point_size));
            break;
        }
        case PcdData::BinaryCompressed:
        {
            kind = "binary_compressed";
            const std::size_t sizes_offset = cursor.offset();
            const auto compressed_size = cursor.read_le<std::uint32_t>("compressed size");
            const auto uncompressed_size = cursor.read_le<std::uint32_t>("uncompressed size");
            if (header.points > std::numeric_limits<std::uint32_t>::max() / point_size ||
                uncompressed_size != header.points * point_size)
                fail(path,
                     "uncompressed size " + std::to_string(uncompressed_size) +
                         " does not match POINTS " + std::to_string(header.points) + " x " +
                         std::to_string(point_size) + " bytes a point",
                     Location::at_byte(sizes_offset));
            cursor.require(compressed_size, "compressed data");
            // LZF expands at most 264 bytes from a 3-byte reference; anything more is corrupt.
            constexpr std::uint64_t max_ratio = 90;
            if (uncompressed_size > std::uint64_t{compressed_size} * max_ratio + 64)
                fail(path, "compressed data is too small for its uncompressed size",
                     Location::at_byte(sizes_offset));
            decompressed.resize(uncompressed_size);
            if (!lzf_decompress(std::string_view(cursor.data(), compressed_size), decompressed))
                fail(path, "corrupt LZF data", Location::at_byte(cursor.offset()));
            // Structure of arrays: each field's values for all points, one field after another.
            std::size_t offset = 0;
            for (PcdField& field : header.fields)
            {
                field.base = decompressed.data() + offset;
                field.stride = field.size * field.count;
                offset += field.stride * header.points;
            }
            for (std::size_t i = 0; i < header.points; ++i)
                builder.add(binary_point(header.fields, i), Location::at_byte(sizes_offset));
            break;
        }
    }

    ReadResult result;
    result.dropped_points = builder.dropped();
    result.points = builder.take();
    result.description = "PCD " + kind;
    if (header.height > 1)
    {
        result.description += " (organized " + std::to_string(header.width) + " x " +
                              std::to_string(header.height) + ")";
        // A depth image: every point was seen from the viewpoint (PCL's default, the origin,
        // where the header gives none).
        result.points.sensor = header.viewpoint.value_or(Vec3d::Zero());
    }
    return result;
}

} // namespace pointform::detail
