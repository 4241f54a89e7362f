// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// libFuzzer harness for the hierarchy reader (read_hierarchy, docs/hierarchy-format.md). The
// first byte is a switch, the rest the file: unless the switch is odd, the file's last 8 bytes
// are replaced by the checksum of the rest, so that most inputs get past the checksum to the
// structure checks. Any outcome
// but success or a pointform::Error (a crash, a hang, a sanitizer report, another exception) is a
// bug, and so is a hierarchy that comes out with a face naming a vertex it does not have.

#include "pointform/core/error.h"
#include "pointform/io/hierarchy.h"

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

namespace {

/// Overwrites the last 8 bytes with the FNV-1a 64 checksum of the bytes before them.
void reseal(std::vector<std::uint8_t>& bytes)
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
    std::vector<std::uint8_t> bytes(data + 1, data + size);
    if (data[0] % 2 == 0)
        reseal(bytes);
    const std::filesystem::path path = std::filesystem::temp_directory_path() /
                                       ("pointform_fuzz_" + std::to_string(::getpid()) + ".pfh");
    if (FILE* file = std::fopen(path.c_str(), "wb"))
    {
        std::fwrite(bytes.data(), 1, bytes.size(), file);
        std::fclose(file);
    }
    try
    {
        const pointform::MultiresMesh mesh = pointform::read_hierarchy(path);
        // The reader validated the structure: every level must come out whole.
        for (std::size_t level = 0; level <= mesh.finest_level(); ++level)
        {
            const pointform::TriMesh m = mesh.level_mesh(level);
            for (const auto& t : m.triangles)
                for (const auto v : t)
                    if (v >= m.vertex_count())
                        __builtin_trap();
        }
    }
    catch (const pointform::Error&)
    {}
    std::error_code ec;
    std::filesystem::remove(path, ec);
    return 0;
}
