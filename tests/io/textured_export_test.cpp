// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// The glTF binary read back byte by byte (header, chunks, alignment, the JSON parsed with
// nlohmann): every level's accessors are prefixes of one bufferView with the prefix's POSITION
// bounds, the indices are the level's faces, MSFT_lod lists the coarser nodes finest first, the
// textures are the images as PNG. The OBJ text: world positions, v flipped, index triples, its
// MTL; and every inconsistent TexturedMesh refused.

#include "pointform/io/textured_export.h"

#include "pointform/core/error.h"
#include "pointform/io/io.h"
#include "pointform/io/png.h"
#include "pointform/multires/export.h"

#include "support/test_support.h"
#include "support/textured_fixtures.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <charconv>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <limits>
#include <numeric>
#include <span>
#include <sstream>
#include <string>
#include <vector>

namespace pointform {
namespace {

using nlohmann::json;

std::vector<std::size_t> all_levels(const MultiresMesh& mesh)
{
    std::vector<std::size_t> levels(mesh.level_count());
    std::iota(levels.begin(), levels.end(), std::size_t{0});
    return levels;
}

std::uint32_t le32(std::span<const std::uint8_t> bytes, std::size_t at)
{
    std::uint32_t value = 0;
    std::memcpy(&value, bytes.data() + at, 4);
    return value;
}

/// A .glb taken apart, checking the container as it goes.
struct Glb
{
    json gltf;
    std::vector<std::uint8_t> bin;

    explicit Glb(std::span<const std::uint8_t> bytes)
    {
        EXPECT_EQ(bytes.size() % 4, 0U);
        EXPECT_EQ(le32(bytes, 0), 0x46546C67U); // "glTF"
        EXPECT_EQ(le32(bytes, 4), 2U);
        EXPECT_EQ(le32(bytes, 8), bytes.size());
        const std::uint32_t json_length = le32(bytes, 12);
        EXPECT_EQ(json_length % 4, 0U);
        EXPECT_EQ(le32(bytes, 16), 0x4E4F534AU); // "JSON"
        const std::string text(reinterpret_cast<const char*>(bytes.data()) + 20, json_length);
        gltf = json::parse(text); // trailing spaces are JSON whitespace
        const std::size_t bin_at = 20 + json_length;
        const std::uint32_t bin_length = le32(bytes, bin_at);
        EXPECT_EQ(bin_length % 4, 0U);
        EXPECT_EQ(le32(bytes, bin_at + 4), 0x004E4942U); // "BIN\0"
        EXPECT_EQ(bin_at + 8 + bin_length, bytes.size());
        bin.assign(bytes.begin() + std::ptrdiff_t(bin_at + 8), bytes.end());
        const std::size_t declared = gltf["buffers"][0]["byteLength"].get<std::size_t>();
        EXPECT_LE(declared, bin.size());
        EXPECT_LT(bin.size() - declared, 4U); // only the padding after the buffer
    }

    /// The bytes of an accessor's bufferView from the accessor's offset on.
    [[nodiscard]] std::span<const std::uint8_t> view_of(const json& accessor) const
    {
        const json& view = gltf["bufferViews"][accessor["bufferView"].get<std::size_t>()];
        const std::size_t offset =
            view["byteOffset"].get<std::size_t>() + accessor.value("byteOffset", std::size_t{0});
        return std::span(bin).subspan(offset, view["byteLength"].get<std::size_t>());
    }

    [[nodiscard]] const json& accessor(const json& index) const
    {
        return gltf["accessors"][index.get<std::size_t>()];
    }
};

TexturedMesh textured_plate()
{
    const MultiresMesh hierarchy = test::plate_hierarchy(3);
    TexturedMesh mesh = level_chain(hierarchy, all_levels(hierarchy));
    test::add_plate_texture(mesh);
    return mesh;
}

TEST(Gltf, LevelsArePrefixesOfOneBufferWithTheirBounds)
{
    const TexturedMesh mesh = textured_plate();
    const std::vector<std::uint8_t> bytes = encode_gltf(mesh);
    const Glb glb(bytes);
    const json& gltf = glb.gltf;
    EXPECT_EQ(gltf["asset"]["version"], "2.0");

    // Every bufferView 4-byte aligned inside the buffer.
    for (const json& view : gltf["bufferViews"])
    {
        EXPECT_EQ(view["byteOffset"].get<std::size_t>() % 4, 0U);
        EXPECT_LE(view["byteOffset"].get<std::size_t>() + view["byteLength"].get<std::size_t>(),
                  gltf["buffers"][0]["byteLength"].get<std::size_t>());
    }

    const std::size_t levels = mesh.lods.size();
    ASSERT_EQ(gltf["meshes"].size(), levels);
    ASSERT_EQ(gltf["nodes"].size(), levels);
    const json& first = gltf["meshes"][0]["primitives"][0]["attributes"];
    for (std::size_t i = 0; i < levels; ++i)
    {
        SCOPED_TRACE("level " + std::to_string(i));
        const std::size_t count = mesh.lod_vertex_counts[i];
        const json& primitive = gltf["meshes"][i]["primitives"][0];
        EXPECT_EQ(gltf["meshes"][i]["name"], "level " + std::to_string(i));
        EXPECT_EQ(gltf["nodes"][i]["name"], "level " + std::to_string(i));
        EXPECT_EQ(gltf["nodes"][i]["mesh"], i);
        EXPECT_EQ(primitive["mode"], 4);
        EXPECT_EQ(primitive["material"], 0);
        for (const char* name : {"POSITION", "NORMAL", "TEXCOORD_0", "TANGENT"})
        {
            SCOPED_TRACE(name);
            ASSERT_TRUE(primitive["attributes"].contains(name));
            const json& accessor = glb.accessor(primitive["attributes"][name]);
            EXPECT_EQ(accessor["count"], count);
            EXPECT_EQ(accessor["componentType"], 5126);
            EXPECT_EQ(accessor.value("byteOffset", 0), 0);
            // One bufferView per attribute, shared by every level.
            EXPECT_EQ(accessor["bufferView"], glb.accessor(first[name])["bufferView"]);
            const json& view = gltf["bufferViews"][accessor["bufferView"].get<std::size_t>()];
            EXPECT_EQ(view["target"], 34962);
            // Shared by several accessors: glTF wants the stride (tightly packed here).
            const std::size_t size = std::string(name) == "TEXCOORD_0" ? 8
                                     : std::string(name) == "TANGENT"  ? 16
                                                                       : 12;
            EXPECT_EQ(view["byteStride"], size);
            EXPECT_EQ(view["byteLength"], size * mesh.positions.size());
        }
        // POSITION: the bytes are the positions; min and max those of the prefix exactly.
        const json& position = glb.accessor(primitive["attributes"]["POSITION"]);
        const std::span<const std::uint8_t> data = glb.view_of(position);
        ASSERT_EQ(data.size(), mesh.positions.size() * 12);
        Vec3f low = Vec3f::Constant(std::numeric_limits<float>::infinity());
        Vec3f high = -low;
        for (std::size_t v = 0; v < count; ++v)
        {
            Vec3f p;
            std::memcpy(p.data(), data.data() + 12 * v, 12);
            ASSERT_EQ(p, mesh.positions[v]);
            low = low.cwiseMin(p);
            high = high.cwiseMax(p);
        }
        for (int axis = 0; axis < 3; ++axis)
        {
            EXPECT_EQ(position["min"][axis].get<float>(), low[axis]);
            EXPECT_EQ(position["max"][axis].get<float>(), high[axis]);
        }
        // TEXCOORD_0 holds the uvs unflipped (glTF's origin is the top-left corner, as ours).
        const std::span<const std::uint8_t> uvs =
            glb.view_of(glb.accessor(primitive["attributes"]["TEXCOORD_0"]));
        Vec2f uv;
        std::memcpy(uv.data(), uvs.data() + 8 * (count - 1), 8);
        EXPECT_EQ(uv, mesh.uvs[count - 1]);

        // Indices: the level's faces, 16-bit (this plate is small).
        const json& indices = glb.accessor(primitive["indices"]);
        EXPECT_EQ(indices["count"], 3 * mesh.lods[i].size());
        EXPECT_EQ(indices["componentType"], 5123);
        EXPECT_EQ(indices["type"], "SCALAR");
        EXPECT_EQ(gltf["bufferViews"][indices["bufferView"].get<std::size_t>()]["target"], 34963);
        const std::span<const std::uint8_t> index_bytes = glb.view_of(indices);
        ASSERT_EQ(index_bytes.size(), 6 * mesh.lods[i].size());
        for (std::size_t f = 0; f < mesh.lods[i].size(); ++f)
            for (std::size_t k = 0; k < 3; ++k)
            {
                std::uint16_t index = 0;
                std::memcpy(&index, index_bytes.data() + 2 * (3 * f + k), 2);
                ASSERT_EQ(index, mesh.lods[i][f][k]);
            }
        // Every node at the hierarchy's origin.
        for (int axis = 0; axis < 3; ++axis)
            EXPECT_EQ(gltf["nodes"][i]["translation"][axis].get<double>(), mesh.origin[axis]);
    }
}

TEST(Gltf, MsftLodListsTheCoarserNodesFinestFirst)
{
    const TexturedMesh mesh = textured_plate();
    const Glb glb(encode_gltf(mesh));
    const json& gltf = glb.gltf;
    ASSERT_EQ(gltf["extensionsUsed"], json::array({"MSFT_lod"}));
    EXPECT_FALSE(gltf.contains("extensionsRequired")); // loaders without it see the finest
    EXPECT_EQ(gltf["scene"], 0);
    ASSERT_EQ(gltf["scenes"][0]["nodes"], json::array({3})); // the finest level is the root
    EXPECT_EQ(gltf["nodes"][3]["extensions"]["MSFT_lod"]["ids"], json::array({2, 1, 0}));
    for (std::size_t i = 0; i < 3; ++i)
        EXPECT_FALSE(gltf["nodes"][i].contains("extensions"));

    // Level numbers from lod_levels name the nodes; one level needs no extension.
    const MultiresMesh hierarchy = test::plate_hierarchy(3);
    const std::vector<std::size_t> levels = {1, 3};
    const Glb two(encode_gltf(level_chain(hierarchy, levels)));
    EXPECT_EQ(two.gltf["nodes"][0]["name"], "level 1");
    EXPECT_EQ(two.gltf["nodes"][1]["name"], "level 3");
    EXPECT_EQ(two.gltf["nodes"][1]["extensions"]["MSFT_lod"]["ids"], json::array({0}));
    const std::vector<std::size_t> one_level = {2};
    const Glb one(encode_gltf(level_chain(hierarchy, one_level)));
    EXPECT_FALSE(one.gltf.contains("extensionsUsed"));
    EXPECT_EQ(one.gltf["scenes"][0]["nodes"], json::array({0}));
    EXPECT_FALSE(one.gltf["nodes"][0].contains("extensions"));
}

TEST(Gltf, TexturesAreThePngImagesInTheBuffer)
{
    const TexturedMesh mesh = textured_plate();
    const Glb glb(encode_gltf(mesh));
    const json& gltf = glb.gltf;
    const json& material = gltf["materials"][0];
    EXPECT_EQ(material["pbrMetallicRoughness"]["metallicFactor"], 0.0);
    EXPECT_EQ(material["doubleSided"], false);
    const auto image_of = [&](const json& texture_ref) {
        const json& texture = gltf["textures"][texture_ref["index"].get<std::size_t>()];
        const json& image = gltf["images"][texture["source"].get<std::size_t>()];
        EXPECT_EQ(image["mimeType"], "image/png");
        EXPECT_FALSE(image.contains("uri"));
        const json& view = gltf["bufferViews"][image["bufferView"].get<std::size_t>()];
        EXPECT_FALSE(view.contains("target"));
        EXPECT_FALSE(view.contains("byteStride"));
        const std::span<const std::uint8_t> png = std::span(glb.bin).subspan(
            view["byteOffset"].get<std::size_t>(), view["byteLength"].get<std::size_t>());
        return decode_png(png, "embedded");
    };
    const TextureImage color = image_of(material["pbrMetallicRoughness"]["baseColorTexture"]);
    EXPECT_EQ(color.pixels, mesh.base_color.pixels);
    EXPECT_EQ(color.width, mesh.base_color.width);
    const TextureImage normal = image_of(material["normalTexture"]);
    EXPECT_EQ(normal.pixels, mesh.normal_map.pixels);
    EXPECT_EQ(gltf["images"].size(), 2U);
    EXPECT_EQ(gltf["samplers"][0]["wrapS"], 33071);
}

TEST(Gltf, WithoutUvsThereIsNoTextureAndNoTexcoord)
{
    const MultiresMesh hierarchy = test::sphere_hierarchy(2);
    const TexturedMesh mesh = level_chain(hierarchy, all_levels(hierarchy));
    const Glb glb(encode_gltf(mesh));
    const json& gltf = glb.gltf;
    for (const json& m : gltf["meshes"])
    {
        const json& attributes = m["primitives"][0]["attributes"];
        EXPECT_TRUE(attributes.contains("POSITION"));
        EXPECT_TRUE(attributes.contains("NORMAL"));
        EXPECT_FALSE(attributes.contains("TEXCOORD_0"));
        EXPECT_FALSE(attributes.contains("TANGENT"));
    }
    EXPECT_FALSE(gltf.contains("images"));
    EXPECT_FALSE(gltf.contains("textures"));
    EXPECT_FALSE(gltf["materials"][0]["pbrMetallicRoughness"].contains("baseColorTexture"));
    EXPECT_FALSE(gltf["materials"][0].contains("normalTexture"));
    EXPECT_EQ(gltf["materials"][0]["pbrMetallicRoughness"]["metallicFactor"], 0.0);
    EXPECT_FALSE(gltf["nodes"][0].contains("translation")); // the sphere's origin is 0
}

TEST(Gltf, LargeLevelsUse32BitIndices)
{
    // Level 7 of an icosahedron has 163842 vertices: more than 16-bit indices can name.
    const MultiresMesh hierarchy = test::sphere_hierarchy(7);
    const std::vector<std::size_t> levels = {0, 7};
    const TexturedMesh mesh = level_chain(hierarchy, levels);
    const Glb glb(encode_gltf(mesh));
    const json& coarse = glb.accessor(glb.gltf["meshes"][0]["primitives"][0]["indices"]);
    const json& fine = glb.accessor(glb.gltf["meshes"][1]["primitives"][0]["indices"]);
    EXPECT_EQ(coarse["componentType"], 5123);
    EXPECT_EQ(fine["componentType"], 5125);
    const std::span<const std::uint8_t> bytes = glb.view_of(fine);
    ASSERT_EQ(bytes.size(), 12 * mesh.lods[1].size());
    EXPECT_EQ(std::memcmp(bytes.data(), mesh.lods[1].data(), bytes.size()), 0);
    EXPECT_EQ(
        glb.accessor(glb.gltf["meshes"][1]["primitives"][0]["attributes"]["POSITION"])["count"],
        163842);
}

TEST(Gltf, WriteIsAtomic)
{
    test::TempDir dir;
    const TexturedMesh mesh = textured_plate();
    const auto path = dir / "plate.glb";
    write_gltf(path, mesh);
    const std::string file = test::read_file(path);
    const std::vector<std::uint8_t> bytes = encode_gltf(mesh);
    EXPECT_EQ(file, std::string(bytes.begin(), bytes.end()));
    EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir.path()),
                            std::filesystem::directory_iterator()),
              1);
    EXPECT_THROW(write_gltf(dir / "missing" / "x.glb", mesh), IoError);
}

TEST(TexturedExport, InconsistentMeshesAreRefused)
{
    const TexturedMesh good = textured_plate();
    EXPECT_NO_THROW(check_textured_mesh(good));
    const auto refused = [](const TexturedMesh& mesh, const char* why) {
        SCOPED_TRACE(why);
        EXPECT_THROW(check_textured_mesh(mesh), InvalidInput);
        EXPECT_THROW((void)encode_gltf(mesh), InvalidInput);
        EXPECT_THROW((void)obj_text(mesh, 0, {}), InvalidInput);
    };
    TexturedMesh m = good;
    m.lods[1][0][2] = static_cast<std::uint32_t>(m.lod_vertex_counts[1]);
    refused(m, "index beyond the level's prefix");
    m = good;
    std::swap(m.lod_vertex_counts[0], m.lod_vertex_counts[1]);
    refused(m, "vertex counts decreasing");
    m = good;
    m.lod_vertex_counts.pop_back();
    refused(m, "a count missing");
    m = good;
    m.lods[0].clear();
    refused(m, "a level without triangles");
    m = good;
    m.uvs.clear();
    refused(m, "a texture without uvs");
    m = good;
    m.normals.pop_back();
    refused(m, "normals not one per vertex");
    m = good;
    m.normals[3] *= 2.0F;
    refused(m, "a normal not of unit length");
    m = good;
    m.tangents[5].w() = 0.5F;
    refused(m, "tangent w not ±1");
    m = good;
    m.positions[7].x() = std::numeric_limits<float>::quiet_NaN();
    refused(m, "a position not finite");
    m = good;
    m.base_color.pixels.pop_back();
    refused(m, "an image of the wrong size");
    m = good;
    m.lods.clear();
    m.lod_vertex_counts.clear();
    m.lod_levels.clear();
    refused(m, "no levels");
    refused(TexturedMesh{}, "nothing at all");
}

/// The lines of `text` that start with `tag` followed by a blank.
std::vector<std::string> lines_of(const std::string& text, const std::string& tag)
{
    std::vector<std::string> out;
    std::istringstream in(text);
    for (std::string line; std::getline(in, line);)
        if (line.rfind(tag + " ", 0) == 0)
            out.push_back(line.substr(tag.size() + 1));
    return out;
}

TEST(Obj, TextHasWorldPositionsFlippedVAndIndexTriples)
{
    const TexturedMesh mesh = textured_plate();
    const std::size_t lod = 2;
    const ObjFileNames names = obj_file_names("out/plate.obj");
    EXPECT_EQ(names.mtl, "plate.mtl");
    EXPECT_EQ(names.base_color, "plate_color.png");
    EXPECT_EQ(names.normal_map, "plate_normal.png");
    const std::string obj = obj_text(mesh, lod, names);
    const std::size_t count = mesh.lod_vertex_counts[lod];

    EXPECT_EQ(lines_of(obj, "mtllib"), std::vector<std::string>{"plate.mtl"});
    EXPECT_EQ(lines_of(obj, "usemtl"), std::vector<std::string>{"textured_plate"});
    const std::vector<std::string> v = lines_of(obj, "v");
    const std::vector<std::string> vt = lines_of(obj, "vt");
    const std::vector<std::string> vn = lines_of(obj, "vn");
    ASSERT_EQ(v.size(), count);
    ASSERT_EQ(vt.size(), count);
    ASSERT_EQ(vn.size(), count);
    for (std::size_t i = 0; i < count; ++i)
    {
        std::istringstream position(v[i]);
        double x = 0;
        double y = 0;
        double z = 0;
        position >> x >> y >> z;
        // World coordinates: origin + the float position, printed to round-trip exactly.
        EXPECT_EQ(x, mesh.origin.x() + double(mesh.positions[i].x()));
        EXPECT_EQ(y, mesh.origin.y() + double(mesh.positions[i].y()));
        EXPECT_EQ(z, mesh.origin.z() + double(mesh.positions[i].z()));
        std::istringstream uv(vt[i]);
        float s = 0;
        float t = 0;
        uv >> s >> t;
        EXPECT_EQ(s, mesh.uvs[i].x());
        EXPECT_EQ(t, 1.0F - mesh.uvs[i].y()); // OBJ's v grows upwards
    }
    const std::vector<std::string> faces = lines_of(obj, "f");
    ASSERT_EQ(faces.size(), mesh.lods[lod].size());
    for (std::size_t f = 0; f < faces.size(); ++f)
    {
        const Triangle& t = mesh.lods[lod][f];
        const std::string expected = std::to_string(t[0] + 1) + "/" + std::to_string(t[0] + 1) +
                                     "/" + std::to_string(t[0] + 1) + " " +
                                     std::to_string(t[1] + 1) + "/" + std::to_string(t[1] + 1) +
                                     "/" + std::to_string(t[1] + 1) + " " +
                                     std::to_string(t[2] + 1) + "/" + std::to_string(t[2] + 1) +
                                     "/" + std::to_string(t[2] + 1);
        ASSERT_EQ(faces[f], expected);
    }

    const std::string mtl = mtl_text(mesh, names);
    EXPECT_EQ(lines_of(mtl, "newmtl"), std::vector<std::string>{"textured_plate"});
    EXPECT_EQ(lines_of(mtl, "map_Kd"), std::vector<std::string>{"plate_color.png"});
    EXPECT_EQ(lines_of(mtl, "norm"), std::vector<std::string>{"plate_normal.png"});
    EXPECT_EQ(lines_of(mtl, "map_Bump"), std::vector<std::string>{"plate_normal.png"});
    EXPECT_THROW((void)obj_text(mesh, mesh.lods.size(), names), InvalidInput);
}

TEST(Obj, WithoutTextureReadsBackAsTheLevel)
{
    test::TempDir dir;
    const MultiresMesh hierarchy = test::plate_hierarchy(2);
    const std::vector<std::size_t> levels = {0, 2};
    const TexturedMesh mesh = level_chain(hierarchy, levels);
    const std::string obj = obj_text(mesh, 1, obj_file_names(dir / "plate.obj"));
    EXPECT_TRUE(lines_of(obj, "vt").empty());
    EXPECT_TRUE(lines_of(obj, "mtllib").empty());
    EXPECT_EQ(lines_of(obj, "f").front().find("//"), 1U); // "a//a b//b c//c"
    EXPECT_TRUE(mtl_text(mesh, {}).empty());
    EXPECT_FALSE(obj_has_material(mesh));

    // Our own OBJ reader gives back the level: faces exactly, positions to float precision.
    test::write_file(dir / "plate.obj", obj);
    const TriMesh back = read_mesh(dir / "plate.obj");
    const TriMesh level = hierarchy.level_mesh(2);
    EXPECT_EQ(back.triangles, level.triangles);
    ASSERT_EQ(back.vertex_count(), level.vertex_count());
    for (std::size_t v = 0; v < level.vertex_count(); ++v)
    {
        const Vec3d expected = level.vertices.origin + level.vertices.positions[v].cast<double>();
        const Vec3d got = back.vertices.origin + back.vertices.positions[v].cast<double>();
        ASSERT_LT((expected - got).norm(), 1e-4) << "vertex " << v;
    }
}

} // namespace
} // namespace pointform
