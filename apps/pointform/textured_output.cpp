// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "textured_output.h"

#include "pointform/core/error.h"
#include "pointform/io/io.h"
#include "pointform/io/textured_export.h"

namespace pointform::cli {

bool is_gltf_output(const std::filesystem::path& path)
{
    return is_gltf_path(path);
}

std::vector<std::filesystem::path> stage_textured_mesh(OutputTransaction& transaction,
                                                       const std::filesystem::path& output,
                                                       const TexturedMesh& mesh,
                                                       std::size_t obj_lod)
{
    // Encoded before staging, so that a bad mesh leaves no temporary file behind.
    const std::vector<TexturedFile> files = textured_files(output, mesh, obj_lod);
    std::vector<std::filesystem::path> targets;
    for (const TexturedFile& file : files)
    {
        transaction.stage(file.path, [&](const std::filesystem::path& path) {
            write_file_atomically(path, file.bytes);
        });
        targets.push_back(file.path);
    }
    return targets;
}

} // namespace pointform::cli
