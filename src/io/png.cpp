// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// PNG through libpng's "simplified" API (png_image_*), which catches libpng's errors itself
// (its setjmp/longjmp stays inside libpng's C frames) and reports them as a return value: no
// longjmp crosses a C++ frame and no exception crosses libpng.

#include "pointform/io/png.h"

#include "pointform/core/error.h"
#include "pointform/core/memory.h"
#include "pointform/io/io.h"

#include "detail_readers.h"

#include <png.h>

#include <array>
#include <cstring>
#include <string>
#include <string_view>

namespace pointform {
namespace {

constexpr std::array<std::uint8_t, 8> png_signature = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};

std::string image_size_text(std::uint64_t width, std::uint64_t height)
{
    return std::to_string(width) + " × " + std::to_string(height);
}

/// Frees a png_image's libpng state on every path out of a function.
class ImageGuard
{
public:
    explicit ImageGuard(png_image& image) : image_(&image) {}
    ~ImageGuard() { png_image_free(image_); }
    ImageGuard(const ImageGuard&) = delete;
    ImageGuard& operator=(const ImageGuard&) = delete;

private:
    png_image* image_;
};

void check_image(const TextureImage& image)
{
    const bool channels_ok = image.channels == 3 || image.channels == 4;
    const std::uint64_t expected = image.width > 0 && image.height > 0 && channels_ok
                                       ? std::uint64_t(image.width) * std::uint64_t(image.height) *
                                             std::uint64_t(image.channels)
                                       : 0;
    if (expected == 0 || image.pixels.size() != expected)
        throw InvalidInput("encode_png: the image is " + std::to_string(image.width) + " by " +
                           std::to_string(image.height) + " pixels with " +
                           std::to_string(image.channels) +
                           " channels (3 or 4 expected) but holds " +
                           std::to_string(image.pixels.size()) + " bytes");
}

/// libpng's message, saying "truncated" when it ran out of bytes.
std::string libpng_failure(const char* message)
{
    const std::string_view text(message);
    if (text.find("beyond end of data") != std::string_view::npos ||
        text.find("Not enough image data") != std::string_view::npos)
        return "PNG image is truncated (libpng: " + std::string(text) + ")";
    return "corrupt PNG image (libpng: " + std::string(text) + ")";
}

/// Refuses an image of `width` × `height` pixels of `channels` bytes with `fail(message)` when
/// it has no pixels, a side beyond the limit, or needs more memory than it may.
template <typename Fail>
void check_size(std::uint64_t width, std::uint64_t height, int channels, const PngLimits& limits,
                const Fail& fail)
{
    if (width == 0 || height == 0)
        fail("PNG image of " + image_size_text(width, height) + " pixels has no pixels");
    if (width > std::uint64_t(limits.max_side) || height > std::uint64_t(limits.max_side))
        fail("PNG image of " + image_size_text(width, height) + " pixels is too large: at most " +
             std::to_string(limits.max_side) + " pixels a side are accepted");
    const std::uint64_t need = width * height * std::uint64_t(channels);
    if (need > limits.max_bytes)
        fail("PNG image of " + image_size_text(width, height) + " pixels would need " +
             std::to_string(need) + " bytes decoded, more than the limit of " +
             std::to_string(limits.max_bytes));
    const MemoryLimit memory = memory_limit();
    if (!fits_in_memory(static_cast<double>(need), memory))
        fail("PNG image of " + image_size_text(width, height) + " pixels would need " +
             std::to_string(need) + " bytes decoded, more than 80% of the " +
             std::to_string(memory.bytes) + " bytes this process may use (" + memory.source + ")");
}

} // namespace

std::vector<std::uint8_t> encode_png(const TextureImage& image)
{
    check_image(image);
    png_image png{};
    png.version = PNG_IMAGE_VERSION;
    png.width = static_cast<png_uint_32>(image.width);
    png.height = static_cast<png_uint_32>(image.height);
    png.format = image.channels == 4 ? PNG_FORMAT_RGBA : PNG_FORMAT_RGB;
    const ImageGuard guard(png);
    // One pass into a buffer of libpng's worst-case size (the pixels stored uncompressed, plus
    // zlib's and the chunks' overhead), then trimmed.
    std::vector<std::uint8_t> out(PNG_IMAGE_PNG_SIZE_MAX(png));
    png_alloc_size_t size = out.size();
    if (png_image_write_to_memory(&png, out.data(), &size, 0, image.pixels.data(), 0, nullptr) == 0)
        throw Error(std::string("encode_png: libpng failed: ") + png.message);
    out.resize(size);
    return out;
}

void write_png(const std::filesystem::path& path, const TextureImage& image)
{
    write_file_atomically(path, encode_png(image));
}

TextureImage decode_png(std::span<const std::uint8_t> bytes,
                        const std::filesystem::path& source_name, const PngLimits& limits)
{
    const auto fail = [&](const std::string& what) {
        throw IoError(source_name, what);
    };
    if (bytes.empty())
        fail("empty file, not a PNG image");
    const std::size_t head = std::min(bytes.size(), png_signature.size());
    if (std::memcmp(bytes.data(), png_signature.data(), head) != 0)
        fail("not a PNG image (the file does not start with the PNG signature)");
    // IHDR: 8 signature bytes, then the chunk's length and type (8), width and height (8).
    if (bytes.size() < 33)
        fail("PNG image is truncated: " + std::to_string(bytes.size()) +
             " bytes, too short for its header");

    // The header's sizes, checked here for clear messages (libpng would also refuse a side of 0
    // or beyond 10⁶ pixels, in its own words).
    const auto be32 = [&](std::size_t at) {
        return (std::uint64_t{bytes[at]} << 24U) | (std::uint64_t{bytes[at + 1]} << 16U) |
               (std::uint64_t{bytes[at + 2]} << 8U) | std::uint64_t{bytes[at + 3]};
    };
    if (std::memcmp(bytes.data() + 12, "IHDR", 4) != 0)
        fail("corrupt PNG image: the first chunk is not IHDR");
    check_size(be32(16), be32(20), 3, limits, fail);

    png_image png{};
    png.version = PNG_IMAGE_VERSION;
    const ImageGuard guard(png);
    if (png_image_begin_read_from_memory(&png, bytes.data(), bytes.size()) == 0)
        fail(libpng_failure(png.message));

    const bool alpha = (png.format & PNG_FORMAT_FLAG_ALPHA) != 0;
    const int channels = alpha ? 4 : 3;
    check_size(png.width, png.height, channels, limits, fail);

    png.format = alpha ? PNG_FORMAT_RGBA : PNG_FORMAT_RGB;
    TextureImage image;
    image.width = static_cast<int>(png.width);
    image.height = static_cast<int>(png.height);
    image.channels = channels;
    image.pixels.resize(PNG_IMAGE_SIZE(png));
    if (png_image_finish_read(&png, nullptr, image.pixels.data(), 0, nullptr) == 0)
        fail(libpng_failure(png.message));
    return image;
}

TextureImage read_png(const std::filesystem::path& path, const PngLimits& limits)
{
    const detail::FileBytes bytes = detail::read_whole_file(path);
    return decode_png(std::span<const std::uint8_t>(
                          reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size()),
                      path, limits);
}

} // namespace pointform
