// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// PNG: encode then decode gives back the very pixels (RGB and RGBA, odd sizes); write_png is
// atomic; hostile bytes (truncated, not a PNG, absurd or zero sizes, more than the memory guard)
// give an IoError naming the source, never a crash or a huge allocation.

#include "pointform/io/png.h"

#include "pointform/core/error.h"

#include "support/test_support.h"
#include "support/textured_fixtures.h"

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <filesystem>
#include <iterator>
#include <span>
#include <string>
#include <vector>

namespace pointform {
namespace {

/// CRC-32 of PNG chunks (ISO 3309), bit by bit: enough for the few chunks the tests forge.
std::uint32_t crc32(std::span<const std::uint8_t> bytes)
{
    std::uint32_t crc = 0xFFFFFFFFU;
    for (const std::uint8_t b : bytes)
    {
        crc ^= b;
        for (int k = 0; k < 8; ++k)
            crc = (crc & 1U) != 0 ? (crc >> 1U) ^ 0xEDB88320U : crc >> 1U;
    }
    return crc ^ 0xFFFFFFFFU;
}

void put_be32(std::vector<std::uint8_t>& out, std::uint32_t value)
{
    for (int shift = 24; shift >= 0; shift -= 8)
        out.push_back(static_cast<std::uint8_t>(value >> static_cast<unsigned>(shift)));
}

/// The signature and an IHDR chunk (valid CRC) announcing width × height, 8-bit RGB, followed
/// by `tail` (the rest of the would-be file).
std::vector<std::uint8_t> forged_png(std::uint32_t width, std::uint32_t height,
                                     std::span<const std::uint8_t> tail = {})
{
    std::vector<std::uint8_t> out = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    put_be32(out, 13);
    const std::size_t type_at = out.size();
    out.insert(out.end(), {'I', 'H', 'D', 'R'});
    put_be32(out, width);
    put_be32(out, height);
    out.insert(out.end(), {8, 2, 0, 0, 0}); // bit depth 8, colour type 2 (RGB), no interlace
    put_be32(out, crc32(std::span(out).subspan(type_at)));
    out.insert(out.end(), tail.begin(), tail.end());
    return out;
}

/// Decodes `bytes` expecting an IoError that names `name` and says `words`.
void expect_refused(const std::vector<std::uint8_t>& bytes, const std::string& words,
                    const PngLimits& limits = {})
{
    const std::filesystem::path name = "hostile.png";
    try
    {
        (void)decode_png(bytes, name, limits);
        ADD_FAILURE() << "decoded " << bytes.size() << " hostile bytes; expected: " << words;
    }
    catch (const IoError& e)
    {
        EXPECT_EQ(e.path(), name);
        EXPECT_NE(std::string(e.what()).find("hostile.png"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
    }
}

TEST(Png, RoundTripGivesTheSamePixelsRgbAndRgba)
{
    for (const int channels : {3, 4})
        for (const auto [width, height] : {std::array{1, 1}, std::array{17, 5}, std::array{64, 48}})
        {
            SCOPED_TRACE(std::to_string(width) + "x" + std::to_string(height) + "x" +
                         std::to_string(channels));
            const TextureImage image = test::checker_image(width, height, channels, 3);
            const std::vector<std::uint8_t> png = encode_png(image);
            ASSERT_GT(png.size(), 8U);
            EXPECT_EQ(png[1], 'P');
            const TextureImage back = decode_png(png, "memory");
            EXPECT_EQ(back.width, width);
            EXPECT_EQ(back.height, height);
            EXPECT_EQ(back.channels, channels);
            EXPECT_EQ(back.pixels, image.pixels);
        }
}

TEST(Png, WriteIsAtomicAndReadsBack)
{
    test::TempDir dir;
    const TextureImage image = test::checker_image(33, 21, 4);
    const auto path = dir / "checker.png";
    write_png(path, image);
    const TextureImage back = read_png(path);
    EXPECT_EQ(back.pixels, image.pixels);
    EXPECT_EQ(back.channels, 4);
    EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()),
                            std::filesystem::directory_iterator()),
              1); // no temporary left beside it
    EXPECT_THROW(write_png(dir / "missing" / "x.png", image), IoError);
    EXPECT_THROW((void)read_png(dir / "absent.png"), IoError);
    test::write_file(dir / "empty.png", "");
    EXPECT_THROW((void)read_png(dir / "empty.png"), IoError);
}

TEST(Png, EncodeRefusesInconsistentImages)
{
    TextureImage image = test::checker_image(4, 4, 3);
    image.pixels.pop_back();
    EXPECT_THROW((void)encode_png(image), InvalidInput);
    EXPECT_THROW((void)encode_png(TextureImage{}), InvalidInput);
    TextureImage two = test::checker_image(4, 4, 3);
    two.channels = 2;
    two.pixels.resize(4 * 4 * 2);
    EXPECT_THROW((void)encode_png(two), InvalidInput);
    TextureImage wide{
        .width = -4, .height = -4, .channels = 3, .pixels = std::vector<std::uint8_t>(48)};
    EXPECT_THROW((void)encode_png(wide), InvalidInput);
}

TEST(Png, EveryTruncationIsRefused)
{
    const std::vector<std::uint8_t> png = encode_png(test::checker_image(16, 12, 3));
    // IEND is the last 12 bytes; every prefix that cuts into the image data or before must fail.
    for (std::size_t length = 0; length + 12 < png.size(); ++length)
    {
        SCOPED_TRACE("first " + std::to_string(length) + " of " + std::to_string(png.size()) +
                     " bytes");
        const std::vector<std::uint8_t> cut(png.begin(), png.begin() + std::ptrdiff_t(length));
        EXPECT_THROW((void)decode_png(cut, "cut.png"), IoError);
    }
    expect_refused(std::vector<std::uint8_t>(png.begin(), png.begin() + 40), "truncated");
}

TEST(Png, WrongMagicIsNotAPng)
{
    const std::string gif = "GIF89a\x10\x00\x10\x00 and some more bytes to look like an image";
    expect_refused(std::vector<std::uint8_t>(gif.begin(), gif.end()), "not a PNG");
    const std::string text = "ply\nformat ascii 1.0\nelement vertex 0\nend_header\n";
    expect_refused(std::vector<std::uint8_t>(text.begin(), text.end()), "not a PNG");
    // One flipped signature byte.
    std::vector<std::uint8_t> png = encode_png(test::checker_image(8, 8, 3));
    png[3] = 'H';
    expect_refused(png, "not a PNG");
}

TEST(Png, HugeAndZeroSizesAreRefusedBeforeAllocating)
{
    // 100000 × 100000 RGB would be 30 GB: refused from the header, whatever follows.
    const std::vector<std::uint8_t> idat(64, 0);
    expect_refused(forged_png(100000, 100000, idat), "too large");
    expect_refused(forged_png(16385, 1, idat), "too large");
    expect_refused(forged_png(1, 0xFFFFFFFFU, idat), "too large");
    expect_refused(forged_png(0, 10, idat), "no pixels");
    expect_refused(forged_png(10, 0, idat), "no pixels");
    // Within the sides but beyond a memory guard of 1000 bytes: 32 × 32 × 3 = 3072.
    expect_refused(encode_png(test::checker_image(32, 32, 3)), "more than the limit",
                   {.max_bytes = 1000});
    expect_refused(encode_png(test::checker_image(32, 32, 3)), "too large", {.max_side = 31});
    // A valid header whose data never comes.
    expect_refused(forged_png(64, 64), "PNG image");
}

TEST(Png, CorruptDataIsRefused)
{
    std::vector<std::uint8_t> png = encode_png(test::checker_image(16, 16, 3));
    // Damage the IHDR CRC, then (separately) a byte inside the compressed data.
    std::vector<std::uint8_t> bad_crc = png;
    bad_crc[29] ^= 0xFFU;
    expect_refused(bad_crc, "corrupt");
    // A byte of the compressed pixels (IDAT is critical: its CRC error is an error; an
    // ancillary chunk's, such as sRGB's, is only a warning).
    const std::string text(png.begin(), png.end());
    const std::size_t idat = text.find("IDAT");
    ASSERT_NE(idat, std::string::npos);
    std::vector<std::uint8_t> bad_data = png;
    bad_data[idat + 8] ^= 0x5AU;
    expect_refused(bad_data, "corrupt");
}

/// A seed of the PNG fuzzer (tests/fuzz/seeds/png), hand-made PNGs of every colour type.
TextureImage seed(const std::string& name)
{
    return read_png(std::filesystem::path(PF_DATA_DIR) / ".." / "tests" / "fuzz" / "seeds" / "png" /
                    name);
}

TEST(Png, EveryColourTypeComesOutAsRgbOrRgba)
{
    // Grey is expanded to RGB, sample for sample.
    const TextureImage gray = seed("gray8.png");
    ASSERT_EQ(gray.width, 4);
    ASSERT_EQ(gray.height, 3);
    ASSERT_EQ(gray.channels, 3);
    for (int y = 0; y < 3; ++y)
        for (int x = 0; x < 4; ++x)
            for (int c = 0; c < 3; ++c)
                EXPECT_EQ(gray.pixels[std::size_t(3 * (4 * y + x) + c)], 85 * x);
    // Grey with alpha: RGBA.
    const TextureImage gray_alpha = seed("gray-alpha.png");
    ASSERT_EQ(gray_alpha.channels, 4);
    EXPECT_EQ(gray_alpha.pixels[0], 10);
    EXPECT_EQ(gray_alpha.pixels[3], 255);
    EXPECT_EQ(gray_alpha.pixels[7], 0);
    // A 2-bit palette with a tRNS chunk: RGBA, the palette's colours and the chunk's alphas.
    const TextureImage palette = seed("palette-trns.png");
    ASSERT_EQ(palette.channels, 4);
    EXPECT_EQ(palette.pixels, (std::vector<std::uint8_t>{255, 0, 0, 255, 0, 255, 0, 128, 0, 0, 255,
                                                         0, 9, 9, 9, 255}));
    // 8-bit RGB and RGBA as stored.
    const TextureImage rgb = seed("rgb8.png");
    ASSERT_EQ(rgb.channels, 3);
    for (std::size_t i = 0; i < rgb.pixels.size(); ++i)
        EXPECT_EQ(rgb.pixels[i], i);
    const TextureImage rgba = seed("rgba8.png");
    ASSERT_EQ(rgba.channels, 4);
    for (std::size_t i = 0; i < rgba.pixels.size(); ++i)
        EXPECT_EQ(rgba.pixels[i], i);
    // 16 bits are reduced to 8; a 1-bit interlaced image is expanded.
    const TextureImage deep = seed("rgb16.png");
    EXPECT_EQ(deep.width, 2);
    EXPECT_EQ(deep.channels, 3);
    const TextureImage bit = seed("gray1-interlaced.png");
    EXPECT_EQ(bit.pixels, (std::vector<std::uint8_t>{255, 255, 255}));
}

} // namespace
} // namespace pointform
