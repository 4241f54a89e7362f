// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// Writes the .glb files the test gltf_validator hands to the Khronos glTF validator, into the
// folder given as the only argument: a hierarchy's level-of-detail chain without a texture
// (closed sphere; plate with a boundary and a far origin), the same plate with uvs, a checker
// colour texture (RGB and RGBA), a normal map and tangents, one level alone, and a hierarchy
// file for `pointform export`.

#include "pointform/io/hierarchy.h"
#include "pointform/io/textured_export.h"
#include "pointform/multires/export.h"

#include "support/textured_fixtures.h"

#include <cstdio>
#include <exception>
#include <filesystem>
#include <numeric>
#include <vector>

namespace {

std::vector<std::size_t> all_levels(const pointform::MultiresMesh& mesh)
{
    std::vector<std::size_t> levels(mesh.level_count());
    std::iota(levels.begin(), levels.end(), std::size_t{0});
    return levels;
}

} // namespace

int main(int argc, char** argv)
{
    using namespace pointform;
    if (argc != 2)
    {
        std::fprintf(stderr, "usage: gltf_samples OUTPUT_FOLDER\n");
        return 2;
    }
    try
    {
        const std::filesystem::path folder = argv[1];
        const MultiresMesh sphere = test::sphere_hierarchy(4);
        write_gltf(folder / "sphere_lods.glb", level_chain(sphere, all_levels(sphere)));
        write_hierarchy(folder / "sphere.pfh", sphere);

        const MultiresMesh plate = test::plate_hierarchy(3);
        TexturedMesh chain = level_chain(plate, all_levels(plate));
        write_gltf(folder / "plate_lods.glb", chain);
        test::add_plate_texture(chain);
        write_gltf(folder / "plate_textured.glb", chain);
        chain.base_color = test::checker_image(40, 40, 4);
        chain.normal_map = {};
        chain.tangents.clear();
        write_gltf(folder / "plate_textured_rgba.glb", chain);

        const std::vector<std::size_t> one = {2};
        write_gltf(folder / "plate_one_level.glb", level_chain(plate, one));
    }
    catch (const std::exception& e)
    {
        std::fprintf(stderr, "gltf_samples: %s\n", e.what());
        return 1;
    }
    return 0;
}
