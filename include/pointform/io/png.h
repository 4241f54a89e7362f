// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

/// \file
/// \brief PNG images (libpng): the one PNG encoder and decoder of pointform, used by the texture
/// export (glTF, OBJ + MTL) and by `render`.

#include "pointform/geometry/textured_mesh.h"

#include <cstdint>
#include <filesystem>
#include <span>
#include <vector>

namespace pointform {

/// \brief What a PNG decoder accepts, checked against the header before any pixel memory is
/// allocated (so a few hostile bytes announcing a 100000 × 100000 image cost nothing).
struct PngLimits
{
    /// Largest width and largest height, in pixels. 16384 is what every GPU API guarantees for a
    /// 2D texture's side; 0 is not a safe value.
    int max_side = 16384;
    /// Largest decoded image, width × height × channels bytes (default 1 GiB: a 16384²
    /// RGBA image). The decoder also refuses images that would need more than 80% of the memory
    /// this process may use (pointform/core/memory.h).
    std::uint64_t max_bytes = std::uint64_t{1} << 30U;
};

/// \brief Encodes an 8-bit RGB or RGBA image as PNG (non-interlaced, 8 bits a channel, sRGB,
/// no gamma chunk), so decode_png() gives back the very same pixels.
/// \param image  width, height ≥ 1; channels 3 or 4; pixels.size() == width × height × channels
/// \throw InvalidInput for an inconsistent image (a side ≤ 0, channels other than 3 and 4,
///        pixels of the wrong size); Error if libpng fails
[[nodiscard]] std::vector<std::uint8_t> encode_png(const TextureImage& image);

/// \brief encode_png() written to `path` through a temporary file beside it, renamed into place
/// when complete, so a failure never leaves a half-written file.
/// \throw IoError naming the file if it cannot be written; InvalidInput as encode_png()
void write_png(const std::filesystem::path& path, const TextureImage& image);

/// \brief Decodes a PNG image: every colour type and bit depth, interlaced or not, comes out as
/// 8-bit RGB (3 channels; grey is expanded) or, when the image has alpha (an alpha channel or
/// a tRNS chunk), RGBA (4 channels, not premultiplied). 16-bit images are reduced to 8 bits.
/// The bytes are never trusted: the signature, the header and the size announced are checked
/// before the pixels are allocated, and a libpng error becomes an exception.
/// \param bytes        the file's contents
/// \param source_name  the file (or other source) named by every error message
/// \throw IoError naming `source_name`: not a PNG (wrong signature), truncated or corrupt data
///        (libpng's message), a side of 0 or more than limits.max_side, or an image bigger than
///        limits.max_bytes or than the memory guard
[[nodiscard]] TextureImage decode_png(std::span<const std::uint8_t> bytes,
                                      const std::filesystem::path& source_name,
                                      const PngLimits& limits = {});

/// \brief Reads a PNG file with decode_png().
/// \throw IoError naming the file: missing, a directory, empty, unreadable, or as decode_png()
[[nodiscard]] TextureImage read_png(const std::filesystem::path& path,
                                    const PngLimits& limits = {});

} // namespace pointform
