// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// render's PNG output goes through the io module's encoder (libpng): one PNG writer in pointform.

#include "pointform/io/png.h"

#include "pointform/core/error.h"
#include "pointform/render/render.h"

namespace pointform {
namespace {

TextureImage texture_of(const Image& image)
{
    return {.width = image.width, .height = image.height, .channels = 3, .pixels = image.rgb};
}

} // namespace

std::vector<std::uint8_t> encode_png(const Image& image)
{
    return encode_png(texture_of(image));
}

void write_png(const std::filesystem::path& path, const Image& image)
{
    write_png(path, texture_of(image));
}

} // namespace pointform
