// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// libFuzzer harness for every reader: the first byte picks the format (file extension; ".pfh" is
// the hierarchy reader), the rest is the file. Any outcome but success or a pointform::Error (a
// crash, a hang, a sanitizer report, another exception) is a bug.

#include "pointform/core/error.h"
#include "pointform/io/hierarchy.h"
#include "pointform/io/io.h"

#include <unistd.h>

#include <array>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

namespace {

constexpr std::array<const char*, 9> extensions = {".ply", ".xyz", ".pts", ".csv", ".off",
                                                   ".obj", ".pcd", ".las", ".pfh"};

/// Overwrites the last 8 bytes of a would-be hierarchy file with the FNV-1a 64 checksum of the
/// rest, as docs/hierarchy-format.md defines it, so that the fuzzer gets past the checksum to the
/// structure checks.
void reseal_hierarchy(std::vector<std::uint8_t>& bytes)
{
    if (bytes.size() < 8)
        return;
    std::uint64_t hash = 0xcbf29ce484222325ULL;
    for (std::size_t i = 0; i + 8 < bytes.size(); ++i)
        hash = (hash ^ bytes[i]) * 0x100000001b3ULL;
    for (std::size_t k = 0; k < 8; ++k)
        bytes[bytes.size() - 8 + k] = static_cast<std::uint8_t>(hash >> (8 * k));
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    if (size == 0)
        return 0;
    const std::filesystem::path path =
        std::filesystem::temp_directory_path() /
        ("pointform_fuzz_" + std::to_string(::getpid()) + extensions[data[0] % extensions.size()]);
    std::vector<std::uint8_t> bytes(data + 1, data + size);
    if (path.extension() == ".pfh" && (data[0] / extensions.size()) % 2 == 1)
        reseal_hierarchy(bytes);
    if (FILE* file = std::fopen(path.c_str(), "wb"))
    {
        std::fwrite(bytes.data(), 1, bytes.size(), file);
        std::fclose(file);
    }
    try
    {
        if (path.extension() == ".pfh")
        {
            // The reader validated the structure: the finest level must come out whole.
            const pointform::MultiresMesh mesh = pointform::read_hierarchy(path);
            const pointform::TriMesh finest = mesh.level_mesh(mesh.finest_level());
            for (const auto& t : finest.triangles)
                for (const auto v : t)
                    if (v >= finest.vertex_count())
                        __builtin_trap();
        }
        else
        {
            const pointform::ReadResult result = pointform::read_geometry(path);
            for (const auto& t : result.triangles)
                for (const auto v : t)
                    if (v >= result.points.size())
                        __builtin_trap(); // a reader let an out-of-range face index through
        }
    }
    catch (const pointform::Error&)
    {}
    std::error_code ec;
    std::filesystem::remove(path, ec);
    return 0;
}
