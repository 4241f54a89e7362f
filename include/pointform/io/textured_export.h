// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

/// \file
/// \brief Export of a TexturedMesh (a textured mesh with levels of detail sharing one vertex
/// buffer): glTF 2.0 binary (.glb) with every level, and OBJ + MTL (+ the PNG textures) for one
/// level. docs/gltf-export.md describes the glTF layout and why it is so.

#include "pointform/geometry/textured_mesh.h"

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace pointform {

/// \brief Checks that a TexturedMesh can be exported, once, before anything is written.
///
/// What is checked: at least one vertex, every position finite; normals, uvs and tangents each
/// empty or one per vertex, finite (uvs outside [0, 1]² are legal), tangents only with normals
/// and with w = ±1; at least one level; lod_vertex_counts one per level, each ≥ 1,
/// non-decreasing (each level's vertices a prefix of the next's) and at most the vertex count;
/// every level at least one triangle, every index below its level's vertex count; lod_levels
/// empty or one per level; each image empty or consistent (sides ≥ 1, 3 or 4 channels, width ×
/// height × channels bytes); a colour texture only with uvs, a normal map only with uvs and
/// normals.
/// \throw InvalidInput saying what is wrong (which level, which vertex)
void check_textured_mesh(const TexturedMesh& mesh);

/// \brief The glTF 2.0 binary (.glb) of a TexturedMesh: one buffer; positions, normals, uvs and
/// tangents each one bufferView over every vertex; per level, one accessor per attribute over
/// the level's prefix (count = lod_vertex_counts[i], byteOffset 0; POSITION with the prefix's
/// min and max) and one index accessor (UNSIGNED_SHORT when the level has at most 65535
/// vertices, else UNSIGNED_INT); one mesh and one node per level, named "level <l>" with l from
/// lod_levels (else the index). The finest level is the scene's root node; the coarser levels'
/// nodes are listed, finest first, in its MSFT_lod extension (used, not required: a loader
/// without it shows the finest level). Every node is translated by the mesh's origin. One
/// material: pbrMetallicRoughness, metallicFactor 0, with base_color as baseColorTexture and
/// normal_map as normalTexture when set (both embedded as PNG in the buffer), doubleSided
/// false. Chunks are padded to 4 bytes (JSON with spaces, BIN with zeros).
/// \throw InvalidInput as check_textured_mesh(), or if the file would exceed the 4 GiB a GLB
///        can hold
[[nodiscard]] std::vector<std::uint8_t> encode_gltf(const TexturedMesh& mesh);

/// \brief encode_gltf() written to `path` (.glb) through a temporary file beside it, renamed
/// into place when complete.
/// \throw IoError naming the file if it cannot be written; InvalidInput as encode_gltf()
void write_gltf(const std::filesystem::path& path, const TexturedMesh& mesh);

/// \brief The files an OBJ export refers to by name, relative to the OBJ's folder.
struct ObjFileNames
{
    std::string mtl;        ///< "STEM.mtl"
    std::string base_color; ///< "STEM_color.png"
    std::string normal_map; ///< "STEM_normal.png"
};

/// \brief The names that go with an OBJ file "DIR/STEM.obj": STEM.mtl, STEM_color.png and
/// STEM_normal.png (written beside it).
[[nodiscard]] ObjFileNames obj_file_names(const std::filesystem::path& obj_path);

/// \brief Whether the OBJ export of `mesh` has a material, hence an MTL file: the mesh has uvs
/// and a colour texture or a normal map.
[[nodiscard]] bool obj_has_material(const TexturedMesh& mesh);

/// \brief The text of an OBJ file holding level `lod` of `mesh` (its vertices [0,
/// lod_vertex_counts[lod]) and faces lods[lod]): `v` (world positions, origin + position, in
/// shortest round-trip decimal), `vt` (u, 1 − v: OBJ's texture origin is the bottom-left
/// corner, glTF's and TextureImage's the top-left) when the mesh has uvs, `vn` when it has
/// normals, and faces `f a/a/a` (1-based; `a//a` without uvs, `a/a` without normals, `a`
/// with neither). With a material (obj_has_material()) it names `mtllib <names.mtl>` and
/// `usemtl`.
/// \throw InvalidInput as check_textured_mesh(), or if `lod` is not a level of the mesh
[[nodiscard]] std::string obj_text(const TexturedMesh& mesh, std::size_t lod,
                                   const ObjFileNames& names);

/// \brief The text of the MTL file that goes with obj_text(): one material, white diffuse,
/// `map_Kd <names.base_color>` when the mesh has a colour texture, and `norm` and `map_Bump`
/// (the two spellings loaders read) `<names.normal_map>` when it has a normal map. Empty when
/// the mesh has no material.
/// \throw InvalidInput as check_textured_mesh()
[[nodiscard]] std::string mtl_text(const TexturedMesh& mesh, const ObjFileNames& names);

/// \brief One file of a textured export: where it goes and its bytes.
struct TexturedFile
{
    std::filesystem::path path;
    std::vector<std::uint8_t> bytes;
};

/// \brief Whether `path` names a glTF binary (.glb, every level) or an OBJ (.obj, one level),
/// the formats of a TexturedMesh, whatever the extension's case.
/// \throw InvalidInput for any other extension
[[nodiscard]] bool is_gltf_path(const std::filesystem::path& path);

/// \brief Every file of `mesh`'s export to `output`, encoded (nothing written): OUT.glb with
/// every level; or OUT.obj with level of detail `obj_lod` and, when the mesh has a material,
/// OUT.mtl and its PNG textures beside it (names from obj_file_names()), the main file first.
/// \throw InvalidInput for another extension or a bad mesh
[[nodiscard]] std::vector<TexturedFile> textured_files(const std::filesystem::path& output,
                                                       const TexturedMesh& mesh,
                                                       std::size_t obj_lod);

} // namespace pointform
