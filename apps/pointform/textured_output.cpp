// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "textured_output.h"

#include "pointform/core/error.h"
#include "pointform/io/io.h"
#include "pointform/io/png.h"
#include "pointform/io/textured_export.h"

#include <algorithm>
#include <cctype>
#include <span>
#include <string>

namespace pointform::cli {
namespace {

void write_text(const std::filesystem::path& path, const std::string& text)
{
    write_file_atomically(
        path, std::span<const std::uint8_t>(reinterpret_cast<const std::uint8_t*>(text.data()),
                                            text.size()));
}

} // namespace

bool is_gltf_output(const std::filesystem::path& path)
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

std::vector<std::filesystem::path> stage_textured_mesh(OutputTransaction& transaction,
                                                       const std::filesystem::path& output,
                                                       const TexturedMesh& mesh,
                                                       std::size_t obj_lod)
{
    if (is_gltf_output(output))
    {
        // Encoded before staging, so that a bad mesh leaves no temporary file behind.
        const std::vector<std::uint8_t> glb = encode_gltf(mesh);
        transaction.stage(
            output, [&](const std::filesystem::path& path) { write_file_atomically(path, glb); });
        return {output};
    }
    const ObjFileNames names = obj_file_names(output);
    const std::string obj = obj_text(mesh, obj_lod, names);
    std::vector<std::filesystem::path> targets = {output};
    transaction.stage(output, [&](const std::filesystem::path& path) { write_text(path, obj); });
    if (!obj_has_material(mesh))
        return targets;
    const std::filesystem::path folder = output.parent_path();
    targets.push_back(folder / names.mtl);
    const std::string mtl = mtl_text(mesh, names);
    transaction.stage(targets.back(),
                      [&](const std::filesystem::path& path) { write_text(path, mtl); });
    if (!mesh.base_color.empty())
    {
        targets.push_back(folder / names.base_color);
        transaction.stage(targets.back(), [&](const std::filesystem::path& path) {
            write_png(path, mesh.base_color);
        });
    }
    if (!mesh.normal_map.empty())
    {
        targets.push_back(folder / names.normal_map);
        transaction.stage(targets.back(), [&](const std::filesystem::path& path) {
            write_png(path, mesh.normal_map);
        });
    }
    return targets;
}

} // namespace pointform::cli
