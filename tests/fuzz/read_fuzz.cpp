// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// libFuzzer harness for every reader: the first byte picks the format (file extension), the rest
// is the file. Any outcome but success or a pointform::Error (a crash, a hang, a sanitizer report,
// another exception) is a bug.

#include "pointform/core/error.h"
#include "pointform/io/io.h"

#include <unistd.h>

#include <array>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>

namespace {

constexpr std::array<const char*, 8> extensions = {".ply", ".xyz", ".pts", ".csv",
                                                   ".off", ".obj", ".pcd", ".las"};

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    if (size == 0)
        return 0;
    const std::filesystem::path path =
        std::filesystem::temp_directory_path() /
        ("pointform_fuzz_" + std::to_string(::getpid()) + extensions[data[0] % extensions.size()]);
    if (FILE* file = std::fopen(path.c_str(), "wb"))
    {
        std::fwrite(data + 1, 1, size - 1, file);
        std::fclose(file);
    }
    try
    {
        const pointform::ReadResult result = pointform::read_geometry(path);
        for (const auto& t : result.triangles)
            for (const auto v : t)
                if (v >= result.points.size())
                    __builtin_trap(); // a reader let an out-of-range face index through
    }
    catch (const pointform::Error&)
    {}
    std::error_code ec;
    std::filesystem::remove(path, ec);
    return 0;
}
