// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/hermite/scatter.h"

#include "pointform/core/disjoint_sets.h"
#include "pointform/core/error.h"
#include "pointform/core/parallel.h"
#include "pointform/hermite/normals.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

namespace pointform {

namespace {

constexpr std::size_t scatter_k = scatter_neighbourhood;
/// The samples whose reach gives the cloud's median at most (every stride-th).
constexpr std::size_t reach_probes = 4096;

} // namespace

bool ScatterTest::scattered(const KdTree& tree, std::span<const Vec3f> positions,
                            std::size_t i) const
{
    std::array<std::uint32_t, scatter_k> index{};
    std::array<float, scatter_k> d2{};
    const std::size_t found = tree.knn(positions[i], scatter_k, index, d2);
    if (found < scatter_k || !(d2[found - 1] > limit2))
        return false;
    const Vec3d lambda = fit_plane(positions, std::span(index).first(found)).eigenvalues;
    return lambda[0] > scattered_volume * lambda[2];
}

bool ScatterTest::stray(const KdTree& tree, std::span<const Vec3f> positions, std::size_t i) const
{
    std::array<std::uint32_t, scatter_k> index{};
    std::array<float, scatter_k> d2{};
    const std::size_t found = tree.knn(positions[i], scatter_k, index, d2);
    if (found < scatter_k || !(d2[found - 1] > limit2))
        return false;
    const LocalPlane all = fit_plane(positions, std::span(index).first(found));
    if (all.eigenvalues[0] > scattered_volume * all.eigenvalues[2])
        return true;
    // The plane of the others (the sample itself is one of the nearest, usually the first).
    std::array<std::uint32_t, scatter_k> others{};
    std::size_t count = 0;
    for (std::size_t j = 0; j < found; ++j)
        if (index[j] != i)
            others[count++] = index[j];
    const LocalPlane plane = fit_plane(positions, std::span(others).first(count));
    if (plane.degenerate)
        return false;
    const double offset = std::abs(plane.normal.dot(positions[i].cast<double>() - plane.centroid));
    if (offset > stray_offset * std::sqrt(static_cast<double>(d2[found - 1])))
        return true;
    // Isolated from its nearest: they lie far closer together than it lies from them.
    std::array<float, scatter_k> reach2{};
    std::array<std::uint32_t, scatter_k> their_index{};
    std::array<float, scatter_k> their_d2{};
    for (std::size_t j = 0; j < count; ++j)
    {
        const std::size_t their = tree.knn(positions[others[j]], scatter_k, their_index, their_d2);
        reach2[j] = their_d2[their - 1];
    }
    const auto middle = reach2.begin() + static_cast<std::ptrdiff_t>(count / 2);
    std::nth_element(reach2.begin(), middle, reach2.begin() + static_cast<std::ptrdiff_t>(count));
    return static_cast<double>(d2[found - 1]) >
           stray_isolation * stray_isolation * static_cast<double>(*middle);
}

Strays find_strays(const KdTree& tree, std::span<const Vec3f> positions, const ScatterTest& test,
                   std::span<const std::uint32_t> candidates)
{
    PF_ASSERT(std::is_sorted(candidates.begin(), candidates.end()));
    // Each candidate's reach tested exactly, its 16 nearest kept, and the test's verdict.
    struct Candidate
    {
        std::array<std::uint32_t, scatter_k - 1> others{};
        std::uint8_t count = 0;
        bool over = false;
        bool stray = false;
    };
    std::vector<Candidate> tested(candidates.size());
    parallel_blocks(candidates.size(), 256, [&](std::size_t begin, std::size_t end) {
        std::array<std::uint32_t, scatter_k> index{};
        std::array<float, scatter_k> d2{};
        for (std::size_t c = begin; c < end; ++c)
        {
            const std::uint32_t i = candidates[c];
            const std::size_t found = tree.knn(positions[i], scatter_k, index, d2);
            Candidate& t = tested[c];
            t.over = found == scatter_k && d2[found - 1] > test.limit2;
            if (!t.over)
                continue;
            for (std::size_t j = 0; j < found && t.count < t.others.size(); ++j)
                if (index[j] != i)
                    t.others[t.count++] = index[j];
            t.stray = test.stray(tree, positions, i);
        }
    });
    // The candidates over the limit, joined to those of their 16 nearest that are over it too:
    // a group of them most of whom are strays is a spray, all of it (the few whose
    // neighbourhood happens to lie flat, or that sit beside the object, too). Groups are the
    // same whatever the order of the joins.
    const auto candidate_of = [&](std::uint32_t i) -> std::size_t {
        const auto at = std::lower_bound(candidates.begin(), candidates.end(), i);
        return at != candidates.end() && *at == i
                   ? static_cast<std::size_t>(at - candidates.begin())
                   : candidates.size();
    };
    DisjointSets groups(candidates.size());
    for (std::size_t c = 0; c < candidates.size(); ++c)
    {
        if (!tested[c].over)
            continue;
        for (std::size_t j = 0; j < tested[c].count; ++j)
        {
            const std::size_t o = candidate_of(tested[c].others[j]);
            if (o < candidates.size() && tested[o].over)
                groups.unite(c, o);
        }
    }
    std::vector<std::uint32_t> members(candidates.size(), 0);
    std::vector<std::uint32_t> group_strays(candidates.size(), 0);
    for (std::size_t c = 0; c < candidates.size(); ++c)
    {
        if (!tested[c].over)
            continue;
        const std::size_t g = groups.find(c);
        ++members[g];
        group_strays[g] += tested[c].stray ? 1 : 0;
    }
    Strays out;
    for (std::size_t c = 0; c < candidates.size(); ++c)
    {
        const std::size_t g = groups.find(c);
        const bool sprayed = tested[c].over && 2 * group_strays[g] > members[g];
        if (sprayed)
            out.sprayed.push_back(candidates[c]);
        if (sprayed || tested[c].stray)
            out.samples.push_back(candidates[c]);
    }
    return out;
}

ScatterTest scatter_test(const KdTree& tree, std::span<const Vec3f> positions)
{
    const std::size_t stride = std::max<std::size_t>(1, positions.size() / reach_probes);
    std::vector<float> reach2;
    std::array<std::uint32_t, scatter_k> index{};
    std::array<float, scatter_k> d2{};
    for (std::size_t i = 0; i < positions.size(); i += stride)
    {
        const std::size_t found = tree.knn(positions[i], scatter_k, index, d2);
        if (found > 0)
            reach2.push_back(d2[found - 1]);
    }
    if (reach2.empty())
        return {.limit2 = std::numeric_limits<float>::infinity()};
    const auto middle = reach2.begin() + static_cast<std::ptrdiff_t>(reach2.size() / 2);
    std::nth_element(reach2.begin(), middle, reach2.end());
    // Most samples on top of 16 others (a cloud of copies): no spacing to judge by.
    if (!(*middle > 0.0F))
        return {.limit2 = std::numeric_limits<float>::infinity()};
    return {.limit2 = static_cast<float>(scattered_reach * scattered_reach *
                                         static_cast<double>(*middle))};
}

} // namespace pointform
