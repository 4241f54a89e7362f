// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/polygonize/components.h"

#include "pointform/core/disjoint_sets.h"
#include "pointform/geometry/mesh_topology.h"
#include "pointform/spatial/triangle_bvh.h"

#include <algorithm>
#include <cstdint>
#include <limits>
#include <vector>

namespace pointform {

std::size_t default_min_component_samples(std::size_t samples)
{
    return std::max<std::size_t>(32, samples / 1000);
}

ComponentFilterReport remove_unsupported_components(TriMesh& mesh, const PointCloud& samples,
                                                    std::size_t min_samples)
{
    ComponentFilterReport report;
    report.min_samples = min_samples;
    if (mesh.face_count() == 0)
        return report;
    const std::size_t nv = mesh.vertex_count();
    DisjointSets sets(nv);
    for (const Triangle& t : mesh.triangles)
    {
        sets.unite(t[0], t[1]);
        sets.unite(t[0], t[2]);
    }
    // Components numbered in order of their first face.
    constexpr std::uint32_t none = std::numeric_limits<std::uint32_t>::max();
    std::vector<std::uint32_t> component_of_root(nv, none);
    std::vector<std::uint32_t> face_component(mesh.face_count());
    for (std::size_t f = 0; f < mesh.face_count(); ++f)
    {
        std::uint32_t& c = component_of_root[sets.find(mesh.triangles[f][0])];
        if (c == none)
            c = static_cast<std::uint32_t>(report.components++);
        face_component[f] = c;
    }
    if (report.components < 2 || min_samples == 0 || samples.empty())
        return report;

    std::vector<std::size_t> support(report.components, 0);
    {
        const TriangleBvh bvh(mesh);
        std::vector<Vec3d> queries(samples.size());
        for (std::size_t i = 0; i < samples.size(); ++i)
            queries[i] = samples.world(i);
        for (const TriangleBvh::Hit& hit : closest_points(bvh, queries))
            if (hit.face.is_valid())
                ++support[face_component[hit.face.value]];
    }
    std::vector<char> keep(report.components, 0);
    for (std::size_t c = 0; c < report.components; ++c)
        keep[c] = support[c] >= min_samples ? 1 : 0;
    // Never remove everything: the best-supported component stays.
    const auto best = static_cast<std::size_t>(std::max_element(support.begin(), support.end()) -
                                               support.begin());
    keep[best] = 1;
    for (std::size_t c = 0; c < report.components; ++c)
        report.removed_components += keep[c] == 0 ? 1 : 0;
    if (report.removed_components == 0)
        return report;

    std::vector<std::uint8_t> keep_face(mesh.face_count());
    for (std::size_t f = 0; f < mesh.face_count(); ++f)
        keep_face[f] = keep[face_component[f]];
    report.removed_faces = keep_faces(mesh, keep_face);
    return report;
}

} // namespace pointform
