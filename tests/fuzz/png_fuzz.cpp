// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// libFuzzer harness for the PNG decoder (decode_png, libpng underneath), with the limits lowered
// to 1024 pixels a side and 4 MiB so that a forged header cannot make one run allocate much. Any
// outcome but an image of the announced size or a pointform::Error (a crash, a hang, a sanitizer
// report, another exception) is a bug; a decoded image is encoded and decoded again and must
// give back the same pixels.

#include "pointform/core/error.h"
#include "pointform/io/png.h"

#include <cstdint>
#include <span>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    const pointform::PngLimits limits{.max_side = 1024, .max_bytes = std::uint64_t{4} << 20U};
    try
    {
        const pointform::TextureImage image =
            pointform::decode_png(std::span(data, size), "fuzz.png", limits);
        if (image.width <= 0 || image.height <= 0 || image.width > limits.max_side ||
            image.height > limits.max_side || (image.channels != 3 && image.channels != 4) ||
            image.pixels.size() !=
                std::size_t(image.width) * std::size_t(image.height) * std::size_t(image.channels))
            __builtin_trap();
        const pointform::TextureImage again =
            pointform::decode_png(pointform::encode_png(image), "again.png", limits);
        if (again.pixels != image.pixels || again.channels != image.channels)
            __builtin_trap();
    }
    catch (const pointform::Error&)
    {}
    return 0;
}
