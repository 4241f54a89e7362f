// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include "pointform/geometry/textured_mesh.h"

#include "output_transaction.h"

#include <cstddef>
#include <filesystem>
#include <vector>

namespace pointform::cli {

/// \brief Whether `path` names a glTF binary (.glb) or an OBJ (.obj) output, the formats of a
/// TexturedMesh. \throw InvalidInput for any other extension
[[nodiscard]] bool is_gltf_output(const std::filesystem::path& path);

/// \brief Stages the files of a TexturedMesh export in `transaction` (nothing is in place until
/// its commit()): OUT.glb with every level; or OUT.obj with level `obj_lod` and, when the mesh
/// has a material, OUT.mtl and its PNG textures beside it (names from obj_file_names()).
/// \return the targets staged, the main file first
/// \throw InvalidInput for another extension or a bad mesh; IoError as OutputTransaction::stage
std::vector<std::filesystem::path> stage_textured_mesh(OutputTransaction& transaction,
                                                       const std::filesystem::path& output,
                                                       const TexturedMesh& mesh,
                                                       std::size_t obj_lod);

} // namespace pointform::cli
