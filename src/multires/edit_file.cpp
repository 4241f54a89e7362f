// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/multires/edit_file.h"

#include "pointform/core/error.h"
#include "pointform/core/json_depth.h"
#include "pointform/geometry/aabb.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>
#include <initializer_list>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

namespace pointform {

namespace {

using json = nlohmann::json;

constexpr std::size_t max_depth = 16;

/// An error about the file `source`: "source: what".
[[noreturn]] void fail(const std::string& source, const std::string& what)
{
    throw InvalidInput(source + ": " + what);
}

/// Refuses nesting deeper than max_depth before the parser sees it (so no input can make the
/// parser or the destructor of a deep value recurse far).
void check_depth(std::string_view text, const std::string& source)
{
    if (json_nests_deeper_than(text, max_depth))
        fail(source, "nesting deeper than " + std::to_string(max_depth) + " levels");
}

json parse_json(std::string_view text, const std::string& source)
{
    check_depth(text, source);
    try
    {
        return json::parse(text);
    }
    catch (const json::exception& e)
    {
        // A syntax error or a number out of double's range: e.byte where the parser knows it.
        const std::size_t byte = dynamic_cast<const json::parse_error*>(&e) != nullptr
                                     ? static_cast<const json::parse_error&>(e).byte
                                     : 0;
        if (byte == 0)
            fail(source, std::string("not valid JSON (") + e.what() + ")");
        std::size_t line = 1;
        std::size_t column = 1;
        for (std::size_t i = 0; i + 1 < byte && i < text.size(); ++i)
        {
            if (text[i] == '\n')
            {
                ++line;
                column = 1;
            }
            else
                ++column;
        }
        fail(source, "not valid JSON at line " + std::to_string(line) + ", column " +
                         std::to_string(column) + " (" + e.what() + ")");
    }
}

void only_keys(const json& object, std::initializer_list<const char*> keys,
               const std::string& source, const std::string& where)
{
    if (!object.is_object())
        fail(source, where + " must be a JSON object");
    for (const auto& [key, value] : object.items())
    {
        bool known = false;
        for (const char* k : keys)
            known = known || key == k;
        if (!known)
        {
            std::string list;
            for (const char* k : keys)
                list += (list.empty() ? "" : ", ") + std::string(k);
            fail(source, where + ": unknown key \"" + key + "\" (expected " + list + ")");
        }
    }
}

double number(const json& value, const std::string& source, const std::string& where)
{
    if (!value.is_number())
        fail(source, where + " must be a number");
    const double x = value.get<double>();
    if (!std::isfinite(x))
        fail(source, where + " is not finite");
    return x;
}

Vec3d vec3(const json& value, const std::string& source, const std::string& where)
{
    if (!value.is_array() || value.size() != 3)
        fail(source, where + " must be an array of 3 numbers");
    return {number(value[0], source, where + "[0]"), number(value[1], source, where + "[1]"),
            number(value[2], source, where + "[2]")};
}

std::uint64_t whole(const json& value, std::uint64_t limit, const std::string& source,
                    const std::string& where)
{
    if (value.is_number_unsigned())
    {
        const auto v = value.get<std::uint64_t>();
        if (v < limit)
            return v;
    }
    else if (value.is_number_integer() && value.get<std::int64_t>() >= 0)
    {
        const auto v = static_cast<std::uint64_t>(value.get<std::int64_t>());
        if (v < limit)
            return v;
    }
    fail(source, where + " must be a whole number from 0 to " + std::to_string(limit - 1) +
                     ", got " + value.dump());
}

std::vector<std::uint32_t> vertex_ids(const json& value, const std::string& source,
                                      const std::string& where)
{
    if (!value.is_array())
        fail(source, where + " must be an array of vertex ids");
    std::vector<std::uint32_t> ids;
    ids.reserve(value.size());
    for (std::size_t i = 0; i < value.size(); ++i)
        ids.push_back(
            static_cast<std::uint32_t>(whole(value[i], std::numeric_limits<std::uint32_t>::max(),
                                             source, where + "[" + std::to_string(i) + "]")));
    return ids;
}

const json& required(const json& object, const char* key, const std::string& source,
                     const std::string& where)
{
    if (!object.contains(key))
        fail(source, where + " needs \"" + key + "\"");
    return object[key];
}

std::size_t level_of(const json& document, const std::string& source)
{
    if (!document.contains("level"))
        return 0;
    return static_cast<std::size_t>(
        whole(document["level"], std::numeric_limits<std::uint32_t>::max(), source, "\"level\""));
}

std::string read_text(const std::filesystem::path& path, const char* what)
{
    std::error_code error;
    if (std::filesystem::is_directory(path, error))
        throw IoError(path, std::string("is a directory, not ") + what);
    std::ifstream in(path, std::ios::binary);
    if (!in)
        throw IoError(path, std::string("cannot open ") + what);
    in.seekg(0, std::ios::end);
    const std::streamoff size = in.tellg();
    if (size < 0)
        throw IoError(path, std::string("cannot read ") + what);
    if (static_cast<std::uint64_t>(size) > max_edit_file_bytes)
        throw IoError(path, std::string("too large for ") + what + ": " + std::to_string(size) +
                                " bytes (at most " + std::to_string(max_edit_file_bytes) + ")");
    in.seekg(0);
    std::string text(static_cast<std::size_t>(size), '\0');
    if (!in.read(text.data(), size))
        throw IoError(path, std::string("cannot read ") + what);
    return text;
}

} // namespace

/// The vertices an object names (a region, a handle): its "vertices" ids, or its "ball" or
/// "box" (the caller checks that exactly one is there); `where` names the object in errors.
RegionOfInterest vertex_set(const json& object, const std::string& source, const std::string& where)
{
    if (object.contains("vertices"))
        return RegionOfInterest::of_vertices(
            vertex_ids(object["vertices"], source, where + ".vertices"));
    if (object.contains("ball"))
    {
        const json& ball = object["ball"];
        const std::string at = where + ".ball";
        only_keys(ball, {"center", "radius"}, source, at);
        return RegionOfInterest::ball(
            vec3(required(ball, "center", source, at), source, at + ".center"),
            number(required(ball, "radius", source, at), source, at + ".radius"));
    }
    const json& box = object["box"];
    const std::string at = where + ".box";
    only_keys(box, {"min", "max"}, source, at);
    return RegionOfInterest::box(vec3(required(box, "min", source, at), source, at + ".min"),
                                 vec3(required(box, "max", source, at), source, at + ".max"));
}

MultiresEdit parse_multires_edit(std::string_view text, const std::string& source)
{
    const json document = parse_json(text, source);
    only_keys(document, {"level", "handles", "region"}, source, "the edit");
    MultiresEdit edit;
    edit.level = level_of(document, source);
    if (document.contains("handles"))
    {
        const json& handles = document["handles"];
        if (!handles.is_array())
            fail(source, "\"handles\" must be an array");
        for (std::size_t h = 0; h < handles.size(); ++h)
        {
            const std::string where = "handles[" + std::to_string(h) + "]";
            const json& item = handles[h];
            only_keys(item, {"vertices", "ball", "box", "translate", "matrix"}, source, where);
            const bool translate = item.contains("translate");
            if (translate == item.contains("matrix"))
                fail(source, where + " needs exactly one of \"translate\" and \"matrix\"");
            if (static_cast<int>(item.contains("vertices")) +
                    static_cast<int>(item.contains("ball")) +
                    static_cast<int>(item.contains("box")) !=
                1)
                fail(source, where + " needs exactly one of \"vertices\", \"ball\" and \"box\"");
            Eigen::Matrix4d matrix = Eigen::Matrix4d::Identity();
            if (translate)
            {
                matrix.topRightCorner<3, 1>() =
                    vec3(item["translate"], source, where + ".translate");
            }
            else
            {
                const json& m = item["matrix"];
                if (!m.is_array() || m.size() != 16)
                    fail(source,
                         where + ".matrix must be an array of 16 numbers (row-major 4 x 4)");
                for (int r = 0; r < 4; ++r)
                    for (int c = 0; c < 4; ++c)
                        matrix(r, c) = number(m[static_cast<std::size_t>(4 * r + c)], source,
                                              where + ".matrix[" + std::to_string(4 * r + c) + "]");
            }
            const RegionOfInterest chosen = vertex_set(item, source, where);
            edit.handles.push_back(chosen.kind == RegionOfInterest::Kind::Vertices
                                       ? DeformHandle::affine(chosen.vertices, matrix)
                                       : DeformHandle::within(chosen, matrix));
        }
    }
    if (document.contains("region"))
    {
        const json& region = document["region"];
        only_keys(region, {"vertices", "ball", "box"}, source, "\"region\"");
        if (region.size() != 1)
            fail(source, "\"region\" needs exactly one of \"vertices\", \"ball\" and \"box\"");
        edit.region = vertex_set(region, source, "region");
    }
    return edit;
}

LatticeEdit parse_lattice(std::string_view text, const std::string& source)
{
    const json document = parse_json(text, source);
    only_keys(document, {"min", "max", "degree", "level", "control_points"}, source, "the lattice");
    LatticeEdit out;
    out.level = level_of(document, source);
    out.lattice.min = vec3(required(document, "min", source, "the lattice"), source, "\"min\"");
    out.lattice.max = vec3(required(document, "max", source, "the lattice"), source, "\"max\"");
    const json& degree = required(document, "degree", source, "the lattice");
    if (!degree.is_array() || degree.size() != 3)
        fail(source, "\"degree\" must be an array of 3 whole numbers");
    for (std::size_t axis = 0; axis < 3; ++axis)
        out.lattice.degree[axis] = static_cast<std::size_t>(whole(
            degree[axis], max_lattice_degree + 1, source, "degree[" + std::to_string(axis) + "]"));
    const json& points = required(document, "control_points", source, "the lattice");
    if (!points.is_array())
        fail(source, "\"control_points\" must be an array of [x, y, z] points");
    if (points.size() > max_lattice_points)
        fail(source, std::to_string(points.size()) + " control points, more than " +
                         std::to_string(max_lattice_points));
    out.lattice.control_points.reserve(points.size());
    for (std::size_t i = 0; i < points.size(); ++i)
        out.lattice.control_points.push_back(
            vec3(points[i], source, "control_points[" + std::to_string(i) + "]"));
    try
    {
        validate_lattice(out.lattice);
    }
    catch (const InvalidInput& e)
    {
        fail(source, e.what());
    }
    return out;
}

MultiresEdit read_multires_edit(const std::filesystem::path& path)
{
    return parse_multires_edit(read_text(path, "an edit file"), path.string());
}

LatticeEdit read_lattice(const std::filesystem::path& path)
{
    return parse_lattice(read_text(path, "a lattice file"), path.string());
}

DeformOutcome deform_hierarchy(MultiresMesh& mesh, const DeformRequest& request)
{
    if (request.edit.has_value() == request.lattice.has_value())
        throw InvalidInput("deform: give exactly one of an edit and a lattice");
    DeformOutcome out;
    out.predictor = mesh.predictor();
    Aabb box;
    for (const Vec3d& p : mesh.positions())
        box.extend(p);
    out.diagonal = box.diagonal();
    if (mesh.level_count() > 0)
        out.details = detail_statistics(analyze_details(mesh), out.normal_tolerance);
    if (request.edit)
    {
        out.mode = "edit";
        out.deformation = deform(mesh, *request.edit);
    }
    else
    {
        const bool plain = request.lattice_mode == LatticeMode::Plain;
        out.mode = plain ? "lattice (plain)" : "lattice (details)";
        out.deformation = apply_lattice(mesh, request.lattice->lattice, request.lattice->level,
                                        request.lattice_mode);
    }
    return out;
}

} // namespace pointform
