// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/multires/parameterization.h"

#include "pointform/core/error.h"
#include "pointform/core/parallel.h"
#include "pointform/geometry/level_topology.h"

#include <algorithm>
#include <limits>
#include <string>

namespace pointform {

Parameterization::Parameterization(const MultiresMesh& mesh)
    : base_faces_(mesh.base_faces().begin(), mesh.base_faces().end())
{
    if (mesh.level_count() == 0)
        throw InvalidInput("parameterization: the hierarchy is empty");
    coordinates_.resize(mesh.vertex_count());
    // Base vertices: the lowest-index face around each, the corner's unit coordinates.
    constexpr std::uint32_t unset = std::numeric_limits<std::uint32_t>::max();
    std::vector<std::uint32_t> first_face(mesh.vertex_count(0), unset);
    for (std::uint32_t f = 0; f < base_faces_.size(); ++f)
        for (int k = 0; k < 3; ++k)
        {
            const std::uint32_t v = base_faces_[f][static_cast<std::size_t>(k)];
            if (first_face[v] != unset)
                continue;
            first_face[v] = f;
            coordinates_[v].face = f;
            coordinates_[v].barycentric = Vec3d::Unit(k);
        }
    // Each level's new vertices: the midpoint, in the base face of the lowest-index face beside
    // the parent edge (h1 is the first halfedge met going through the faces), of its ends.
    for (std::size_t level = 0; level < mesh.finest_level(); ++level)
    {
        const LevelTopology topology = level_topology(mesh, level);
        const unsigned shift = static_cast<unsigned>(2 * level);
        parallel_blocks(topology.halfedges.size(), 4096, [&](std::size_t begin, std::size_t end) {
            for (std::size_t j = begin; j < end; ++j)
            {
                const std::uint32_t h1 = topology.halfedges[j][0];
                const auto base = static_cast<std::uint32_t>((h1 / 3) >> shift);
                BaseCoordinates& out = coordinates_[topology.first_new + j];
                out.face = base;
                out.barycentric = 0.5 * (coordinates_in(base, topology.from(h1)) +
                                         coordinates_in(base, topology.to(h1)));
            }
        });
    }
}

Vec3d Parameterization::coordinates_in(std::uint32_t face, std::uint32_t v) const
{
    const BaseCoordinates& c = coordinates_[v];
    if (c.face == face)
        return c.barycentric;
    // v lies on the boundary of its canonical face: carry each non-zero coordinate over to the
    // same base vertex among `face`'s corners.
    const Triangle& from = base_faces_[c.face];
    const Triangle& to = base_faces_[face];
    Vec3d out = Vec3d::Zero();
    for (int k = 0; k < 3; ++k)
    {
        const double w = c.barycentric[k];
        if (w == 0.0)
            continue;
        const auto* corner = std::find(to.begin(), to.end(), from[static_cast<std::size_t>(k)]);
        if (corner == to.end())
            throw InvalidInput("parameterization: vertex " + std::to_string(v) +
                               " does not lie on base face " + std::to_string(face));
        out[corner - to.begin()] = w;
    }
    return out;
}

Parameterization::Location Parameterization::locate(std::uint32_t face, const Vec3d& barycentric,
                                                    std::size_t level)
{
    Location at{face, barycentric};
    for (std::size_t l = 0; l < level; ++l)
    {
        const Vec3d& b = at.barycentric;
        // The 1-to-4 split of MultiresMesh: 4f (a, m_ab, m_ca), 4f+1 (m_ab, b, m_bc),
        // 4f+2 (m_ca, m_bc, c), 4f+3 (m_ab, m_bc, m_ca).
        if (b.x() >= 0.5)
        {
            at.face = 4 * at.face;
            at.barycentric = Vec3d(2.0 * b.x() - 1.0, 2.0 * b.y(), 2.0 * b.z());
        }
        else if (b.y() >= 0.5)
        {
            at.face = 4 * at.face + 1;
            at.barycentric = Vec3d(2.0 * b.x(), 2.0 * b.y() - 1.0, 2.0 * b.z());
        }
        else if (b.z() >= 0.5)
        {
            at.face = 4 * at.face + 2;
            at.barycentric = Vec3d(2.0 * b.x(), 2.0 * b.y(), 2.0 * b.z() - 1.0);
        }
        else
        {
            at.face = 4 * at.face + 3;
            at.barycentric = Vec3d(1.0 - 2.0 * b.z(), 1.0 - 2.0 * b.x(), 1.0 - 2.0 * b.y());
        }
    }
    return at;
}

} // namespace pointform
