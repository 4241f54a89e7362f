// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// PLY (Stanford polygon file format): ascii, binary_little_endian and binary_big_endian.
// The header is parsed into elements and properties; one driver interprets the `vertex` and
// `face` elements and skips every other element, over either an ascii or a binary value source.

#include "detail_readers.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>

namespace pointform::detail {
namespace {

/// A face index as read (any number, possibly huge or NaN), for an error message. Casting it to
/// an integer type would be undefined behaviour when it is out of range.
std::string format_index(double index)
{
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%.17g", index);
    return buffer;
}

enum class PlyType : std::uint8_t
{
    Int8,
    Uint8,
    Int16,
    Uint16,
    Int32,
    Uint32,
    Float32,
    Float64,
};

std::optional<PlyType> parse_ply_type(std::string_view name)
{
    if (name == "char" || name == "int8")
        return PlyType::Int8;
    if (name == "uchar" || name == "uint8")
        return PlyType::Uint8;
    if (name == "short" || name == "int16")
        return PlyType::Int16;
    if (name == "ushort" || name == "uint16")
        return PlyType::Uint16;
    if (name == "int" || name == "int32")
        return PlyType::Int32;
    if (name == "uint" || name == "uint32")
        return PlyType::Uint32;
    if (name == "float" || name == "float32")
        return PlyType::Float32;
    if (name == "double" || name == "float64")
        return PlyType::Float64;
    return std::nullopt;
}

std::size_t type_size(PlyType type)
{
    switch (type)
    {
        case PlyType::Int8:
        case PlyType::Uint8:
            return 1;
        case PlyType::Int16:
        case PlyType::Uint16:
            return 2;
        case PlyType::Int32:
        case PlyType::Uint32:
        case PlyType::Float32:
            return 4;
        case PlyType::Float64:
            return 8;
    }
    return 0;
}

bool is_floating(PlyType type)
{
    return type == PlyType::Float32 || type == PlyType::Float64;
}

struct PlyProperty
{
    std::string name;
    PlyType type = PlyType::Float32; ///< value type (item type for lists)
    bool is_list = false;
    PlyType count_type = PlyType::Uint8;
    Field field = Field::None; ///< what a vertex property means to us
    bool face_indices = false; ///< the vertex index list of the face element
};

struct PlyElement
{
    std::string name;
    std::uint64_t count = 0;
    std::vector<PlyProperty> properties;
    std::uint64_t line = 0; ///< header line that declares it

    /// Bytes per instance in binary, or 0 if the element has a list property.
    [[nodiscard]] std::size_t fixed_stride() const
    {
        std::size_t stride = 0;
        for (const auto& p : properties)
        {
            if (p.is_list)
                return 0;
            stride += type_size(p.type);
        }
        return stride;
    }

    /// Fewest bytes one instance can take in binary.
    [[nodiscard]] std::size_t min_binary_size() const
    {
        std::size_t size = 0;
        for (const auto& p : properties)
            size += type_size(p.is_list ? p.count_type : p.type);
        return size;
    }
};

enum class PlyEncoding
{
    Ascii,
    BinaryLittleEndian,
    BinaryBigEndian,
};

struct PlyHeader
{
    PlyEncoding encoding = PlyEncoding::Ascii;
    std::vector<PlyElement> elements;
    std::size_t data_offset = 0;       ///< first byte after end_header
    std::uint64_t header_lines = 0;    ///< number of header lines
    std::optional<std::size_t> vertex; ///< index of the vertex element, if any
    std::optional<std::size_t> face;   ///< index of the face element with vertex indices, if any
    AttributeSet attributes;
};

/// Vertex property names we read.
constexpr FieldName vertex_property_names[] = {
    {"x", Field::X},
    {"y", Field::Y},
    {"z", Field::Z},
    {"nx", Field::Nx},
    {"normal_x", Field::Nx},
    {"ny", Field::Ny},
    {"normal_y", Field::Ny},
    {"nz", Field::Nz},
    {"normal_z", Field::Nz},
    {"red", Field::Red},
    {"diffuse_red", Field::Red},
    {"r", Field::Red},
    {"green", Field::Green},
    {"diffuse_green", Field::Green},
    {"g", Field::Green},
    {"blue", Field::Blue},
    {"diffuse_blue", Field::Blue},
    {"b", Field::Blue},
    {"radius", Field::Radius},
};

PlyHeader parse_header(const std::filesystem::path& path, std::string_view bytes)
{
    PlyHeader header;
    LineReader lines(bytes);
    std::string_view line;
    if (!lines.next(line) || trim(line) != "ply")
        fail(path, "not a PLY file (the first line is not 'ply')", Location::at_line(1));

    bool have_format = false;
    bool ended = false;
    while (!ended && lines.next(line))
    {
        const Location here = Location::at_line(lines.line_number());
        std::string_view rest = line;
        std::string_view keyword;
        if (!next_token(rest, keyword))
            continue;
        if (keyword == "comment" || keyword == "obj_info")
            continue;
        if (keyword == "end_header")
        {
            ended = true;
        }
        else if (keyword == "format")
        {
            std::string_view encoding;
            std::string_view version;
            if (!next_token(rest, encoding) || !next_token(rest, version))
                fail(path, "malformed format line", here);
            if (encoding == "ascii")
                header.encoding = PlyEncoding::Ascii;
            else if (encoding == "binary_little_endian")
                header.encoding = PlyEncoding::BinaryLittleEndian;
            else if (encoding == "binary_big_endian")
                header.encoding = PlyEncoding::BinaryBigEndian;
            else
                fail(path, "unknown PLY format " + quote(encoding), here);
            have_format = true;
        }
        else if (keyword == "element")
        {
            std::string_view name;
            std::string_view count;
            PlyElement element;
            if (!next_token(rest, name) || !next_token(rest, count) ||
                !parse_integer(count, element.count))
                fail(path, "malformed element line (expected: element <name> <count>)", here);
            element.name = std::string(name);
            element.line = lines.line_number();
            header.elements.push_back(std::move(element));
        }
        else if (keyword == "property")
        {
            if (header.elements.empty())
                fail(path, "property declared before any element", here);
            PlyProperty property;
            std::string_view type;
            std::string_view name;
            if (!next_token(rest, type))
                fail(path, "malformed property line", here);
            if (type == "list")
            {
                std::string_view count_type;
                std::string_view item_type;
                if (!next_token(rest, count_type) || !next_token(rest, item_type) ||
                    !next_token(rest, name))
                    fail(path,
                         "malformed list property (expected: property list <count type> "
                         "<item type> <name>)",
                         here);
                const auto ct = parse_ply_type(count_type);
                const auto it = parse_ply_type(item_type);
                if (!ct || !it)
                    fail(path, "unknown property type in list " + quote(line), here);
                if (is_floating(*ct))
                    fail(path, "list count type must be an integer type", here);
                property.is_list = true;
                property.count_type = *ct;
                property.type = *it;
            }
            else
            {
                const auto t = parse_ply_type(type);
                if (!t || !next_token(rest, name))
                    fail(path, "unknown property type " + quote(type), here);
                property.type = *t;
            }
            property.name = std::string(name);
            header.elements.back().properties.push_back(std::move(property));
        }
        else
        {
            fail(path, "unknown header line " + quote(line), here);
        }
    }
    if (!ended)
        fail(path, "header has no end_header line", Location::at_line(lines.line_number()));
    if (!have_format)
        fail(path, "header has no format line", Location::at_line(lines.line_number()));
    header.data_offset = lines.offset();
    header.header_lines = lines.line_number();

    for (std::size_t e = 0; e < header.elements.size(); ++e)
    {
        PlyElement& element = header.elements[e];
        if (element.name == "vertex" && !header.vertex)
        {
            FieldSet found;
            for (auto& property : element.properties)
            {
                if (property.is_list)
                    continue;
                property.field = field_named(property.name, vertex_property_names);
                found.add(property.field);
            }
            if (!found.has_position())
                fail(path, "vertex element has no x, y and z properties",
                     Location::at_line(element.line));
            header.attributes = found.attributes();
            header.vertex = e;
        }
        else if (element.name == "face" && !header.face)
        {
            for (auto& property : element.properties)
            {
                if (property.name == "vertex_indices" || property.name == "vertex_index")
                {
                    if (!property.is_list)
                        fail(path, "face property " + property.name + " is not a list",
                             Location::at_line(element.line));
                    if (is_floating(property.type))
                        fail(path, "face indices must have an integer type",
                             Location::at_line(element.line));
                    property.face_indices = true;
                    header.face = e;
                    break;
                }
            }
        }
    }
    if (header.face && header.elements[*header.face].count > 0)
    {
        if (!header.vertex)
            fail(path, "file has faces but no vertex element",
                 Location::at_line(header.elements[*header.face].line));
        if (header.elements[*header.vertex].count > std::numeric_limits<std::uint32_t>::max())
            fail(path, "too many vertices for 32-bit face indices",
                 Location::at_line(header.elements[*header.vertex].line));
    }
    return header;
}

std::uint8_t to_color(double value, PlyType type)
{
    if (!(value > 0.0)) // also catches NaN
        return 0;
    if (is_floating(type))
        return static_cast<std::uint8_t>(std::lround(std::min(value, 1.0) * 255.0));
    if (type == PlyType::Uint16 || type == PlyType::Int16)
        return static_cast<std::uint8_t>(static_cast<unsigned>(std::min(value, 65535.0)) >> 8U);
    return static_cast<std::uint8_t>(std::min(value, 255.0));
}

/// Stores a vertex property's value in its point (colours converted from their type).
void set_property(PointRecord& point, const PlyProperty& property, double value)
{
    set_field(point, property.field,
              is_color(property.field) ? to_color(value, property.type) : value);
}

/// A binary PLY scalar of `type` at p, as a double.
double load_scalar(const char* p, PlyType type, ByteOrder order)
{
    switch (type)
    {
        case PlyType::Int8:
            return load<std::int8_t>(p, order);
        case PlyType::Uint8:
            return load<std::uint8_t>(p, order);
        case PlyType::Int16:
            return load<std::int16_t>(p, order);
        case PlyType::Uint16:
            return load<std::uint16_t>(p, order);
        case PlyType::Int32:
            return load<std::int32_t>(p, order);
        case PlyType::Uint32:
            return load<std::uint32_t>(p, order);
        case PlyType::Float32:
            return static_cast<double>(load<float>(p, order));
        case PlyType::Float64:
            return load<double>(p, order);
    }
    return 0.0;
}

/// Values of a binary body, read through a ByteCursor in the file's byte order.
class BinarySource
{
public:
    BinarySource(const std::filesystem::path& path, std::string_view bytes, std::size_t offset,
                 ByteOrder order)
        : cursor_(path, bytes, offset), order_(order)
    {}

    void begin(const PlyElement& element, std::uint64_t index)
    {
        element_ = &element;
        index_ = index;
        start_ = cursor_.offset();
    }
    void end() const {}
    [[nodiscard]] Location where() const { return Location::at_byte(start_); }

    double scalar(PlyType type)
    {
        need(type_size(type));
        const double value = load_scalar(cursor_.data(), type, order_);
        cursor_.seek(cursor_.offset() + type_size(type));
        return value;
    }

    /// Reads all of a vertex element whose instances have one size (no lists) at once, in
    /// parallel; false (nothing read) when its instances do not have one size or the file ends
    /// inside it (the reading one by one then says where).
    bool read_fixed_size(const PlyElement& element, CloudBuilder& builder)
    {
        const std::size_t stride = element.fixed_stride();
        if (stride == 0 || element.count > cursor_.remaining() / stride)
            return false;
        std::vector<std::size_t> offsets;
        std::size_t offset = 0;
        for (const auto& property : element.properties)
        {
            offsets.push_back(offset);
            offset += type_size(property.type);
        }
        const char* base = cursor_.data();
        const std::size_t start = cursor_.offset();
        const auto count = static_cast<std::size_t>(element.count);
        // Where x, y and z are (the last of each, as set_field() keeps).
        std::array<std::optional<std::size_t>, 3> axis;
        for (std::size_t k = 0; k < offsets.size(); ++k)
        {
            const Field field = element.properties[k].field;
            if (field == Field::X || field == Field::Y || field == Field::Z)
                axis[static_cast<std::size_t>(field) - static_cast<std::size_t>(Field::X)] = k;
        }
        builder.add_all(
            count,
            [&](std::size_t i) {
                Vec3d position = Vec3d::Zero();
                for (std::size_t a = 0; a < 3; ++a)
                    if (axis[a])
                        position[static_cast<Eigen::Index>(a)] =
                            load_scalar(base + i * stride + offsets[*axis[a]],
                                        element.properties[*axis[a]].type, order_);
                return position;
            },
            [&](std::size_t i, PointRecord& point) {
                point = PointRecord{};
                const char* p = base + i * stride;
                for (std::size_t k = 0; k < offsets.size(); ++k)
                {
                    const PlyProperty& property = element.properties[k];
                    set_property(point, property,
                                 load_scalar(p + offsets[k], property.type, order_));
                }
            },
            [&](std::size_t i) { return Location::at_byte(start + i * stride); });
        cursor_.seek(start + count * stride);
        return true;
    }

    void skip_values(PlyType type, std::uint64_t n)
    {
        const std::uint64_t size = type_size(type);
        if (n > cursor_.remaining() / size)
            truncated();
        cursor_.seek(cursor_.offset() + static_cast<std::size_t>(n * size));
    }

    void skip_element(const PlyElement& element)
    {
        const std::size_t stride = element.fixed_stride();
        if (stride > 0)
        {
            begin(element, 0);
            if (element.count > cursor_.remaining() / stride)
            {
                index_ = cursor_.remaining() / stride;
                cursor_.seek(cursor_.offset() + static_cast<std::size_t>(index_ * stride));
                truncated();
            }
            cursor_.seek(cursor_.offset() + static_cast<std::size_t>(element.count * stride));
            return;
        }
        for (std::uint64_t i = 0; i < element.count; ++i)
        {
            begin(element, i);
            for (const auto& property : element.properties)
                skip_values(property.type, property.is_list ? list_count(property) : 1);
        }
    }

    std::uint64_t list_count(const PlyProperty& property)
    {
        const std::size_t at = cursor_.offset();
        const double n = scalar(property.count_type);
        if (n < 0.0)
            fail(cursor_.path(),
                 "negative list length in " + element_->name + " " + std::to_string(index_),
                 Location::at_byte(at));
        return static_cast<std::uint64_t>(n);
    }

    /// Checks that the whole body was consumed.
    void finish() const
    {
        if (cursor_.remaining() != 0)
            fail(cursor_.path(),
                 std::to_string(cursor_.remaining()) +
                     " bytes of data after the last element (the header counts do not match "
                     "the data)",
                 Location::at_byte(cursor_.offset()));
    }

    [[nodiscard]] std::size_t remaining() const { return cursor_.remaining(); }
    [[nodiscard]] const std::filesystem::path& path() const { return cursor_.path(); }

private:
    void need(std::size_t n) const
    {
        if (n > cursor_.remaining())
            truncated();
    }

    [[noreturn]] void truncated() const
    {
        fail(cursor_.path(),
             "file is truncated: data ends in " + element_->name + " " + std::to_string(index_) +
                 " of " + std::to_string(element_->count) + " declared by the header",
             Location::at_byte(cursor_.offset()));
    }

    ByteCursor cursor_;
    ByteOrder order_;
    const PlyElement* element_ = nullptr;
    std::uint64_t index_ = 0;
    std::size_t start_ = 0;
};

/// Values of an ascii body: one element instance a line, values separated by white space.
class AsciiSource
{
public:
    AsciiSource(const std::filesystem::path& path, std::string_view bytes, std::size_t offset,
                std::uint64_t header_lines)
        : path_(&path), lines_(bytes, offset, header_lines)
    {}

    void begin(const PlyElement& element, std::uint64_t index)
    {
        element_ = &element;
        index_ = index;
        if (!next_data_line(rest_))
            fail(*path_,
                 "file ends after " + std::to_string(index) + " of the " +
                     std::to_string(element.count) + " " + element.name +
                     " elements the header declares",
                 Location::at_line(lines_.line_number() + 1));
    }

    void end()
    {
        std::string_view extra;
        if (next_token(rest_, extra))
            fail(*path_,
                 "line has more values than the header declares for a " + element_->name +
                     " (unexpected " + quote(extra) + ")",
                 where());
    }

    [[nodiscard]] Location where() const { return Location::at_line(lines_.line_number()); }

    double scalar(PlyType /*type*/)
    {
        std::string_view token;
        if (!next_token(rest_, token))
            fail(*path_, "line has fewer values than the header declares for a " + element_->name,
                 where());
        double value = 0.0;
        if (!parse_double(token, value))
            fail(*path_, "malformed number " + quote(token), where());
        return value;
    }

    void skip_values(PlyType type, std::uint64_t n)
    {
        for (std::uint64_t i = 0; i < n; ++i)
            (void)scalar(type);
    }

    std::uint64_t list_count(const PlyProperty& property)
    {
        const double n = scalar(property.count_type);
        if (n < 0.0 || n != std::floor(n) || n > 1e9)
            fail(*path_, "invalid list length in " + element_->name, where());
        return static_cast<std::uint64_t>(n);
    }

    void skip_element(const PlyElement& element)
    {
        std::string_view line;
        for (std::uint64_t i = 0; i < element.count; ++i)
            if (!next_data_line(line))
                fail(*path_,
                     "file ends after " + std::to_string(i) + " of the " +
                         std::to_string(element.count) + " " + element.name +
                         " elements the header declares",
                     Location::at_line(lines_.line_number() + 1));
    }

    void finish()
    {
        std::string_view line;
        if (next_data_line(line))
            fail(*path_,
                 "more data than the header declares (the element counts do not match the data)",
                 where());
    }

    [[nodiscard]] std::size_t remaining() const { return lines_.remaining(); }
    [[nodiscard]] const std::filesystem::path& path() const { return *path_; }

private:
    /// Next line that is not blank.
    bool next_data_line(std::string_view& line)
    {
        while (lines_.next(line))
            if (!trim(line).empty())
                return true;
        return false;
    }

    const std::filesystem::path* path_;
    LineReader lines_;
    std::string_view rest_;
    const PlyElement* element_ = nullptr;
    std::uint64_t index_ = 0;
};

template <typename Source>
void read_vertices(Source& source, const PlyElement& element, CloudBuilder& builder)
{
    if constexpr (std::is_same_v<Source, BinarySource>)
        if (source.read_fixed_size(element, builder))
            return;
    for (std::uint64_t i = 0; i < element.count; ++i)
    {
        source.begin(element, i);
        const Location where = source.where();
        PointRecord point;
        for (const auto& property : element.properties)
        {
            if (property.is_list)
            {
                source.skip_values(property.type, source.list_count(property));
                continue;
            }
            set_property(point, property, source.scalar(property.type));
        }
        source.end();
        builder.add(point, where);
    }
}

template <typename Source>
void read_faces(Source& source, const PlyElement& element, std::uint64_t vertex_count,
                std::vector<Triangle>& triangles)
{
    std::vector<std::uint32_t> polygon;
    for (std::uint64_t i = 0; i < element.count; ++i)
    {
        source.begin(element, i);
        for (const auto& property : element.properties)
        {
            if (!property.is_list)
            {
                (void)source.scalar(property.type);
                continue;
            }
            const std::uint64_t n = source.list_count(property);
            if (!property.face_indices)
            {
                source.skip_values(property.type, n);
                continue;
            }
            polygon.clear();
            for (std::uint64_t k = 0; k < n; ++k)
            {
                const double index = source.scalar(property.type);
                if (!(index >= 0.0) || index >= static_cast<double>(vertex_count))
                    fail(source.path(),
                         "face " + std::to_string(i) + " refers to vertex " + format_index(index) +
                             " but the file has " + std::to_string(vertex_count) + " vertices",
                         source.where());
                polygon.push_back(static_cast<std::uint32_t>(index));
            }
        }
        source.end();
        append_fan(triangles, polygon);
    }
}

template <typename Source>
ReadResult read_body(Source& source, const PlyHeader& header, NonFinitePolicy policy,
                     std::size_t ascii_min_line)
{
    const auto min_size = [&](const PlyElement& element) {
        return ascii_min_line > 0 ? ascii_min_line
                                  : std::max<std::size_t>(1, element.min_binary_size());
    };
    const PlyElement* vertex = header.vertex ? &header.elements[*header.vertex] : nullptr;
    const PlyElement* face = header.face ? &header.elements[*header.face] : nullptr;
    const std::uint64_t vertex_count = vertex != nullptr ? vertex->count : 0;
    CloudBuilder builder(source.path(), policy, header.attributes,
                         vertex != nullptr
                             ? capped_reserve(vertex_count, source.remaining(), min_size(*vertex))
                             : 0);
    ReadResult result;
    if (face != nullptr)
        result.triangles.reserve(capped_reserve(face->count, source.remaining(), min_size(*face)));

    for (const auto& element : header.elements)
    {
        if (&element == vertex)
            read_vertices(source, element, builder);
        else if (&element == face)
            read_faces(source, element, vertex_count, result.triangles);
        else
            source.skip_element(element);
    }
    source.finish();
    builder.check_no_drops_with_faces(!result.triangles.empty());
    result.dropped_points = builder.dropped();
    result.points = builder.take();
    return result;
}

/// Whether binary files need doubles for the world positions: not when the origin is zero, nor
/// when every world coordinate is a float (a float input read with an origin is such a cloud:
/// its floats go back out as they came in, at half the size).
bool needs_world_double(const PointCloudView& cloud)
{
    if (cloud.origin.isZero(0.0))
        return false;
    std::atomic<bool> exact{true};
    parallel_blocks(cloud.size(), 1U << 16U, [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end && exact.load(std::memory_order_relaxed); ++i)
        {
            const Vec3d w = cloud.world(i);
            if (w.cast<float>().cast<double>() != w)
                exact.store(false, std::memory_order_relaxed);
        }
    });
    return !exact.load();
}

void write_header(OutputBuffer& out, const PointCloudView& cloud, std::size_t faces, bool ascii,
                  bool world_double)
{
    out.write("ply\nformat ");
    out.write(ascii ? "ascii 1.0\n" : "binary_little_endian 1.0\n");
    out.write("comment written by pointform\nelement vertex ");
    out.write_integer(cloud.size());
    out.write(world_double ? "\nproperty double x\nproperty double y\nproperty double z\n"
                           : "\nproperty float x\nproperty float y\nproperty float z\n");
    if (cloud.has_normals())
        out.write("property float nx\nproperty float ny\nproperty float nz\n");
    if (cloud.has_colors())
        out.write("property uchar red\nproperty uchar green\nproperty uchar blue\n");
    if (cloud.has_radii())
        out.write("property float radius\n");
    if (faces > 0)
    {
        out.write("element face ");
        out.write_integer(faces);
        const bool fits_int = cloud.size() <= std::size_t{std::numeric_limits<std::int32_t>::max()};
        out.write(fits_int ? "\nproperty list uchar int vertex_indices\n"
                           : "\nproperty list uchar uint vertex_indices\n");
    }
    out.write("end_header\n");
}

/// The vertex element of a binary PLY file, in parallel (see write_header() for the layout).
void write_binary_vertices(OutputBuffer& out, const PointCloudView& cloud, bool world_double)
{
    const std::size_t size = (world_double ? 24U : 12U) + (cloud.has_normals() ? 12U : 0U) +
                             (cloud.has_colors() ? 3U : 0U) + (cloud.has_radii() ? 4U : 0U);
    const auto put = [](char*& p, auto value) {
        if constexpr (native_byte_order != ByteOrder::Little)
            value = byte_swap(value);
        std::memcpy(p, &value, sizeof(value));
        p += sizeof(value);
    };
    out.write_items(cloud.size(), size, [&](std::size_t i, char* p) {
        if (world_double)
        {
            const Vec3d w = cloud.world(i);
            put(p, w.x());
            put(p, w.y());
            put(p, w.z());
        }
        else if (!cloud.origin.isZero(0.0))
        {
            const Vec3f v = cloud.world(i).cast<float>(); // exact: see needs_world_double()
            put(p, v.x());
            put(p, v.y());
            put(p, v.z());
        }
        else
        {
            const Vec3f& v = cloud.positions[i];
            put(p, v.x());
            put(p, v.y());
            put(p, v.z());
        }
        if (cloud.has_normals())
        {
            const Vec3f& n = cloud.normals[i];
            put(p, n.x());
            put(p, n.y());
            put(p, n.z());
        }
        if (cloud.has_colors())
        {
            const Color c = cloud.colors[i];
            put(p, c.r);
            put(p, c.g);
            put(p, c.b);
        }
        if (cloud.has_radii())
            put(p, cloud.radii[i]);
    });
}

} // namespace

ReadResult read_ply(const std::filesystem::path& path, std::string_view bytes,
                    NonFinitePolicy policy)
{
    const PlyHeader header = parse_header(path, bytes);
    ReadResult result;
    if (header.encoding == PlyEncoding::Ascii)
    {
        AsciiSource source(path, bytes, header.data_offset, header.header_lines);
        constexpr std::size_t min_line = 2; // one digit and a newline
        result = read_body(source, header, policy, min_line);
        result.description = "PLY ascii";
    }
    else
    {
        const bool little = header.encoding == PlyEncoding::BinaryLittleEndian;
        BinarySource source(path, bytes, header.data_offset,
                            little ? ByteOrder::Little : ByteOrder::Big);
        result = read_body(source, header, policy, 0);
        result.description = little ? "PLY binary_little_endian" : "PLY binary_big_endian";
    }
    return result;
}

void write_ply(OutputBuffer& out, const PointCloudView& cloud, std::span<const Triangle> triangles,
               bool ascii, int precision)
{
    // Text keeps the double world values (its numbers are read back as doubles).
    const bool world_double = ascii ? !cloud.origin.isZero(0.0) : needs_world_double(cloud);
    write_header(out, cloud, triangles.size(), ascii, world_double);
    if (!ascii)
        write_binary_vertices(out, cloud, world_double);
    for (std::size_t i = 0; ascii && i < cloud.size(); ++i)
    {
        write_world_text(out, cloud, i, precision);
        if (cloud.has_normals())
            for (int axis = 0; axis < 3; ++axis)
            {
                out.put(' ');
                out.write_number(cloud.normals[i][axis]);
            }
        if (cloud.has_colors())
        {
            const Color c = cloud.colors[i];
            for (const std::uint8_t channel : {c.r, c.g, c.b})
            {
                out.put(' ');
                out.write_integer(channel);
            }
        }
        if (cloud.has_radii())
        {
            out.put(' ');
            out.write_number(cloud.radii[i]);
        }
        out.put('\n');
    }
    for (const Triangle& t : triangles)
    {
        if (ascii)
        {
            write_triangle_text(out, t);
        }
        else
        {
            out.put(3);
            out.write_le(t[0]);
            out.write_le(t[1]);
            out.write_le(t[2]);
        }
    }
}

} // namespace pointform::detail
