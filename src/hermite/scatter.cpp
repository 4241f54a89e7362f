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

/// A sample and its nearest (itself usually first), nearest first.
struct Neighbourhood
{
    std::array<std::uint32_t, scatter_k> index{};
    std::array<float, scatter_k> d2{};
    std::size_t found = 0;

    Neighbourhood(const KdTree& tree, std::span<const Vec3f> positions, std::size_t i)
        : found(tree.knn(positions[i], scatter_k, index, d2))
    {}

    /// Whether all 16 nearest were found and the reach² is over `limit2`.
    [[nodiscard]] bool past(float limit2) const
    {
        return found == scatter_k && d2[found - 1] > limit2;
    }
};

/// The nearest of sample `i` but itself.
struct Others
{
    std::array<std::uint32_t, scatter_k - 1> index{};
    std::size_t count = 0;

    Others() = default;
    Others(const Neighbourhood& near, std::size_t i)
    {
        for (std::size_t j = 0; j < near.found && count < index.size(); ++j)
            if (near.index[j] != i)
                index[count++] = near.index[j];
    }
};

/// Whether the neighbourhood fills a volume (scattered_volume).
bool fills_volume(std::span<const Vec3f> positions, const Neighbourhood& near)
{
    const Vec3d lambda = fit_plane(positions, std::span(near.index).first(near.found)).eigenvalues;
    return lambda[0] > scattered_volume * lambda[2];
}

/// Whether sample `i` stands off the plane of `others` (stray_offset) or is isolated from them
/// (stray_isolation).
bool stands_apart(const KdTree& tree, std::span<const Vec3f> positions, std::size_t i,
                  const Neighbourhood& near, const Others& others)
{
    const LocalPlane plane = fit_plane(positions, std::span(others.index).first(others.count));
    if (plane.degenerate)
        return false;
    const double offset = std::abs(plane.normal.dot(positions[i].cast<double>() - plane.centroid));
    if (offset > stray_offset * std::sqrt(static_cast<double>(near.d2[near.found - 1])))
        return true;
    // Isolated from its nearest: they lie far closer together than it lies from them.
    std::array<float, scatter_k> reach2{};
    for (std::size_t j = 0; j < others.count; ++j)
    {
        const Neighbourhood theirs(tree, positions, others.index[j]);
        reach2[j] = theirs.d2[theirs.found - 1];
    }
    const auto middle = reach2.begin() + static_cast<std::ptrdiff_t>(others.count / 2);
    std::nth_element(reach2.begin(), middle,
                     reach2.begin() + static_cast<std::ptrdiff_t>(others.count));
    return static_cast<double>(near.d2[near.found - 1]) >
           stray_isolation * stray_isolation * static_cast<double>(*middle);
}

} // namespace

bool ScatterTest::scattered(const KdTree& tree, std::span<const Vec3f> positions,
                            std::size_t i) const
{
    const Neighbourhood near(tree, positions, i);
    return near.past(limit2) && fills_volume(positions, near);
}

bool ScatterTest::stray(const KdTree& tree, std::span<const Vec3f> positions, std::size_t i) const
{
    const Neighbourhood near(tree, positions, i);
    return near.past(limit2) && (fills_volume(positions, near) ||
                                 stands_apart(tree, positions, i, near, Others(near, i)));
}

Strays find_strays(const KdTree& tree, std::span<const Vec3f> positions, const ScatterTest& test,
                   std::span<const std::uint32_t> candidates)
{
    PF_ASSERT(std::is_sorted(candidates.begin(), candidates.end()));
    // Each candidate's reach tested exactly, its 16 nearest kept, and the test's verdict (as
    // ScatterTest::stray() gives it, from the one search).
    struct Candidate
    {
        Others others;
        bool over = false;
        bool stray = false;
    };
    std::vector<Candidate> tested(candidates.size());
    parallel_blocks(candidates.size(), 256, [&](std::size_t begin, std::size_t end) {
        for (std::size_t c = begin; c < end; ++c)
        {
            const std::uint32_t i = candidates[c];
            const Neighbourhood near(tree, positions, i);
            Candidate& t = tested[c];
            t.over = near.past(test.limit2);
            if (!t.over)
                continue;
            t.others = Others(near, i);
            t.stray =
                fills_volume(positions, near) || stands_apart(tree, positions, i, near, t.others);
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
        for (std::size_t j = 0; j < tested[c].others.count; ++j)
        {
            const std::size_t o = candidate_of(tested[c].others.index[j]);
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
    for (std::size_t i = 0; i < positions.size(); i += stride)
    {
        const Neighbourhood near(tree, positions, i);
        if (near.found > 0)
            reach2.push_back(near.d2[near.found - 1]);
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
