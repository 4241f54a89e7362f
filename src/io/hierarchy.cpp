// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/io/hierarchy.h"

#include "pointform/io/io.h"

#include "detail_readers.h"

#include <array>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <limits>
#include <memory>
#include <string>
#include <string_view>
#include <utility>

namespace pointform {
namespace {

using detail::fail;
using detail::Location;

constexpr std::uint64_t header_bytes = 56;
constexpr std::uint64_t checksum_bytes = 8;

std::string_view magic_bytes()
{
    return {reinterpret_cast<const char*>(hierarchy_magic.data()), hierarchy_magic.size()};
}

/// FNV-1a, 64 bits (offset basis 0xcbf29ce484222325, prime 0x100000001b3).
std::uint64_t fnv1a64(std::string_view bytes)
{
    std::uint64_t hash = 0xcbf29ce484222325ULL;
    for (const char c : bytes)
    {
        hash ^= static_cast<unsigned char>(c);
        hash *= 0x100000001b3ULL;
    }
    return hash;
}

std::string hex(std::uint64_t value)
{
    char text[24];
    std::snprintf(text, sizeof(text), "0x%016llx", static_cast<unsigned long long>(value));
    return text;
}

/// Bytes the data after the header take, checksum included, for these header counts (no
/// overflow: every count is a u32).
std::uint64_t file_bytes(std::uint64_t levels, std::uint64_t vertices, std::uint64_t base_faces,
                         std::uint64_t parent_edges)
{
    return header_bytes + 12 * base_faces + 4 * (levels + 1) + 8 * parent_edges + 24 * vertices +
           checksum_bytes;
}

template <typename T>
void append_le(std::string& out, T value)
{
    if constexpr (detail::native_byte_order != detail::ByteOrder::Little)
        value = detail::byte_swap(value);
    char bytes[sizeof(T)];
    std::memcpy(bytes, &value, sizeof(T));
    out.append(bytes, sizeof(T));
}

std::uint32_t to_u32(std::size_t value, const char* what)
{
    if (value > std::numeric_limits<std::uint32_t>::max())
        throw InvalidInput(std::string("write_hierarchy: too many ") + what +
                           " for the hierarchy format (32-bit counts)");
    return static_cast<std::uint32_t>(value);
}

struct FileCloser
{
    void operator()(std::FILE* file) const { std::fclose(file); }
};
using FilePtr = std::unique_ptr<std::FILE, FileCloser>;

MultiresMesh decode(const std::filesystem::path& path, std::string_view bytes)
{
    const std::string_view magic = magic_bytes();
    if (!bytes.starts_with(magic))
    {
        if (bytes.size() < magic.size() && magic.starts_with(bytes))
            fail(path,
                 "file is truncated: " + std::to_string(bytes.size()) +
                     " bytes, shorter than the hierarchy magic",
                 Location::at_byte(bytes.size()));
        fail(path,
             "not a pointform hierarchy (the file does not start with the magic bytes "
             "89 50 46 48 0D 0A 1A 0A)",
             Location::at_byte(0));
    }
    detail::ByteCursor cursor(path, bytes, magic.size());
    const auto version = cursor.read_le<std::uint32_t>("the format version");
    if (version != hierarchy_format_version && version != 1)
        fail(path,
             "pointform hierarchy format version " + std::to_string(version) +
                 " is not supported (this build reads versions 1 and " +
                 std::to_string(hierarchy_format_version) + ")",
             Location::at_byte(8));
    cursor.require(header_bytes - cursor.offset(), "the hierarchy header");
    const auto word = cursor.read_le<std::uint32_t>(version == 1 ? "the flags" : "the predictor");
    if (version == 1 && word != 0)
        fail(path, "corrupt hierarchy: unknown flags " + hex(word) + " (version 1 has none)",
             Location::at_byte(12));
    if (version != 1 && word > 1)
        fail(path,
             "corrupt hierarchy: unknown predictor " + std::to_string(word) +
                 " (0 midpoint, 1 butterfly)",
             Location::at_byte(12));
    MultiresParts parts;
    parts.predictor = word == 1 && version != 1 ? Predictor::Butterfly : Predictor::Midpoint;
    for (int axis = 0; axis < 3; ++axis)
        parts.origin[axis] = cursor.read_le<double>("the origin");
    const std::uint64_t levels = cursor.read_le<std::uint32_t>("the level count");
    const std::uint64_t vertices = cursor.read_le<std::uint32_t>("the vertex count");
    const std::uint64_t base_faces = cursor.read_le<std::uint32_t>("the base face count");
    const std::uint64_t parent_edges = cursor.read_le<std::uint32_t>("the parent edge count");

    // The counts fix the file's size: check it before allocating anything for them.
    const std::uint64_t expected = file_bytes(levels, vertices, base_faces, parent_edges);
    const std::string counts = std::to_string(levels) + " levels, " + std::to_string(vertices) +
                               " vertices, " + std::to_string(base_faces) + " base faces and " +
                               std::to_string(parent_edges) + " parent edges";
    if (bytes.size() < expected)
        fail(path,
             "file is truncated: the header announces " + counts + ", which take " +
                 std::to_string(expected) + " bytes, but the file has " +
                 std::to_string(bytes.size()),
             Location::at_byte(bytes.size()));
    if (bytes.size() > expected)
        fail(path,
             "corrupt hierarchy: " + std::to_string(bytes.size() - expected) +
                 " bytes after the end of the data (the header announces " + counts + ", " +
                 std::to_string(expected) + " bytes)",
             Location::at_byte(expected));
    const std::size_t payload = static_cast<std::size_t>(expected - checksum_bytes);
    const std::uint64_t stored =
        detail::load<std::uint64_t>(bytes.data() + payload, detail::ByteOrder::Little);
    const std::uint64_t computed = fnv1a64(bytes.substr(0, payload));
    if (stored != computed)
        fail(path,
             "corrupt hierarchy: checksum mismatch (stored " + hex(stored) + ", computed " +
                 hex(computed) + ")",
             Location::at_byte(payload));

    parts.base_faces.resize(static_cast<std::size_t>(base_faces));
    for (Triangle& t : parts.base_faces)
        for (std::uint32_t& v : t)
            v = cursor.read_le<std::uint32_t>("the base faces");
    parts.level_offsets.resize(static_cast<std::size_t>(levels + 1));
    for (std::size_t& offset : parts.level_offsets)
        offset = cursor.read_le<std::uint32_t>("the level offsets");
    parts.parent_edges.resize(static_cast<std::size_t>(parent_edges));
    for (ParentEdge& e : parts.parent_edges)
    {
        e.a = cursor.read_le<std::uint32_t>("the parent edges");
        e.b = cursor.read_le<std::uint32_t>("the parent edges");
    }
    parts.positions.resize(static_cast<std::size_t>(vertices));
    for (Vec3d& p : parts.positions)
        for (int axis = 0; axis < 3; ++axis)
            p[axis] = cursor.read_le<double>("the positions");
    try
    {
        return MultiresMesh(std::move(parts));
    }
    catch (const InvalidInput& e)
    {
        fail(path, std::string("invalid hierarchy: ") + e.what());
    }
}

} // namespace

void write_hierarchy(const std::filesystem::path& path, const MultiresMesh& mesh)
{
    if (mesh.level_count() == 0)
        throw InvalidInput("write_hierarchy: the hierarchy is empty (no levels)");
    const MultiresParts& p = mesh.parts();
    const std::uint32_t levels = to_u32(mesh.level_count(), "levels");
    const std::uint32_t vertices = to_u32(p.positions.size(), "vertices");
    const std::uint32_t base_faces = to_u32(p.base_faces.size(), "base faces");
    const std::uint32_t parent_edges = to_u32(p.parent_edges.size(), "parent edges");

    std::string out;
    out.reserve(static_cast<std::size_t>(file_bytes(levels, vertices, base_faces, parent_edges)));
    out.append(magic_bytes());
    append_le(out, hierarchy_format_version);
    append_le(out, std::uint32_t{p.predictor == Predictor::Butterfly ? 1U : 0U});
    for (int axis = 0; axis < 3; ++axis)
        append_le(out, p.origin[axis]);
    append_le(out, levels);
    append_le(out, vertices);
    append_le(out, base_faces);
    append_le(out, parent_edges);
    for (const Triangle& t : p.base_faces)
        for (const std::uint32_t v : t)
            append_le(out, v);
    for (const std::size_t offset : p.level_offsets)
        append_le(out, to_u32(offset, "vertices"));
    for (const ParentEdge& e : p.parent_edges)
    {
        append_le(out, e.a);
        append_le(out, e.b);
    }
    for (const Vec3d& position : p.positions)
        for (int axis = 0; axis < 3; ++axis)
            append_le(out, position[axis]);
    append_le(out, fnv1a64(out));
    write_file_atomically(path, std::span<const std::uint8_t>(
                                    reinterpret_cast<const std::uint8_t*>(out.data()), out.size()));
}

MultiresMesh read_hierarchy(const std::filesystem::path& path)
{
    const detail::FileBytes bytes = detail::read_whole_file(path);
    return decode(path, bytes);
}

bool is_hierarchy_file(const std::filesystem::path& path) noexcept
{
    try
    {
        const FilePtr file(std::fopen(path.c_str(), "rb"));
        if (!file)
            return false;
        char head[hierarchy_magic.size()];
        return std::fread(head, 1, sizeof(head), file.get()) == sizeof(head) &&
               std::string_view(head, sizeof(head)) == magic_bytes();
    }
    catch (...)
    {
        return false;
    }
}

std::optional<std::uint32_t> hierarchy_file_version(const std::filesystem::path& path) noexcept
{
    try
    {
        const FilePtr file(std::fopen(path.c_str(), "rb"));
        if (!file)
            return std::nullopt;
        std::array<unsigned char, hierarchy_magic.size() + 4> head{};
        if (std::fread(head.data(), 1, head.size(), file.get()) != head.size() ||
            std::string_view(reinterpret_cast<const char*>(head.data()), hierarchy_magic.size()) !=
                magic_bytes())
            return std::nullopt;
        const std::size_t at = hierarchy_magic.size();
        return static_cast<std::uint32_t>(head[at]) |
               (static_cast<std::uint32_t>(head[at + 1]) << 8) |
               (static_cast<std::uint32_t>(head[at + 2]) << 16) |
               (static_cast<std::uint32_t>(head[at + 3]) << 24);
    }
    catch (...)
    {
        return std::nullopt;
    }
}

} // namespace pointform
