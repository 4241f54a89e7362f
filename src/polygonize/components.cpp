// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/polygonize/components.h"

#include "pointform/core/disjoint_sets.h"
#include "pointform/core/parallel.h"
#include "pointform/geometry/mesh_topology.h"
#include "pointform/hermite/scatter.h"
#include "pointform/spatial/spatial_sort.h"
#include "pointform/spatial/triangle_bvh.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <vector>

namespace pointform {

namespace {

/// The samples whose nearest triangle lies in each component. The largest component (most
/// faces) is weighed against the rest: a sample's nearest triangle among the rest (usually few
/// faces), then whether the largest has one strictly closer: a point of it found for an earlier
/// sample (in Morton order) that is, or else a search bounded by the rest's distance. The
/// nearest triangle of the whole mesh is in the component found, as an exact search finds it,
/// but for exact ties, which go to the rest.
struct Support
{
    std::vector<std::size_t> count;     ///< per component
    std::vector<std::uint32_t> nearest; ///< per sample: its component, or none
};

Support component_support(const TriMesh& mesh, const std::vector<std::uint32_t>& face_component,
                          std::size_t components, const PointCloud& samples)
{
    std::vector<std::size_t> faces_of(components, 0);
    for (const std::uint32_t c : face_component)
        ++faces_of[c];
    const auto largest = static_cast<std::uint32_t>(
        std::max_element(faces_of.begin(), faces_of.end()) - faces_of.begin());
    TriMesh large;
    TriMesh rest;
    for (TriMesh* part : {&large, &rest})
    {
        part->vertices.origin = mesh.vertices.origin;
        part->vertices.positions = mesh.vertices.positions;
    }
    std::vector<std::uint32_t> rest_component;
    for (std::size_t f = 0; f < mesh.face_count(); ++f)
    {
        if (face_component[f] == largest)
        {
            large.triangles.push_back(mesh.triangles[f]);
        }
        else
        {
            rest.triangles.push_back(mesh.triangles[f]);
            rest_component.push_back(face_component[f]);
        }
    }
    const TriangleBvh large_bvh(large);
    const TriangleBvh rest_bvh(rest);
    large = TriMesh{};
    rest = TriMesh{};

    constexpr std::uint32_t none = std::numeric_limits<std::uint32_t>::max();
    std::vector<std::uint32_t> nearest(samples.size(), none);
    const std::vector<std::uint32_t> order = spatial_order(samples.positions);
    parallel_blocks(order.size(), 1024, [&](std::size_t begin, std::size_t end) {
        // The nearest point among the rest found for the sample before bounds the next search.
        constexpr double nan = std::numeric_limits<double>::quiet_NaN();
        Vec3d previous = Vec3d::Constant(nan);
        // A point of the largest component found for an earlier sample: where it is nearer
        // than the rest (by a margin far above rounding), so is the largest, with no search.
        Vec3d on_large = Vec3d::Constant(nan);
        for (std::size_t k = begin; k < end; ++k)
        {
            const std::uint32_t i = order[k];
            const Vec3d p = samples.world(i);
            const double bound = (p - previous).norm() * (1.0 + 1e-6);
            TriangleBvh::Hit hit;
            if (std::isfinite(bound))
                hit = rest_bvh.closest(p, bound);
            if (!hit.found())
                hit = rest_bvh.closest(p);
            if (!hit.found())
                continue; // a non-finite sample
            previous = hit.point;
            if ((p - on_large).norm() * (1.0 + 1e-9) < hit.distance)
            {
                nearest[i] = largest;
                continue;
            }
            const TriangleBvh::Hit large_hit = large_bvh.closest(p, hit.distance);
            if (large_hit.found() && large_hit.distance < hit.distance)
            {
                on_large = large_hit.point;
                nearest[i] = largest;
            }
            else
            {
                nearest[i] = rest_component[hit.face.value];
            }
        }
    });
    std::vector<std::size_t> support(components, 0);
    for (const std::uint32_t c : nearest)
        if (c != none)
            ++support[c];
    return {std::move(support), std::move(nearest)};
}

/// The samples of a component tested at most (evenly spread over its supporters in index order).
constexpr std::size_t scatter_tests = 256;

} // namespace

std::size_t default_min_component_samples(std::size_t samples)
{
    return std::max<std::size_t>(32, samples / 1000);
}

ComponentFilterReport remove_unsupported_components(TriMesh& mesh, const PointCloud& samples,
                                                    std::size_t min_samples,
                                                    const KdTree* sample_tree)
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

    const Support found = component_support(mesh, face_component, report.components, samples);
    const std::vector<std::size_t>& support = found.count;
    std::vector<char> keep(report.components, 0);
    for (std::size_t c = 0; c < report.components; ++c)
        keep[c] = support[c] >= min_samples ? 1 : 0;
    // Never remove everything: the best-supported component stays.
    const auto best = static_cast<std::size_t>(std::max_element(support.begin(), support.end()) -
                                               support.begin());
    keep[best] = 1;
    // The others kept, unless their support is mostly scattered samples (every one tested, or
    // scatter_tests of them spread evenly in index order).
    std::size_t candidates = 0;
    for (std::size_t c = 0; c < report.components; ++c)
        candidates += keep[c] != 0 && c != best ? 1 : 0;
    if (candidates > 0)
    {
        std::vector<std::vector<std::uint32_t>> tested(report.components);
        std::vector<std::size_t> seen(report.components, 0);
        for (std::size_t i = 0; i < samples.size(); ++i)
        {
            const std::uint32_t c = found.nearest[i];
            if (c == std::numeric_limits<std::uint32_t>::max() || keep[c] == 0 || c == best)
                continue;
            // Taken where the count crosses a multiple of support / scatter_tests.
            const std::size_t before = seen[c]++ * scatter_tests / support[c];
            const std::size_t after = seen[c] * scatter_tests / support[c];
            if (after > before)
                tested[c].push_back(static_cast<std::uint32_t>(i));
        }
        std::optional<KdTree> own_tree;
        if (sample_tree == nullptr)
            own_tree.emplace(samples.positions);
        const KdTree& tree = sample_tree != nullptr ? *sample_tree : *own_tree;
        const ScatterTest test = scatter_test(tree, samples.positions);
        for (std::size_t c = 0; c < report.components; ++c)
        {
            if (tested[c].empty())
                continue;
            std::size_t count = 0;
            for (const std::uint32_t i : tested[c])
                count += test.scattered(tree, samples.positions, i) ? 1 : 0;
            if (2 * count > tested[c].size())
            {
                keep[c] = 0;
                ++report.scattered_components;
            }
        }
    }
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
