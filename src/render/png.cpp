// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/core/error.h"
#include "pointform/render/render.h"

#include <stb_image_write.h> // compiled in Debian's libstb

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <random>
#include <string>

namespace pointform {
namespace {

void append_bytes(void* context, void* data, int size)
{
    auto* out = static_cast<std::vector<std::uint8_t>*>(context);
    const auto* bytes = static_cast<const std::uint8_t*>(data);
    out->insert(out->end(), bytes, bytes + size);
}

std::filesystem::path temporary_name(const std::filesystem::path& path)
{
    static std::atomic<unsigned> counter{0};
    static const unsigned seed = std::random_device{}();
    const unsigned tag = seed ^ (counter.fetch_add(1) * 2654435761U);
    char suffix[16];
    std::snprintf(suffix, sizeof(suffix), "%08x", tag);
    std::filesystem::path temp = path;
    temp += ".tmp-";
    temp += suffix;
    return temp;
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
    const std::vector<std::uint8_t> png = encode_png(image);
    constexpr int attempts = 8;
    std::filesystem::path temp;
    std::FILE* file = nullptr;
    for (int i = 0; i < attempts && file == nullptr; ++i)
    {
        temp = temporary_name(path);
        file = std::fopen(temp.c_str(), "wbx"); // x: fail rather than reuse an existing name
        if (file == nullptr && errno != EEXIST)
            break;
    }
    if (file == nullptr)
        throw IoError(path, std::string("cannot create the file: ") + std::strerror(errno));
    const bool written = std::fwrite(png.data(), 1, png.size(), file) == png.size();
    const int write_errno = errno;
    const bool closed = std::fclose(file) == 0;
    std::error_code ec;
    if (!written || !closed)
    {
        std::filesystem::remove(temp, ec);
        throw IoError(path,
                      std::string("write failed: ") + std::strerror(written ? errno : write_errno));
    }
    std::filesystem::rename(temp, path, ec);
    if (ec)
    {
        std::error_code ignored;
        std::filesystem::remove(temp, ignored);
        throw IoError(path, "cannot move the temporary file into place: " + ec.message());
    }
}

} // namespace pointform
