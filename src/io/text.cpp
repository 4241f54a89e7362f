// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// Column text point sets: .xyz .pts .csv .txt .pwn. Values are separated by white space or
// commas; the layout comes from a header line of column names if there is one, else from the
// number of columns (3: x y z, 6: x y z nx ny nz, 7: x y z intensity r g b for PTS).

#include "detail_readers.h"

#include <algorithm>
#include <cmath>

namespace pointform::detail {
namespace {

struct Layout
{
    std::vector<Field> columns; ///< what each column holds (Field::None: ignored)
    AttributeSet attributes;
    std::string description;
};

constexpr bool separators_include_commas = true;

bool is_comment(std::string_view line)
{
    return line.starts_with('#') || line.starts_with("//");
}

std::size_t count_tokens(std::string_view line)
{
    std::size_t n = 0;
    std::string_view token;
    while (next_token(line, token, separators_include_commas))
        ++n;
    return n;
}

bool all_numbers(std::string_view line)
{
    std::string_view token;
    double value = 0.0;
    while (next_token(line, token, separators_include_commas))
        if (!parse_double(token, value))
            return false;
    return true;
}

/// Column names (lower case) we read.
constexpr FieldName column_names[] = {
    {"x", Field::X},        {"//x", Field::X},         {"y", Field::Y},
    {"z", Field::Z},        {"nx", Field::Nx},         {"normal_x", Field::Nx},
    {"normalx", Field::Nx}, {"ny", Field::Ny},         {"normal_y", Field::Ny},
    {"normaly", Field::Ny}, {"nz", Field::Nz},         {"normal_z", Field::Nz},
    {"normalz", Field::Nz}, {"r", Field::Red},         {"red", Field::Red},
    {"g", Field::Green},    {"green", Field::Green},   {"b", Field::Blue},
    {"blue", Field::Blue},  {"radius", Field::Radius},
};

Field column_from_name(std::string_view raw)
{
    while (!raw.empty() && (raw.front() == '"' || raw.front() == '\''))
        raw.remove_prefix(1);
    while (!raw.empty() && (raw.back() == '"' || raw.back() == '\''))
        raw.remove_suffix(1);
    return field_named(to_lower(raw), column_names);
}

Layout layout_from_names(const std::filesystem::path& path, std::string_view line, Location where)
{
    Layout layout;
    std::string_view token;
    while (next_token(line, token, separators_include_commas))
        layout.columns.push_back(column_from_name(token));
    FieldSet found;
    for (const Field field : layout.columns)
        found.add(field);
    if (!found.has_position())
        fail(path,
             "first line is neither numbers nor a header naming x, y and z columns: " + quote(line),
             where);
    layout.attributes = found.attributes();
    layout.description =
        "text with a header line, " + std::to_string(layout.columns.size()) + " columns";
    return layout;
}

/// True if the values 5 to 7 of a 7-column line are integers in [0, 255], as PTS colors are.
bool looks_like_pts_colors(std::string_view line)
{
    std::string_view token;
    for (int i = 0; i < 7 && next_token(line, token, separators_include_commas); ++i)
    {
        int value = 0;
        if (i >= 4 && (!parse_integer(token, value) || value < 0 || value > 255))
            return false;
    }
    return true;
}

Layout layout_from_count(const std::filesystem::path& path, std::string_view line, std::size_t n,
                         bool pts_hint, Location where)
{
    if (n < 3)
        fail(path, "expected at least 3 values (x y z) on a line, found " + std::to_string(n),
             where);
    Layout layout;
    layout.columns.assign(n, Field::None);
    layout.columns[0] = Field::X;
    layout.columns[1] = Field::Y;
    layout.columns[2] = Field::Z;
    if (n == 7 && (pts_hint || looks_like_pts_colors(line)))
    {
        layout.columns[4] = Field::Red;
        layout.columns[5] = Field::Green;
        layout.columns[6] = Field::Blue;
        layout.attributes.colors = true;
        layout.description = "text, 7 columns (x y z intensity r g b)";
    }
    else if (n >= 6)
    {
        layout.columns[3] = Field::Nx;
        layout.columns[4] = Field::Ny;
        layout.columns[5] = Field::Nz;
        layout.attributes.normals = true;
        layout.description =
            "text, " + std::to_string(n) + " columns (x y z nx ny nz" + (n > 6 ? " ...)" : ")");
    }
    else
    {
        layout.description =
            "text, " + std::to_string(n) + " columns (x y z" + (n > 3 ? " ...)" : ")");
    }
    return layout;
}

std::uint8_t to_color(double value)
{
    if (!(value > 0.0))
        return 0;
    return static_cast<std::uint8_t>(std::lround(std::min(value, 255.0)));
}

} // namespace

ReadResult read_text(const std::filesystem::path& path, std::string_view bytes,
                     NonFinitePolicy policy, bool pts_hint)
{
    LineReader lines(bytes);
    std::string_view line;
    const auto next_data_line = [&]() {
        while (lines.next(line))
        {
            const std::string_view content = trim(line);
            if (!content.empty() && !is_comment(content))
                return true;
        }
        return false;
    };

    if (!next_data_line())
        fail(path, "file has no data lines (only blank lines or comments)");

    // A single integer first: the point count of a PTS file.
    std::optional<std::uint64_t> declared_count;
    std::uint64_t count_line = 0;
    std::uint64_t value = 0;
    if (count_tokens(line) == 1 && parse_integer(trim(line), value))
    {
        declared_count = value;
        count_line = lines.line_number();
        if (!next_data_line())
        {
            if (value != 0)
                fail(path,
                     "count line declares " + std::to_string(value) + " points but none follow",
                     Location::at_line(count_line));
            ReadResult empty;
            empty.description = "text (PTS count line, no points)";
            return empty;
        }
    }

    Layout layout;
    bool first_is_data = true;
    if (all_numbers(line))
    {
        layout = layout_from_count(path, line, count_tokens(line), pts_hint,
                                   Location::at_line(lines.line_number()));
    }
    else
    {
        layout = layout_from_names(path, line, Location::at_line(lines.line_number()));
        first_is_data = false;
    }
    const std::size_t columns = layout.columns.size();

    const std::size_t estimate = bytes.size() / std::max<std::size_t>(line.size() + 1, 6);
    CloudBuilder builder(path, policy, layout.attributes, estimate + estimate / 8);

    std::uint64_t records = 0;
    bool have_line = first_is_data || next_data_line();
    while (have_line)
    {
        const Location where = Location::at_line(lines.line_number());
        PointRecord point;
        std::string_view rest = line;
        std::string_view token;
        std::size_t k = 0;
        while (next_token(rest, token, separators_include_commas))
        {
            if (k == columns)
                fail(path,
                     "line has " + std::to_string(count_tokens(line)) + " values, expected " +
                         std::to_string(columns),
                     where);
            double v = 0.0;
            if (!parse_double(token, v))
                fail(path, "malformed number " + quote(token), where);
            const Field field = layout.columns[k];
            set_field(point, field, is_color(field) ? to_color(v) : v);
            ++k;
        }
        if (k != columns)
            fail(path,
                 "line has " + std::to_string(k) + " values, expected " + std::to_string(columns),
                 where);
        builder.add(point, where);
        ++records;
        have_line = next_data_line();
    }

    if (declared_count && *declared_count != records)
        fail(path,
             "count line declares " + std::to_string(*declared_count) +
                 " points but the file has " + std::to_string(records),
             Location::at_line(count_line));

    ReadResult result;
    result.dropped_points = builder.dropped();
    result.points = builder.take();
    result.description = layout.description;
    return result;
}

void write_xyz(OutputBuffer& out, const PointCloudView& cloud, int precision)
{
    for (std::size_t i = 0; i < cloud.size(); ++i)
    {
        write_world_text(out, cloud, i, precision);
        if (cloud.has_normals())
            for (int axis = 0; axis < 3; ++axis)
            {
                out.put(' ');
                out.write_number(cloud.normals[i][axis]);
            }
        out.put('\n');
    }
}

} // namespace pointform::detail
