// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// OFF (Object File Format) and its [ST][C][N]OFF variants, ascii only. Comments start with '#'.

#include "detail_readers.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace pointform::detail {
namespace {

struct OffVariant
{
    bool normals = false;
    bool colors = false;
    bool texture = false;
};

/// Parses the keyword: [ST][C][N]OFF (C and N accepted in either order).
std::optional<OffVariant> parse_keyword(std::string_view keyword)
{
    if (!keyword.ends_with("OFF"))
        return std::nullopt;
    keyword.remove_suffix(3);
    OffVariant variant;
    if (keyword.starts_with("ST"))
    {
        variant.texture = true;
        keyword.remove_prefix(2);
    }
    for (const char c : keyword)
    {
        if (c == 'C' && !variant.colors)
            variant.colors = true;
        else if (c == 'N' && !variant.normals)
            variant.normals = true;
        else
            return std::nullopt;
    }
    return variant;
}

bool looks_fractional(std::string_view token)
{
    return token.find_first_of(".eE") != std::string_view::npos;
}

std::uint8_t to_color(double value, bool fractional)
{
    if (!(value > 0.0))
        return 0;
    const double scaled = fractional ? std::min(value, 1.0) * 255.0 : std::min(value, 255.0);
    return static_cast<std::uint8_t>(std::lround(scaled));
}

/// Reads the non-blank lines of an OFF file, with '#' comments removed.
class OffLines
{
public:
    explicit OffLines(std::string_view bytes) : lines_(bytes) {}

    bool next(std::string_view& content)
    {
        std::string_view line;
        while (lines_.next(line))
        {
            const std::size_t hash = line.find('#');
            content = trim(line.substr(0, hash));
            if (!content.empty())
                return true;
        }
        return false;
    }

    [[nodiscard]] Location where() const { return Location::at_line(lines_.line_number()); }
    [[nodiscard]] Location after_end() const { return Location::at_line(lines_.line_number() + 1); }

private:
    LineReader lines_;
};

} // namespace

ReadResult read_off(const std::filesystem::path& path, std::string_view bytes,
                    NonFinitePolicy policy)
{
    OffLines lines(bytes);
    std::string_view line;
    if (!lines.next(line))
        fail(path, "file has no OFF keyword (only blank lines or comments)");
    std::string_view rest = line;
    std::string_view keyword;
    (void)next_token(rest, keyword);
    const auto variant = parse_keyword(keyword);
    if (!variant)
        fail(path, "not an OFF file (first word is " + quote(keyword) + ")", lines.where());

    // The counts may follow the keyword on the same line.
    std::string_view counts = trim(rest);
    if (counts == "BINARY")
        fail(path, "binary OFF is not supported", lines.where());
    if (counts.empty())
    {
        if (!lines.next(line))
            fail(path, "file ends before the vertex and face counts", lines.after_end());
        counts = line;
    }
    std::uint64_t vertex_count = 0;
    std::uint64_t face_count = 0;
    std::string_view token;
    if (!next_token(counts, token) || !parse_integer(token, vertex_count) ||
        !next_token(counts, token) || !parse_integer(token, face_count))
        fail(path, "expected the vertex and face counts", lines.where());
    if (vertex_count > std::numeric_limits<std::uint32_t>::max())
        fail(path, "too many vertices for 32-bit face indices", lines.where());

    constexpr std::size_t min_vertex_line = 6; // "0 0 0\n"
    CloudBuilder builder(path, policy, {.normals = variant->normals, .colors = variant->colors},
                         capped_reserve(vertex_count, bytes.size(), min_vertex_line));
    const std::size_t required = 3 + (variant->normals ? 3 : 0);
    std::string_view values[16];
    for (std::uint64_t i = 0; i < vertex_count; ++i)
    {
        if (!lines.next(line))
            fail(path,
                 "file ends after " + std::to_string(i) + " of the " +
                     std::to_string(vertex_count) + " vertices the header declares",
                 lines.after_end());
        std::size_t n = 0;
        rest = line;
        while (n < std::size(values) && next_token(rest, values[n]))
            ++n;
        if (n < required)
            fail(path,
                 "vertex line has " + std::to_string(n) + " values, expected at least " +
                     std::to_string(required),
                 lines.where());
        double v[6] = {};
        for (std::size_t k = 0; k < required; ++k)
            if (!parse_double(values[k], v[k]))
                fail(path, "malformed number " + quote(values[k]), lines.where());
        PointRecord point;
        point.position = {v[0], v[1], v[2]};
        if (variant->normals)
            point.normal =
                Vec3f(static_cast<float>(v[3]), static_cast<float>(v[4]), static_cast<float>(v[5]));
        if (variant->colors)
        {
            const std::size_t trailing = variant->texture ? 2 : 0;
            const std::size_t color_values = n >= required + trailing ? n - required - trailing : 0;
            if (color_values != 3 && color_values != 4)
                fail(path, "COFF vertex line needs r g b [a] after the coordinates", lines.where());
            double rgb[3] = {};
            bool fractional = false;
            for (std::size_t k = 0; k < 3; ++k)
            {
                if (!parse_double(values[required + k], rgb[k]))
                    fail(path, "malformed number " + quote(values[required + k]), lines.where());
                fractional = fractional || looks_fractional(values[required + k]);
            }
            point.color = {to_color(rgb[0], fractional), to_color(rgb[1], fractional),
                           to_color(rgb[2], fractional)};
        }
        builder.add(point, lines.where());
    }

    ReadResult result;
    constexpr std::size_t min_face_line = 8; // "3 0 1 2\n"
    result.triangles.reserve(capped_reserve(face_count, bytes.size(), min_face_line));
    std::vector<std::uint32_t> polygon;
    for (std::uint64_t f = 0; f < face_count; ++f)
    {
        if (!lines.next(line))
            fail(path,
                 "file ends after " + std::to_string(f) + " of the " + std::to_string(face_count) +
                     " faces the header declares",
                 lines.after_end());
        rest = line;
        std::uint64_t n = 0;
        if (!next_token(rest, token) || !parse_integer(token, n))
            fail(path, "face line must start with its vertex count, found " + quote(token),
                 lines.where());
        polygon.clear();
        for (std::uint64_t k = 0; k < n; ++k)
        {
            std::int64_t index = 0;
            if (!next_token(rest, token))
                fail(path,
                     "face line declares " + std::to_string(n) + " vertices but has " +
                         std::to_string(k),
                     lines.where());
            if (!parse_integer(token, index))
                fail(path, "malformed vertex index " + quote(token), lines.where());
            if (index < 0 || static_cast<std::uint64_t>(index) >= vertex_count)
                fail(path,
                     "face " + std::to_string(f) + " refers to vertex " + std::to_string(index) +
                         " but the file has " + std::to_string(vertex_count) + " vertices",
                     lines.where());
            polygon.push_back(static_cast<std::uint32_t>(index));
        }
        append_fan(result.triangles, polygon);
    }

    builder.check_no_drops_with_faces(!result.triangles.empty());
    result.dropped_points = builder.dropped();
    result.points = builder.take();
    result.description = std::string(keyword);
    return result;
}

void write_off(OutputBuffer& out, const TriMesh& mesh, int precision)
{
    out.write("OFF\n");
    out.write_integer(mesh.vertex_count());
    out.put(' ');
    out.write_integer(mesh.face_count());
    out.write(" 0\n");
    for (std::size_t i = 0; i < mesh.vertex_count(); ++i)
    {
        write_world_text(out, mesh.vertices, i, precision);
        out.put('\n');
    }
    for (const Triangle& t : mesh.triangles)
        write_triangle_text(out, t);
}

} // namespace pointform::detail
