// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// libFuzzer harness for the files of `pointform deform` (docs/deform.md). The first byte picks
// the parser (even: an edit, odd: a lattice), the rest is the file's text. A file that parses
// is then applied to a small fixed hierarchy, so the checks that need the hierarchy (vertex ids,
// handles in the region, the level, the lattice's size) and the solve run too. Any outcome but
// success or a pointform::Error (a crash, a hang, a sanitizer report, another exception) is a
// bug, and so is a deformed hierarchy that fails its own validation.

#include "pointform/core/error.h"
#include "pointform/multires/deformation.h"
#include "pointform/multires/edit_file.h"
#include "pointform/multires/lattice.h"

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <numbers>
#include <string_view>

namespace {

using pointform::Triangle;
using pointform::Vec3d;

/// An octahedron on the unit sphere refined twice, new vertices pushed onto the sphere.
pointform::MultiresMesh make_hierarchy()
{
    pointform::TriMesh base;
    const std::vector<Vec3d> v = {{1, 0, 0},  {-1, 0, 0}, {0, 1, 0},
                                  {0, -1, 0}, {0, 0, 1},  {0, 0, -1}};
    for (const Vec3d& p : v)
        base.vertices.positions.push_back(p.cast<float>());
    base.triangles = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4},
                      {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
    pointform::MultiresMesh mesh(base);
    for (int level = 0; level < 2; ++level)
    {
        (void)mesh.split();
        for (Vec3d& p : mesh.finest_new_positions())
            p.normalize();
    }
    return mesh;
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
    if (size == 0)
        return 0;
    static const pointform::MultiresMesh rest = make_hierarchy();
    const std::string_view text(reinterpret_cast<const char*>(data + 1), size - 1);
    try
    {
        pointform::MultiresMesh mesh = rest;
        if (data[0] % 2 == 0)
            (void)pointform::deform(mesh, pointform::parse_multires_edit(text, "fuzz.json"));
        else
        {
            const pointform::LatticeEdit lattice = pointform::parse_lattice(text, "fuzz.json");
            (void)pointform::apply_lattice(
                mesh, lattice.lattice, lattice.level,
                data[0] % 4 == 1 ? pointform::LatticeMode::Details : pointform::LatticeMode::Plain);
        }
        mesh.validate();
    }
    catch (const pointform::Error&)
    {}
    return 0;
}
