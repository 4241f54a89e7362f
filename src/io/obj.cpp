// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// Wavefront OBJ: `v` (with optional r g b), `vn` and `f` statements; everything else is ignored.
// Face corners may be v, v/vt, v//vn or v/vt/vn, with 1-based or negative (relative) indices.

#include "detail_readers.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace pointform::detail {
namespace {

/// One face corner that names a normal: vertex index and normal index, both 0-based.
struct CornerNormal
{
    std::uint32_t vertex;
    std::uint32_t normal;
};

std::uint8_t to_color(double value)
{
    if (!(value > 0.0))
        return 0;
    // OBJ vertex colors are in [0, 1]; accept 0..255 from writers that use bytes.
    const double scaled = value <= 1.0 ? value * 255.0 : std::min(value, 255.0);
    return static_cast<std::uint8_t>(std::lround(scaled));
}

/// Resolves a 1-based or negative (relative) OBJ index against `count` items defined so far.
/// Returns false if it does not name one of them.
bool resolve_index(std::int64_t index, std::size_t count, std::uint32_t& resolved)
{
    const auto n = static_cast<std::int64_t>(count);
    const std::int64_t zero_based = index > 0 ? index - 1 : n + index;
    if (index == 0 || zero_based < 0 || zero_based >= n)
        return false;
    resolved = static_cast<std::uint32_t>(zero_based);
    return true;
}

/// Per-vertex normals from the face references, or from `vn` lines when there is one a vertex.
/// Returns an empty vector when the file does not give every vertex a normal.
std::vector<Vec3f> vertex_normals(std::size_t vertex_count, const std::vector<Vec3f>& normals,
                                  const std::vector<CornerNormal>& corners)
{
    if (normals.empty())
        return {};
    const bool one_to_one = normals.size() == vertex_count &&
                            std::all_of(corners.begin(), corners.end(),
                                        [](const CornerNormal& c) { return c.vertex == c.normal; });
    if (one_to_one)
        return normals;
    if (corners.empty())
        return {};
    // Average the normals each vertex is given by the faces around it.
    std::vector<Vec3f> sum(vertex_count, Vec3f::Zero());
    std::vector<std::uint32_t> hits(vertex_count, 0);
    for (const CornerNormal& c : corners)
    {
        sum[c.vertex] += normals[c.normal];
        ++hits[c.vertex];
    }
    for (std::size_t i = 0; i < vertex_count; ++i)
    {
        if (hits[i] == 0)
        {
            if (normals.size() != vertex_count)
                return {};
            sum[i] = normals[i];
        }
    }
    return sum;
}

} // namespace

ReadResult read_obj(const std::filesystem::path& path, std::string_view bytes,
                    NonFinitePolicy policy)
{
    std::vector<Vec3d> positions;
    std::vector<Color> colors;
    std::vector<Vec3f> normals;
    std::vector<CornerNormal> corners;
    bool all_colored = true;
    std::optional<std::uint64_t> first_non_finite_line;
    ReadResult result;

    LineReader lines(bytes);
    std::string_view line;
    std::string_view token;
    std::vector<std::uint32_t> polygon;
    while (lines.next(line))
    {
        std::string_view rest = line;
        if (!next_token(rest, token) || token.front() == '#')
            continue;
        const Location where = Location::at_line(lines.line_number());
        if (token == "v")
        {
            double v[6] = {};
            std::size_t n = 0;
            while (next_token(rest, token))
            {
                if (n < 6 && !parse_double(token, v[n]))
                    fail(path, "malformed number " + quote(token), where);
                ++n;
            }
            if (n < 3)
                fail(path, "vertex needs x y z, found " + std::to_string(n) + " values", where);
            const Vec3d p(v[0], v[1], v[2]);
            if (!p.allFinite())
            {
                if (policy != NonFinitePolicy::Drop)
                    fail(path,
                         "non-finite coordinate in vertex " + std::to_string(positions.size()),
                         where);
                if (!first_non_finite_line)
                    first_non_finite_line = lines.line_number();
            }
            positions.push_back(p);
            if (n == 6) // x y z r g b, a common extension
                colors.push_back({to_color(v[3]), to_color(v[4]), to_color(v[5])});
            else
                all_colored = false;
        }
        else if (token == "vn")
        {
            double v[3] = {};
            for (double& component : v)
                if (!next_token(rest, token) || !parse_double(token, component))
                    fail(path, "normal needs three numbers", where);
            normals.emplace_back(static_cast<float>(v[0]), static_cast<float>(v[1]),
                                 static_cast<float>(v[2]));
        }
        else if (token == "f")
        {
            polygon.clear();
            while (next_token(rest, token))
            {
                // v, v/vt, v//vn or v/vt/vn
                const std::size_t slash = token.find('/');
                const std::string_view vertex_part = token.substr(0, slash);
                std::string_view normal_part;
                if (slash != std::string_view::npos)
                {
                    const std::size_t second = token.find('/', slash + 1);
                    if (second != std::string_view::npos)
                        normal_part = token.substr(second + 1);
                }
                std::int64_t index = 0;
                std::uint32_t vertex = 0;
                if (!parse_integer(vertex_part, index))
                    fail(path, "malformed face corner " + quote(token), where);
                if (!resolve_index(index, positions.size(), vertex))
                    fail(path,
                         "face refers to vertex " + std::to_string(index) + " but " +
                             std::to_string(positions.size()) + " vertices are defined before it",
                         where);
                if (!normal_part.empty())
                {
                    std::uint32_t normal = 0;
                    if (!parse_integer(normal_part, index))
                        fail(path, "malformed face corner " + quote(token), where);
                    if (!resolve_index(index, normals.size(), normal))
                        fail(path,
                             "face refers to normal " + std::to_string(index) + " but " +
                                 std::to_string(normals.size()) + " normals are defined before it",
                             where);
                    corners.push_back({vertex, normal});
                }
                polygon.push_back(vertex);
            }
            append_fan(result.triangles, polygon);
        }
        if (positions.size() > std::numeric_limits<std::uint32_t>::max())
            fail(path, "too many vertices for 32-bit indices", where);
    }

    const std::vector<Vec3f> vertex_normal = vertex_normals(positions.size(), normals, corners);
    const AttributeSet attributes{.normals = !vertex_normal.empty(),
                                  .colors = all_colored && !positions.empty()};
    const Location drop_where =
        first_non_finite_line ? Location::at_line(*first_non_finite_line) : Location{};
    CloudBuilder builder(path, policy, attributes, positions.size());
    for (std::size_t i = 0; i < positions.size(); ++i)
    {
        PointRecord point;
        point.position = positions[i];
        if (attributes.normals)
            point.normal = vertex_normal[i];
        if (attributes.colors)
            point.color = colors[i];
        builder.add(point, drop_where);
    }
    builder.check_no_drops_with_faces(!result.triangles.empty());
    result.dropped_points = builder.dropped();
    result.points = builder.take();
    result.description = "OBJ";
    return result;
}

void write_obj(OutputBuffer& out, const TriMesh& mesh, int precision)
{
    const PointCloud& vertices = mesh.vertices;
    out.write("# written by pointform\n");
    for (std::size_t i = 0; i < vertices.size(); ++i)
    {
        out.write("v ");
        write_world_text(out, vertices, i, precision);
        out.put('\n');
    }
    if (vertices.has_normals())
        for (const Vec3f& n : vertices.normals)
        {
            out.write("vn ");
            out.write_number(n.x());
            out.put(' ');
            out.write_number(n.y());
            out.put(' ');
            out.write_number(n.z());
            out.put('\n');
        }
    for (const Triangle& t : mesh.triangles)
    {
        out.put('f');
        for (const std::uint32_t v : t)
        {
            out.put(' ');
            out.write_integer(std::uint64_t{v} + 1);
            if (vertices.has_normals())
            {
                out.write("//");
                out.write_integer(std::uint64_t{v} + 1);
            }
        }
        out.put('\n');
    }
}

} // namespace pointform::detail
