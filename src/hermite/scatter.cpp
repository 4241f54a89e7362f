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

/// The RMS distance from their plane of the three quarters of a normal sample nearest its mean is
/// 0.61 of the sample's deviation: off_surface() scales the kept neighbours' RMS by this.
constexpr double trimmed_rms_to_deviation = 1.65;
/// off_surface() reads at most this many entries of a row, and needs this many others at least.
constexpr std::size_t off_surface_max_row = 64;
constexpr std::size_t off_surface_min_row = 8;
/// off_surface() passes over a sample whose nearest's centroid is nearer it than this many times
/// their RMS distance from that centroid (a stray off the surface stands off by more than its
/// nearest's spread; a sample among them by about a quarter of it).
constexpr double off_surface_among = 0.5;

/// Whether sample `i` stands off the surface of `row`'s other entries (off_surface_samples()).
bool off_surface(std::span<const Vec3f> positions, std::span<const std::uint32_t> row,
                 std::uint32_t i)
{
    std::array<std::uint32_t, off_surface_max_row> others{};
    std::size_t count = 0;
    for (const std::uint32_t j : row)
        if (j != i && count < others.size())
            others[count++] = j;
    if (count < off_surface_min_row)
        return false;
    // Most samples lie among their nearest, near their centroid: nearer than
    // off_surface_among times their RMS distance from it (a cheap pass that spares the rest).
    {
        Vec3d sum = Vec3d::Zero();
        double square = 0.0;
        const Vec3d p = positions[i].cast<double>();
        for (std::size_t j = 0; j < count; ++j)
        {
            const Vec3d q = positions[others[j]].cast<double>() - p;
            sum += q;
            square += q.squaredNorm();
        }
        const Vec3d centre = sum / static_cast<double>(count);
        const double spread2 = square / static_cast<double>(count) - centre.squaredNorm();
        if (centre.squaredNorm() <= off_surface_among * off_surface_among * spread2)
            return false;
    }
    const auto kept =
        static_cast<std::size_t>(std::ceil(off_surface_kept * static_cast<double>(count)));
    // The surface's share of the row: first those nearest the row's coordinate-wise median
    // (other strays in the row, spread wider than the surface's samples, move it little where
    // a plane through all of them would tilt towards them), then those nearest their plane.
    std::array<std::pair<double, std::uint32_t>, off_surface_max_row> by_distance{};
    std::array<float, off_surface_max_row> coordinate{};
    Vec3f median;
    for (Eigen::Index axis = 0; axis < 3; ++axis)
    {
        for (std::size_t j = 0; j < count; ++j)
            coordinate[j] = positions[others[j]][axis];
        const auto middle = coordinate.begin() + static_cast<std::ptrdiff_t>(count / 2);
        std::nth_element(coordinate.begin(), middle,
                         coordinate.begin() + static_cast<std::ptrdiff_t>(count));
        median[axis] = *middle;
    }
    for (std::size_t j = 0; j < count; ++j)
        by_distance[j] = {(positions[others[j]] - median).cast<double>().squaredNorm(), others[j]};
    std::array<std::uint32_t, off_surface_max_row> near_plane{};
    const auto nearest_kept = [&] {
        // The `kept` smallest (ties by index, so the choice is the same on any machine).
        std::nth_element(by_distance.begin(),
                         by_distance.begin() + static_cast<std::ptrdiff_t>(kept - 1),
                         by_distance.begin() + static_cast<std::ptrdiff_t>(count));
        for (std::size_t j = 0; j < kept; ++j)
            near_plane[j] = by_distance[j].second;
        std::sort(near_plane.begin(), near_plane.begin() + static_cast<std::ptrdiff_t>(kept));
        return fit_plane(positions, std::span(near_plane).first(kept));
    };
    const LocalPlane central = nearest_kept();
    if (central.degenerate)
        return false;
    for (std::size_t j = 0; j < count; ++j)
        by_distance[j] = {
            std::abs(central.normal.dot(positions[others[j]].cast<double>() - central.centroid)),
            others[j]};
    const LocalPlane plane = nearest_kept();
    if (plane.degenerate)
        return false;
    const double noise = trimmed_rms_to_deviation * std::sqrt(plane.eigenvalues[0]);
    const double spread = std::sqrt(0.5 * (plane.eigenvalues[1] + plane.eigenvalues[2]));
    const double height = plane.normal.dot(positions[i].cast<double>() - plane.centroid);
    const double off = std::abs(height);
    if (!(off > off_surface_noise * noise && off > off_surface_spacing * spread))
        return false;
    // Others off the plane too: the sample's own face at a crease (seen at a grazing angle, so
    // sampled more sparsely than the other face), or other strays. Two or fewer: off the
    // surface. More: a face of its own if it lies on their plane.
    const double beside = std::max(off_surface_beside * noise, 0.25 * spread);
    std::array<std::uint32_t, off_surface_max_row + 1> apart{};
    std::size_t apart_count = 0;
    for (std::size_t j = 0; j < count; ++j)
        if (std::abs(plane.normal.dot(positions[others[j]].cast<double>() - plane.centroid)) >
            beside)
            apart[apart_count++] = others[j];
    if (apart_count < off_surface_face)
        return true;
    apart[apart_count++] = i;
    const LocalPlane face = fit_plane(positions, std::span(apart).first(apart_count));
    if (face.degenerate)
        return false;
    for (std::size_t j = 0; j < apart_count; ++j)
        if (std::abs(face.normal.dot(positions[apart[j]].cast<double>() - face.centroid)) > beside)
            return true;
    return false;
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

namespace {

/// `found` (ascending) without the samples that lie on a plane with the nearest of them: a sheet
/// (a thin part's far face), not strays.
void drop_sheets(std::span<const Vec3f> positions, std::vector<std::uint32_t>& found)
{
    constexpr std::size_t fellows = off_surface_sheet_neighbours + 1;
    if (found.size() < fellows)
        return;
    std::vector<Vec3f> at(found.size());
    for (std::size_t c = 0; c < found.size(); ++c)
        at[c] = positions[found[c]];
    const KdTree tree(at);
    std::vector<std::uint8_t> sheet(found.size(), 0);
    parallel_blocks(found.size(), 256, [&](std::size_t begin, std::size_t end) {
        std::array<std::uint32_t, fellows> index{};
        std::array<float, fellows> d2{};
        for (std::size_t c = begin; c < end; ++c)
        {
            const std::size_t got = tree.knn(at[c], fellows, index, d2);
            const LocalPlane plane = fit_plane(at, std::span(index).first(got));
            const double across = off_surface_sheet * off_surface_sheet;
            sheet[c] =
                !plane.degenerate && plane.eigenvalues[0] <= across * plane.eigenvalues[1] ? 1 : 0;
        }
    });
    std::size_t kept = 0;
    for (std::size_t c = 0; c < found.size(); ++c)
        if (sheet[c] == 0)
            found[kept++] = found[c];
    found.resize(kept);
}

} // namespace

std::vector<std::uint32_t> off_surface_samples(std::span<const Vec3f> positions,
                                               const KnnTable& neighbors)
{
    check_knn_table(neighbors, positions.size(), positions.size(), "off_surface_samples");
    std::vector<std::uint32_t> found = parallel_collect<std::uint32_t>(
        positions.size(), 4096,
        [&](std::size_t begin, std::size_t end, std::vector<std::uint32_t>& out) {
            for (std::size_t i = begin; i < end; ++i)
                if (off_surface(positions, neighbors.neighbors(i), static_cast<std::uint32_t>(i)))
                    out.push_back(static_cast<std::uint32_t>(i));
        });
    drop_sheets(positions, found);
    // Strays among strays: a row holding three or more other strays on one plane with the sample
    // has them off the surface's plane beside it, as its own face at a crease would be. Each
    // round tests again the samples whose rows hold samples found so far, without those.
    std::vector<std::uint8_t> off(found.empty() ? 0 : positions.size(), 0);
    for (std::size_t round = 0; round < off_surface_rounds && !found.empty(); ++round)
    {
        for (const std::uint32_t i : found)
            off[i] = 1;
        std::vector<std::uint32_t> more = parallel_collect<std::uint32_t>(
            positions.size(), 4096,
            [&](std::size_t begin, std::size_t end, std::vector<std::uint32_t>& out) {
                std::array<std::uint32_t, off_surface_max_row> rest{};
                for (std::size_t i = begin; i < end; ++i)
                {
                    if (off[i] != 0)
                        continue;
                    const std::span<const std::uint32_t> row = neighbors.neighbors(i);
                    std::size_t count = 0;
                    bool without = false;
                    for (const std::uint32_t j : row)
                    {
                        if (off[j] != 0)
                            without = true;
                        else if (count < rest.size())
                            rest[count++] = j;
                    }
                    if (without && off_surface(positions, std::span(rest).first(count),
                                               static_cast<std::uint32_t>(i)))
                        out.push_back(static_cast<std::uint32_t>(i));
                }
            });
        if (more.empty())
            break;
        std::fill(off.begin(), off.end(), std::uint8_t{0});
        std::vector<std::uint32_t> merged(found.size() + more.size());
        std::merge(found.begin(), found.end(), more.begin(), more.end(), merged.begin());
        found = std::move(merged);
        drop_sheets(positions, found);
    }
    return found;
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
