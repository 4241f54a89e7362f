// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include "pointform/geometry/point_cloud.h"
#include "pointform/geometry/tri_mesh.h"
#include "pointform/io/io_options.h"

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

namespace pointform {

/// \brief Everything a reader took from a file: the points with their attributes, the faces if
/// the file had any (polygons are fan-triangulated), and what was dropped.
struct ReadResult
{
    PointCloud points;
    std::vector<Triangle> triangles; ///< empty for point sets
    FileFormat format = FileFormat::Auto;
    std::size_t dropped_points = 0; ///< non-finite points dropped (PCD organized clouds)
    std::string description;        ///< e.g. "PLY binary_big_endian", "LAS 1.4 point format 6"
};

/// \brief Reads a point set or mesh (Level 1 input).
///
/// Formats: PLY (ascii, binary little/big-endian, every scalar type; vertex x y z with optional
/// nx ny nz, red green blue (uchar or float), radius; faces as vertex_indices/vertex_index);
/// XYZ/PTS/CSV/TXT/PWN text with 3 columns (x y z), 6 (x y z nx ny nz) or more (PTS: x y z
/// intensity r g b); OFF; OBJ (v, vn, f); PCD (ascii, binary, binary_compressed) as PCL writes it;
/// LAS 1.0–1.4, point formats 0–10, uncompressed, with scale and offset applied.
/// Positions are stored as float32 relative to a double origin chosen by `choose_origin`.
/// \throw IoError naming the file, the line (text) or byte offset (binary) and what is wrong:
///        missing or empty file, truncated data, header counts that do not match the data,
///        malformed numbers, out-of-range face indices, non-finite coordinates (unless dropped).
[[nodiscard]] ReadResult read_geometry(const std::filesystem::path& path,
                                       const ReadOptions& options = {});

/// \brief Reads the points of any supported file (a mesh gives its vertices).
[[nodiscard]] PointCloud read_point_cloud(const std::filesystem::path& path,
                                          const ReadOptions& options = {});

/// \brief Reads a triangle mesh. \throw IoError if the file has no faces.
[[nodiscard]] TriMesh read_mesh(const std::filesystem::path& path, const ReadOptions& options = {});

/// \brief Writes points with whatever attributes they carry (normals, colors, radii) as PLY
/// (binary little-endian by default, ascii on request) or XYZ text (x y z [nx ny nz]).
/// The file is written to a temporary name beside `path` and renamed when complete, so a
/// failure never leaves a half-written file.
/// \throw IoError if the format is not writable or the file cannot be written.
void write_point_cloud(const std::filesystem::path& path, const PointCloudView& cloud,
                       const WriteOptions& options = {});

/// \brief Writes a triangle mesh as PLY, OFF or OBJ, atomically like write_point_cloud.
void write_mesh(const std::filesystem::path& path, const TriMesh& mesh,
                const WriteOptions& options = {});

/// \brief Writes `bytes` to `path` through a temporary file beside it that is renamed into
/// place, so a failure never leaves a half-written file (any output format can use this).
/// \throw IoError naming the file
void write_file_atomically(const std::filesystem::path& path, std::span<const std::uint8_t> bytes);

/// \brief The format `Auto` resolves to for this path. \throw IoError for unknown extensions.
[[nodiscard]] FileFormat format_from_extension(const std::filesystem::path& path);

} // namespace pointform
