// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include "pointform/geometry/multires_mesh.h"

#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>

namespace pointform {

/// \file
/// \brief The pointform hierarchy file (".pfh"): a whole MultiresMesh, its base mesh, every
/// level's parent edges and every position, in one versioned binary file
/// (docs/hierarchy-format.md).
///
/// Layout of format version 2 (version 1, which this reader still reads, is the same with a u32
/// "flags" word of 0 at offset 12 and no record of the predictor: it reads as Midpoint). Every
/// integer is unsigned little-endian, every real an IEEE-754 binary64 little-endian; there is no
/// padding. V is the number of vertices of the finest level, L the number of levels (J + 1), F0 the
/// number of base faces and P = V − V0 the number of vertices added by splits (V0 = the base's
/// vertex count).
///
///     offset           size     field
///     0                8        magic: 89 50 46 48 0D 0A 1A 0A  ("\x89PFH\r\n\x1a\n")
///     8                4        u32 format version: 2
///     12               4        u32 predictor of the levels above the base: 0 midpoint,
///                               1 butterfly (others are rejected)
///     16               24       f64 × 3 origin x, y, z (world = origin + position)
///     40               4        u32 L, number of levels (≥ 1)
///     44               4        u32 V, number of vertices of the finest level
///     48               4        u32 F0, number of base faces (≥ 1)
///     52               4        u32 P, number of parent edges (= V − V0)
///     56               12·F0    base faces: u32 × 3 each (a, b, c), counter-clockwise seen
///                               from outside, indices < V0
///     +                4·(L+1)  level offsets: u32 each; 0, then the vertex count of each
///                               level (V0, V1, …, V_J = V), strictly increasing
///     +                8·P      parent edges: u32 × 2 each (a, b); entry k belongs to vertex
///                               V0 + k, the edge of level i that it splits (it is a vertex of
///                               level i + 1), both ends vertices of level i
///     +                24·V     positions: f64 × 3 each, relative to the origin, level by level
///     56 + 12·F0 + 4·(L+1) + 8·P + 24·V
///                      8        u64 checksum: FNV-1a 64 of every byte before it
///
/// The file size is therefore fixed by the header's counts, and the faces of level i ≥ 1 are not
/// stored: they follow from the base faces and the parent edges by the 1-to-4 split that
/// MultiresMesh documents (child 4f … 4f+3 of face f).
///
/// A reader checks, in this order: the magic, the version, the predictor (version 1: the flags),
/// that the file has exactly the size the counts announce (before allocating anything for them),
/// the checksum, and then every structural invariant through MultiresMesh's constructor (base an
/// oriented manifold, one new vertex per edge of the level below, parent edges naming each edge
/// once, finite positions, …). A version-2 writer must change the version number; readers reject
/// versions they do not know.

/// \brief The format version write_hierarchy() writes; read_hierarchy() reads it and version 1.
inline constexpr std::uint32_t hierarchy_format_version = 2;

/// \brief The 8 magic bytes a hierarchy file starts with.
inline constexpr std::array<std::uint8_t, 8> hierarchy_magic = {0x89, 'P',  'F',  'H',
                                                                0x0D, 0x0A, 0x1A, 0x0A};

/// \brief Writes `mesh` as a hierarchy file (format version hierarchy_format_version). The file
/// is written to a temporary name beside `path` and renamed when complete, so a failure never
/// leaves a half-written file.
/// \throw InvalidInput if the hierarchy is empty (no levels)
/// \throw IoError naming the file if it cannot be written
void write_hierarchy(const std::filesystem::path& path, const MultiresMesh& mesh);

/// \brief Reads a hierarchy file, trusting nothing in it (see the checks above).
/// \throw IoError naming the file: missing or unreadable; "not a pointform hierarchy" (wrong
///        magic); a version other than 1 and hierarchy_format_version (named); truncated or with
///        trailing bytes; "corrupt" (checksum mismatch, unknown flags); or a structure that
///        MultiresMesh rejects (its message, with the file's name)
[[nodiscard]] MultiresMesh read_hierarchy(const std::filesystem::path& path);

/// \brief Whether `path` is a readable file that starts with the hierarchy magic bytes (it may
/// still be of another version, truncated or corrupt). Never throws.
[[nodiscard]] bool is_hierarchy_file(const std::filesystem::path& path) noexcept;

/// \brief The format version word of a file that starts with the hierarchy magic bytes (what
/// read_hierarchy() then reads, or refuses); nothing for any other file. Never throws.
[[nodiscard]] std::optional<std::uint32_t> hierarchy_file_version(
    const std::filesystem::path& path) noexcept;

} // namespace pointform
