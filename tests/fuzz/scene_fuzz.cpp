// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// libFuzzer harness for the scene language (parse_scene): the input is a scene's text. A scene
// that parses is evaluated at a few points, with its bounds and cost, and for a 16th of the
// inputs (those whose bytes hash to 0 mod 16) its seeds. The choice was the size's being a
// multiple of 16 before, which the shipped seed scene (464 bytes) and every mutation that keeps
// its length met: the corpus filled with them, each 1.5 s of seeds under ASan, and the rate fell
// to 50-100 executions a second. Any outcome but
// success or a pointform::InvalidInput (a crash, a hang, a stack overflow, a sanitizer report,
// another exception) is a bug.

#include "pointform/core/error.h"
#include "pointform/implicit/scene.h"

#include <array>
#include <cstdint>
#include <string_view>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    try
    {
        const pointform::Scene scene = pointform::parse_scene(text);
        const pointform::Field& field = *scene.field;
        const pointform::Aabb box = field.bounds();
        (void)field.cost();
        const std::array<pointform::Vec3d, 4> points = {
            pointform::Vec3d(0, 0, 0), pointform::Vec3d(0.5, -0.25, 1.0),
            box.is_empty() ? pointform::Vec3d(1, 1, 1) : box.min,
            box.is_empty() ? pointform::Vec3d(-1, 2, 0) : box.max};
        for (const pointform::Vec3d& p : points)
            (void)field.evaluate(p);
        // Seeds (sweeps, Newton steps) cost most: a 16th of the inputs, by an FNV-1a hash of
        // their bytes.
        std::uint32_t hash = 2166136261U;
        for (std::size_t i = 0; i < size; ++i)
            hash = (hash ^ data[i]) * 16777619U;
        if (hash % 16 == 0)
        {
            std::vector<pointform::Vec3d> seeds;
            field.append_seeds(seeds);
        }
    }
    catch (const pointform::InvalidInput&)
    {}
    return 0;
}
