// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include <cstddef>
#include <string>

namespace pointform {

/// \brief File formats pointform reads or writes. `Auto` picks one from the file extension
/// (.ply .xyz .pts .csv .txt .pwn .off .obj .pcd .las).
enum class FileFormat
{
    Auto,
    Ply,
    Xyz, ///< whitespace- or comma-separated text columns: .xyz .pts .csv .txt .pwn
    Off,
    Obj,
    Pcd,
    Las,
};

/// \brief What a reader does with points whose coordinates are NaN or infinite.
enum class NonFinitePolicy
{
    /// Throw IoError naming the file and the point. Default for every format except PCD.
    Error,
    /// Drop the point and count it in ReadResult::dropped_points. Default for PCD, where NaN
    /// marks missing pixels of organized clouds.
    Drop,
    /// Error for every format but PCD, Drop for PCD.
    FormatDefault,
};

/// \brief Options for reading.
struct ReadOptions
{
    /// Forces a format instead of guessing from the extension.
    FileFormat format = FileFormat::Auto;
    /// Treatment of NaN or infinite coordinates.
    NonFinitePolicy non_finite = NonFinitePolicy::FormatDefault;
};

/// \brief Options for writing.
struct WriteOptions
{
    /// Forces a format instead of guessing from the extension. Writable: Ply, Xyz (and, for
    /// meshes, Ply, Off, Obj).
    FileFormat format = FileFormat::Auto;
    /// PLY only: write ascii instead of binary little-endian.
    bool ascii = false;
    /// Text formats: significant digits of coordinates (0 = enough to round-trip float32
    /// relative to the origin).
    int precision = 0;
};

/// \brief Name of a format ("ply", "xyz", ...).
[[nodiscard]] std::string format_name(FileFormat format);

} // namespace pointform
