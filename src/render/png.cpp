// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/core/error.h"
#include "pointform/io/io.h"
#include "pointform/render/render.h"

#include <stb_image_write.h> // compiled in Debian's libstb

#include <string>

namespace pointform {
namespace {

void append_bytes(void* context, void* data, int size)
{
    auto* out = static_cast<std::vector<std::uint8_t>*>(context);
    const auto* bytes = static_cast<const std::uint8_t*>(data);
    out->insert(out->end(), bytes, bytes + size);
}

} // namespace

std::vector<std::uint8_t> encode_png(const Image& image)
{
    if (image.width <= 0 || image.height <= 0 ||
        image.rgb.size() !=
            static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height) * 3)
        throw InvalidInput("encode_png: the image is " + std::to_string(image.width) + " by " +
                           std::to_string(image.height) + " pixels but holds " +
                           std::to_string(image.rgb.size()) + " bytes");
    std::vector<std::uint8_t> png;
    if (stbi_write_png_to_func(&append_bytes, &png, image.width, image.height, 3, image.rgb.data(),
                               image.width * 3) == 0)
        throw Error("encode_png: stb_image_write failed");
    return png;
}

void write_png(const std::filesystem::path& path, const Image& image)
{
    write_file_atomically(path, encode_png(image));
}

} // namespace pointform
