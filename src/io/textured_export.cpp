// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// The checks every TexturedMesh export shares, and the OBJ + MTL texts of one level.

#include "pointform/io/textured_export.h"

#include "pointform/core/error.h"
#include "pointform/io/png.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <string_view>

namespace pointform {
namespace {

/// Unit vectors may be off by this much in length (float rounding of a normalized double).
constexpr float unit_tolerance = 1e-3F;

[[noreturn]] void invalid(const std::string& what)
{
    throw InvalidInput("textured mesh: " + what);
}

template <typename Values>
void check_per_vertex(const Values& values, std::size_t vertices, const char* name)
{
    if (!values.empty() && values.size() != vertices)
        invalid(std::string(name) + ": " + std::to_string(values.size()) + " for " +
                std::to_string(vertices) + " vertices (expected one per vertex, or none)");
    for (std::size_t v = 0; v < values.size(); ++v)
        if (!values[v].allFinite())
            invalid(std::string(name) + " of vertex " + std::to_string(v) + " is not finite");
}

template <typename Vector>
void check_unit(const Vector& value, std::size_t v, const char* name)
{
    if (std::abs(value.norm() - 1.0F) > unit_tolerance)
        invalid(std::string(name) + " of vertex " + std::to_string(v) + " is not of unit length (" +
                std::to_string(value.norm()) + ")");
}

void check_image(const TextureImage& image, const char* name)
{
    if (image.empty())
        return;
    const bool sides = image.width > 0 && image.height > 0;
    const bool channels = image.channels == 3 || image.channels == 4;
    if (!sides || !channels ||
        image.pixels.size() !=
            std::size_t(image.width) * std::size_t(image.height) * std::size_t(image.channels))
        invalid(std::string(name) + " is " + std::to_string(image.width) + " by " +
                std::to_string(image.height) + " pixels with " + std::to_string(image.channels) +
                " channels (3 or 4 expected) but holds " + std::to_string(image.pixels.size()) +
                " bytes");
}

/// Appends a number in the shortest decimal that reads back as the same value.
template <typename Real>
void append_number(std::string& out, Real value)
{
    char text[32];
    const auto result = std::to_chars(text, text + sizeof(text), value);
    out.append(text, result.ptr);
}

void append_index(std::string& out, std::size_t index)
{
    char text[24];
    const auto result = std::to_chars(text, text + sizeof(text), index);
    out.append(text, result.ptr);
}

/// The mesh's name as an OBJ/MTL material name: one word (blanks become '_').
std::string material_name(const TexturedMesh& mesh)
{
    std::string name = mesh.name.empty() ? std::string("material") : mesh.name;
    for (char& c : name)
        if (c == ' ' || c == '\t' || c == '\n' || c == '\r')
            c = '_';
    return name;
}

} // namespace

void check_textured_mesh(const TexturedMesh& mesh)
{
    const std::size_t vertices = mesh.positions.size();
    if (vertices == 0)
        invalid("no vertices");
    if (!mesh.origin.allFinite())
        invalid("the origin is not finite");
    check_per_vertex(mesh.positions, vertices, "position");
    check_per_vertex(mesh.normals, vertices, "normals");
    check_per_vertex(mesh.uvs, vertices, "uvs");
    check_per_vertex(mesh.tangents, vertices, "tangents");
    for (std::size_t v = 0; v < mesh.normals.size(); ++v)
        check_unit(mesh.normals[v], v, "normal");
    if (!mesh.tangents.empty() && mesh.normals.empty())
        invalid("tangents without normals");
    for (std::size_t v = 0; v < mesh.tangents.size(); ++v)
    {
        check_unit(mesh.tangents[v].head<3>().eval(), v, "tangent");
        if (mesh.tangents[v].w() != 1.0F && mesh.tangents[v].w() != -1.0F)
            invalid("tangent of vertex " + std::to_string(v) +
                    " has w = " + std::to_string(mesh.tangents[v].w()) + " (expected +1 or -1)");
    }

    const std::size_t levels = mesh.lods.size();
    if (levels == 0)
        invalid("no levels");
    if (mesh.lod_vertex_counts.size() != levels)
        invalid(std::to_string(mesh.lod_vertex_counts.size()) + " vertex counts for " +
                std::to_string(levels) + " levels");
    if (!mesh.lod_levels.empty() && mesh.lod_levels.size() != levels)
        invalid(std::to_string(mesh.lod_levels.size()) + " level numbers for " +
                std::to_string(levels) + " levels");
    std::size_t previous = 1;
    for (std::size_t i = 0; i < levels; ++i)
    {
        const std::size_t count = mesh.lod_vertex_counts[i];
        if (count < previous || count > vertices)
            invalid("level " + std::to_string(i) + " has " + std::to_string(count) +
                    " vertices; expected " + std::to_string(previous) + " to " +
                    std::to_string(vertices) +
                    " (each level's vertices a prefix of the next level's)");
        previous = count;
        if (mesh.lods[i].empty())
            invalid("level " + std::to_string(i) + " has no triangles");
        for (std::size_t f = 0; f < mesh.lods[i].size(); ++f)
            for (const std::uint32_t v : mesh.lods[i][f])
                if (v >= count)
                    invalid("triangle " + std::to_string(f) + " of level " + std::to_string(i) +
                            " names vertex " + std::to_string(v) + " but the level has " +
                            std::to_string(count) + " vertices");
    }

    check_image(mesh.base_color, "the colour texture");
    check_image(mesh.normal_map, "the normal map");
    if (mesh.uvs.empty() && (!mesh.base_color.empty() || !mesh.normal_map.empty()))
        invalid("a texture needs texture coordinates (uvs)");
    if (!mesh.normal_map.empty() && mesh.normals.empty())
        invalid("a normal map needs vertex normals");
}

ObjFileNames obj_file_names(const std::filesystem::path& obj_path)
{
    const std::string stem = obj_path.stem().string();
    return {stem + ".mtl", stem + "_color.png", stem + "_normal.png"};
}

bool obj_has_material(const TexturedMesh& mesh)
{
    return !mesh.uvs.empty() && (!mesh.base_color.empty() || !mesh.normal_map.empty());
}

std::string obj_text(const TexturedMesh& mesh, std::size_t lod, const ObjFileNames& names)
{
    check_textured_mesh(mesh);
    if (lod >= mesh.lods.size())
        throw InvalidInput("obj_text: level " + std::to_string(lod) +
                           " does not exist (the mesh has " + std::to_string(mesh.lods.size()) +
                           ")");
    const std::size_t count = mesh.lod_vertex_counts[lod];
    const bool uvs = !mesh.uvs.empty();
    const bool normals = !mesh.normals.empty();

    std::string out = "# written by pointform: " + mesh.name + ", level " +
                      std::to_string(mesh.lod_levels.empty() ? lod : mesh.lod_levels[lod]) + "\n";
    out.reserve(out.size() + count * 96 + mesh.lods[lod].size() * 40);
    const bool material = obj_has_material(mesh);
    if (material)
        out += "mtllib " + names.mtl + "\n";
    for (std::size_t v = 0; v < count; ++v)
    {
        out += "v";
        for (int axis = 0; axis < 3; ++axis)
        {
            out += ' ';
            const double world = mesh.origin[axis] + static_cast<double>(mesh.positions[v][axis]);
            if (mesh.origin[axis] == 0.0)
                append_number(out, mesh.positions[v][axis]); // the float, exactly
            else
                append_number(out, world);
        }
        out += '\n';
    }
    if (uvs)
        for (std::size_t v = 0; v < count; ++v)
        {
            out += "vt ";
            append_number(out, mesh.uvs[v].x());
            out += ' ';
            append_number(out, 1.0F - mesh.uvs[v].y()); // OBJ's v axis points up
            out += '\n';
        }
    if (normals)
        for (std::size_t v = 0; v < count; ++v)
        {
            out += "vn ";
            append_number(out, mesh.normals[v].x());
            out += ' ';
            append_number(out, mesh.normals[v].y());
            out += ' ';
            append_number(out, mesh.normals[v].z());
            out += '\n';
        }
    if (material)
        out += "usemtl " + material_name(mesh) + "\n";
    for (const Triangle& t : mesh.lods[lod])
    {
        out += 'f';
        for (const std::uint32_t v : t)
        {
            out += ' ';
            append_index(out, std::size_t{v} + 1);
            if (uvs || normals)
            {
                out += '/';
                if (uvs)
                    append_index(out, std::size_t{v} + 1);
                if (normals)
                {
                    out += '/';
                    append_index(out, std::size_t{v} + 1);
                }
            }
        }
        out += '\n';
    }
    return out;
}

std::string mtl_text(const TexturedMesh& mesh, const ObjFileNames& names)
{
    check_textured_mesh(mesh);
    if (!obj_has_material(mesh))
        return {};
    std::string out = "# written by pointform\nnewmtl " + material_name(mesh) + "\n";
    out += "Ka 0 0 0\nKd 1 1 1\nKs 0 0 0\nNs 1\nd 1\nillum 1\n";
    if (!mesh.base_color.empty())
        out += "map_Kd " + names.base_color + "\n";
    if (!mesh.normal_map.empty())
    {
        out += "norm " + names.normal_map + "\n";
        out += "map_Bump " + names.normal_map + "\n";
    }
    return out;
}

bool is_gltf_path(const std::filesystem::path& path)
{
    std::string ext = path.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    if (ext == ".glb")
        return true;
    if (ext == ".obj")
        return false;
    throw InvalidInput(path.string() +
                       ": unknown output format; expected .glb (glTF binary, every level) or .obj "
                       "(OBJ, one level)");
}

std::vector<TexturedFile> textured_files(const std::filesystem::path& output,
                                         const TexturedMesh& mesh, std::size_t obj_lod)
{
    if (is_gltf_path(output))
        return {{output, encode_gltf(mesh)}};
    const auto text_bytes = [](const std::string& text) {
        return std::vector<std::uint8_t>(text.begin(), text.end());
    };
    const ObjFileNames names = obj_file_names(output);
    std::vector<TexturedFile> files = {{output, text_bytes(obj_text(mesh, obj_lod, names))}};
    if (!obj_has_material(mesh))
        return files;
    const std::filesystem::path folder = output.parent_path();
    files.push_back({folder / names.mtl, text_bytes(mtl_text(mesh, names))});
    if (!mesh.base_color.empty())
        files.push_back({folder / names.base_color, encode_png(mesh.base_color)});
    if (!mesh.normal_map.empty())
        files.push_back({folder / names.normal_map, encode_png(mesh.normal_map)});
    return files;
}

} // namespace pointform
