// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// glTF 2.0 binary (.glb) writer for TexturedMesh, written by hand: the subset is small (one
// buffer, one material, a node per level) and nlohmann-json writes the JSON chunk. See
// docs/gltf-export.md.

#include "pointform/core/error.h"
#include "pointform/io/io.h"
#include "pointform/io/png.h"
#include "pointform/io/textured_export.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <bit>
#include <limits>
#include <optional>
#include <string>

namespace pointform {
namespace {

using nlohmann::json;

// glTF enumerations (the OpenGL constants the specification uses).
constexpr int gl_array_buffer = 34962;
constexpr int gl_element_array_buffer = 34963;
constexpr int gl_unsigned_short = 5123;
constexpr int gl_unsigned_int = 5125;
constexpr int gl_float = 5126;
constexpr int gl_linear = 9729;
constexpr int gl_linear_mipmap_linear = 9987;
constexpr int gl_clamp_to_edge = 33071;
constexpr int gl_triangles = 4;

constexpr std::uint32_t glb_magic = 0x46546C67; // "glTF"
constexpr std::uint32_t glb_version = 2;
constexpr std::uint32_t glb_chunk_json = 0x4E4F534A; // "JSON"
constexpr std::uint32_t glb_chunk_bin = 0x004E4942;  // "BIN\0"

// The buffer holds the vertex arrays' bytes as they are in memory; glTF's are little-endian.
static_assert(std::endian::native == std::endian::little, "the glTF writer assumes little-endian");

constexpr std::size_t padded4(std::size_t n)
{
    return (n + 3) & ~std::size_t{3};
}

/// The BIN chunk being built and the bufferViews into it; every view starts 4-byte aligned.
class BinaryBuffer
{
public:
    /// Appends `size` bytes as a new bufferView (with `target` and `stride`, if any) and returns
    /// its index.
    std::size_t add_view(const void* data, std::size_t size, std::optional<int> target,
                         std::size_t stride = 0)
    {
        bytes_.resize(padded4(bytes_.size()), 0);
        const std::size_t offset = bytes_.size();
        const auto* first = static_cast<const std::uint8_t*>(data);
        bytes_.insert(bytes_.end(), first, first + size);
        json view = {{"buffer", 0}, {"byteOffset", offset}, {"byteLength", size}};
        if (target)
            view["target"] = *target;
        if (stride > 0)
            view["byteStride"] = stride;
        views_.push_back(std::move(view));
        return views_.size() - 1;
    }

    [[nodiscard]] std::vector<std::uint8_t>& bytes() { return bytes_; }
    [[nodiscard]] json& views() { return views_; }

private:
    std::vector<std::uint8_t> bytes_;
    json views_ = json::array();
};

template <typename Vector>
std::size_t add_vertex_view(BinaryBuffer& buffer, const std::vector<Vector>& values)
{
    static_assert(sizeof(Vector) == Vector::SizeAtCompileTime * sizeof(float));
    // The stride is explicit: every level's accessor reads the same view (glTF requires
    // byteStride on a vertex bufferView that several accessors use).
    return buffer.add_view(values.data(), values.size() * sizeof(Vector), gl_array_buffer,
                           sizeof(Vector));
}

/// Accessor over the first `count` vertices of an attribute's bufferView.
json vertex_accessor(std::size_t view, std::size_t count, const char* type)
{
    return {{"bufferView", view},
            {"byteOffset", 0},
            {"componentType", gl_float},
            {"count", count},
            {"type", type}};
}

/// The indices of one level, 16-bit when every index fits below 65535 (the largest value of
/// each type is reserved by glTF for primitive restart), else 32-bit.
json index_accessor(BinaryBuffer& buffer, const std::vector<Triangle>& faces,
                    std::size_t vertex_count)
{
    const std::size_t count = 3 * faces.size();
    std::size_t view = 0;
    int type = gl_unsigned_int;
    if (vertex_count <= std::numeric_limits<std::uint16_t>::max())
    {
        std::vector<std::uint16_t> small;
        small.reserve(count);
        for (const Triangle& t : faces)
            for (const std::uint32_t v : t)
                small.push_back(static_cast<std::uint16_t>(v));
        view = buffer.add_view(small.data(), small.size() * sizeof(std::uint16_t),
                               gl_element_array_buffer);
        type = gl_unsigned_short;
    }
    else
    {
        static_assert(sizeof(Triangle) == 3 * sizeof(std::uint32_t));
        view =
            buffer.add_view(faces.data(), faces.size() * sizeof(Triangle), gl_element_array_buffer);
    }
    return {{"bufferView", view},
            {"byteOffset", 0},
            {"componentType", type},
            {"count", count},
            {"type", "SCALAR"}};
}

/// An image embedded as PNG: its bufferView, image and texture entries.
std::size_t add_texture(BinaryBuffer& buffer, json& images, json& textures,
                        const TextureImage& image, const std::string& name)
{
    const std::vector<std::uint8_t> png = encode_png(image);
    const std::size_t view = buffer.add_view(png.data(), png.size(), std::nullopt);
    images.push_back({{"bufferView", view}, {"mimeType", "image/png"}, {"name", name}});
    textures.push_back({{"sampler", 0}, {"source", images.size() - 1}, {"name", name}});
    return textures.size() - 1;
}

void append_u32(std::vector<std::uint8_t>& out, std::uint32_t value)
{
    for (unsigned k = 0; k < 4; ++k)
        out.push_back(static_cast<std::uint8_t>(value >> (8U * k)));
}

} // namespace

std::vector<std::uint8_t> encode_gltf(const TexturedMesh& mesh)
{
    check_textured_mesh(mesh);
    const std::size_t levels = mesh.lods.size();
    const bool textured = !mesh.uvs.empty();

    BinaryBuffer buffer;
    const std::size_t position_view = add_vertex_view(buffer, mesh.positions);
    // Views of the optional attributes; `none` when the mesh has no such attribute.
    constexpr std::size_t none = std::numeric_limits<std::size_t>::max();
    const std::size_t normal_view =
        mesh.normals.empty() ? none : add_vertex_view(buffer, mesh.normals);
    const std::size_t uv_view = textured ? add_vertex_view(buffer, mesh.uvs) : none;
    const std::size_t tangent_view =
        mesh.tangents.empty() ? none : add_vertex_view(buffer, mesh.tangents);

    json accessors = json::array();
    json meshes = json::array();
    json nodes = json::array();
    // Running bounds of the prefix: each level's POSITION min and max cover exactly its vertices.
    Vec3f low = Vec3f::Constant(std::numeric_limits<float>::infinity());
    Vec3f high = -low;
    std::size_t bounded = 0;
    for (std::size_t i = 0; i < levels; ++i)
    {
        const std::size_t count = mesh.lod_vertex_counts[i];
        for (; bounded < count; ++bounded)
        {
            low = low.cwiseMin(mesh.positions[bounded]);
            high = high.cwiseMax(mesh.positions[bounded]);
        }
        json attributes;
        json position = vertex_accessor(position_view, count, "VEC3");
        position["min"] = {double(low.x()), double(low.y()), double(low.z())};
        position["max"] = {double(high.x()), double(high.y()), double(high.z())};
        accessors.push_back(std::move(position));
        attributes["POSITION"] = accessors.size() - 1;
        if (normal_view != none)
        {
            accessors.push_back(vertex_accessor(normal_view, count, "VEC3"));
            attributes["NORMAL"] = accessors.size() - 1;
        }
        if (uv_view != none)
        {
            accessors.push_back(vertex_accessor(uv_view, count, "VEC2"));
            attributes["TEXCOORD_0"] = accessors.size() - 1;
        }
        if (tangent_view != none)
        {
            accessors.push_back(vertex_accessor(tangent_view, count, "VEC4"));
            attributes["TANGENT"] = accessors.size() - 1;
        }
        accessors.push_back(index_accessor(buffer, mesh.lods[i], count));
        const std::size_t indices = accessors.size() - 1;

        const std::string name =
            "level " + std::to_string(mesh.lod_levels.empty() ? i : mesh.lod_levels[i]);
        meshes.push_back({{"name", name},
                          {"primitives", json::array({{{"attributes", std::move(attributes)},
                                                       {"indices", indices},
                                                       {"material", 0},
                                                       {"mode", gl_triangles}}})}});
        json node = {{"name", name}, {"mesh", i}};
        if (!mesh.origin.isZero(0.0))
            node["translation"] = {mesh.origin.x(), mesh.origin.y(), mesh.origin.z()};
        nodes.push_back(std::move(node));
    }

    json gltf;
    gltf["asset"] = {{"version", "2.0"}, {"generator", "pointform"}};
    // The finest level is the scene's root; MSFT_lod lists the others, finest first.
    const std::size_t root = levels - 1;
    if (levels > 1)
    {
        json ids = json::array();
        for (std::size_t i = root; i-- > 0;)
            ids.push_back(i);
        nodes[root]["extensions"]["MSFT_lod"] = {{"ids", std::move(ids)}};
        gltf["extensionsUsed"] = json::array({"MSFT_lod"});
    }
    gltf["scene"] = 0;
    gltf["scenes"] = json::array({{{"name", mesh.name}, {"nodes", json::array({root})}}});
    gltf["nodes"] = std::move(nodes);
    gltf["meshes"] = std::move(meshes);

    json material = {{"name", mesh.name},
                     {"pbrMetallicRoughness", {{"metallicFactor", 0.0}, {"roughnessFactor", 1.0}}},
                     {"doubleSided", false}};
    json images = json::array();
    json textures = json::array();
    if (textured && !mesh.base_color.empty())
        material["pbrMetallicRoughness"]["baseColorTexture"] = {
            {"index", add_texture(buffer, images, textures, mesh.base_color, "base color")},
            {"texCoord", 0}};
    if (textured && !mesh.normal_map.empty())
        material["normalTexture"] = {
            {"index", add_texture(buffer, images, textures, mesh.normal_map, "normal map")},
            {"texCoord", 0}};
    gltf["materials"] = json::array({std::move(material)});
    if (!textures.empty())
    {
        // Atlas charts end at the image's border: clamp rather than wrap.
        gltf["samplers"] = json::array({{{"magFilter", gl_linear},
                                         {"minFilter", gl_linear_mipmap_linear},
                                         {"wrapS", gl_clamp_to_edge},
                                         {"wrapT", gl_clamp_to_edge}}});
        gltf["images"] = std::move(images);
        gltf["textures"] = std::move(textures);
    }
    gltf["accessors"] = std::move(accessors);
    std::vector<std::uint8_t>& bin = buffer.bytes();
    gltf["buffers"] = json::array({{{"byteLength", bin.size()}}});
    gltf["bufferViews"] = std::move(buffer.views());

    std::string text = gltf.dump();
    text.resize(padded4(text.size()), ' ');
    bin.resize(padded4(bin.size()), 0);
    const std::uint64_t total = 12 + 8 + std::uint64_t{text.size()} + 8 + std::uint64_t{bin.size()};
    if (total > std::numeric_limits<std::uint32_t>::max())
        throw InvalidInput("encode_gltf: the file would have " + std::to_string(total) +
                           " bytes, more than the 4 GiB a GLB file can hold");

    std::vector<std::uint8_t> out;
    out.reserve(static_cast<std::size_t>(total));
    append_u32(out, glb_magic);
    append_u32(out, glb_version);
    append_u32(out, static_cast<std::uint32_t>(total));
    append_u32(out, static_cast<std::uint32_t>(text.size()));
    append_u32(out, glb_chunk_json);
    out.insert(out.end(), text.begin(), text.end());
    append_u32(out, static_cast<std::uint32_t>(bin.size()));
    append_u32(out, glb_chunk_bin);
    out.insert(out.end(), bin.begin(), bin.end());
    return out;
}

void write_gltf(const std::filesystem::path& path, const TexturedMesh& mesh)
{
    write_file_atomically(path, encode_gltf(mesh));
}

} // namespace pointform
