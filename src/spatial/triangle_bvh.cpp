// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/spatial/triangle_bvh.h"

#include "pointform/core/error.h"
#include "pointform/core/parallel.h"
#include "pointform/spatial/spatial_sort.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <utility>

namespace pointform {
namespace {

constexpr std::size_t sah_bins = 16;
/// Below this depth the build splits by the surface-area heuristic; deeper, by the median, so
/// that the depth stays below max_sah_depth + log2(F) whatever the input.
constexpr int max_sah_depth = 40;
/// Traversal stack: at most one entry a level plus one.
constexpr std::size_t stack_capacity = 128;
constexpr std::size_t query_block = 1024;

/// A triangle is measured as its edges when sin² of its sharpest-conditioned angle is below this:
/// its width is then under 1e-8 of its size, below what the plane projection resolves reliably.
constexpr double degenerate_sin2 = 1e-16;

double half_area(const Aabb& box)
{
    if (box.is_empty())
        return 0.0;
    const Vec3d s = box.size();
    return s.x() * s.y() + s.y() * s.z() + s.z() * s.x();
}

/// Ranges of at most this many triangles are split by the surface-area heuristic at every
/// position along each axis (their boxes' centres sorted) instead of by bins: most nodes are
/// this small, and filling and sweeping 3 × 16 bins cost them more than the sort.
constexpr std::size_t small_split_refs = 16;

using Lanes = Eigen::Array4f; ///< x, y, z and a lane the build ignores

constexpr float float_max = std::numeric_limits<float>::max();

/// A triangle as the build sorts it: its box, exact in float as its corners are float
/// positions, and its index in the mesh. The build places triangles by their boxes' centres
/// (lo + hi, at twice the scale).
struct BuildRef
{
    Lanes lo;
    Lanes hi;
    std::uint32_t face;

    [[nodiscard]] Lanes centre2() const { return lo + hi; }
};

/// Whether x comes before y along `axis`: by their boxes' centres, ties by face index.
bool centre_before(const BuildRef& x, const BuildRef& y, Eigen::Index axis)
{
    const float cx = x.lo[axis] + x.hi[axis];
    const float cy = y.lo[axis] + y.hi[axis];
    return cx < cy || (cx == cy && x.face < y.face);
}

/// The box of some triangles and the box of their centres (at twice the scale); empty: lo
/// above hi.
struct BuildBox
{
    Lanes lo = Lanes::Constant(float_max);
    Lanes hi = Lanes::Constant(-float_max);
    Lanes centre_lo = Lanes::Constant(float_max);
    Lanes centre_hi = Lanes::Constant(-float_max);

    void add(const BuildRef& r)
    {
        lo = lo.min(r.lo);
        hi = hi.max(r.hi);
        const Lanes c = r.centre2();
        centre_lo = centre_lo.min(c);
        centre_hi = centre_hi.max(c);
    }

    void merge(const BuildBox& b)
    {
        lo = lo.min(b.lo);
        hi = hi.max(b.hi);
        centre_lo = centre_lo.min(b.centre_lo);
        centre_hi = centre_hi.max(b.centre_hi);
    }

    /// The extent of the centres along an axis (0 where empty).
    [[nodiscard]] double centre_extent(std::size_t axis) const
    {
        const auto a = static_cast<Eigen::Index>(axis);
        return std::max(0.0, static_cast<double>(centre_hi[a]) - static_cast<double>(centre_lo[a]));
    }

    [[nodiscard]] double half_area() const
    {
        if (lo[0] > hi[0])
            return 0.0;
        const double x = static_cast<double>(hi[0]) - static_cast<double>(lo[0]);
        const double y = static_cast<double>(hi[1]) - static_cast<double>(lo[1]);
        const double z = static_cast<double>(hi[2]) - static_cast<double>(lo[2]);
        return x * y + y * z + z * x;
    }
};

BuildBox range_box(const std::vector<BuildRef>& refs, std::size_t begin, std::size_t end)
{
    BuildBox box;
    for (std::size_t i = begin; i < end; ++i)
        box.add(refs[i]);
    return box;
}

/// The cheapest split of a small range (more than one and at most small_split_refs triangles)
/// by the surface-area heuristic over every position along each axis, applied: the range
/// reordered along the best axis, the children's boxes written. Ties go to the first axis and
/// the first position.
std::size_t split_small(std::vector<BuildRef>& refs, std::size_t begin, std::size_t end,
                        BuildBox& left, BuildBox& right)
{
    const std::size_t n = end - begin;
    std::array<std::array<std::uint8_t, small_split_refs>, 3> order{};
    double best_cost = std::numeric_limits<double>::infinity();
    std::size_t best_axis = 0;
    std::size_t best_at = n / 2;
    for (std::size_t ax = 0; ax < 3; ++ax)
    {
        auto& o = order[ax];
        const auto a = static_cast<Eigen::Index>(ax);
        const auto before = [&](std::uint8_t x, std::uint8_t y) {
            return centre_before(refs[begin + x], refs[begin + y], a);
        };
        for (std::size_t i = 0; i < n; ++i)
        {
            o[i] = static_cast<std::uint8_t>(i);
            for (std::size_t j = i; j > 0 && before(o[j], o[j - 1]); --j)
                std::swap(o[j], o[j - 1]);
        }
        std::array<double, small_split_refs> right_cost{};
        BuildBox acc;
        for (std::size_t k = n - 1; k > 0; --k)
        {
            acc.add(refs[begin + o[k]]);
            right_cost[k] = static_cast<double>(n - k) * acc.half_area();
        }
        acc = BuildBox{};
        for (std::size_t k = 0; k + 1 < n; ++k)
        {
            acc.add(refs[begin + o[k]]);
            const double cost = static_cast<double>(k + 1) * acc.half_area() + right_cost[k + 1];
            if (cost < best_cost)
            {
                best_cost = cost;
                best_axis = ax;
                best_at = k + 1;
            }
        }
    }
    std::array<BuildRef, small_split_refs> copy;
    std::copy(refs.begin() + static_cast<std::ptrdiff_t>(begin),
              refs.begin() + static_cast<std::ptrdiff_t>(end), copy.begin());
    for (std::size_t k = 0; k < n; ++k)
        refs[begin + k] = copy[order[best_axis][k]];
    left = range_box(refs, begin, begin + best_at);
    right = range_box(refs, begin + best_at, end);
    return begin + best_at;
}

/// The surface-area heuristic's bins of a range, along each axis.
struct Bins
{
    std::array<std::array<BuildBox, sah_bins>, 3> box;
    std::array<std::array<std::uint32_t, sah_bins>, 3> count{};

    void merge(const Bins& b)
    {
        for (std::size_t a = 0; a < 3; ++a)
            for (std::size_t k = 0; k < sah_bins; ++k)
            {
                box[a][k].merge(b.box[a][k]);
                count[a][k] += b.count[a][k];
            }
    }

    /// The boxes of bins [from, to) along `axis`, merged.
    [[nodiscard]] BuildBox side(std::size_t axis, std::size_t from, std::size_t to) const
    {
        BuildBox out;
        for (std::size_t k = from; k < to; ++k)
            out.merge(box[axis][k]);
        return out;
    }
};

/// A range's bins of a triangle along the three axes (by its box's centre), and the bins.
class Binner
{
public:
    explicit Binner(const BuildBox& box) : lo_(box.centre_lo), scale_(Lanes::Zero())
    {
        for (std::size_t a = 0; a < 3; ++a)
        {
            const double extent = box.centre_extent(a);
            used_[a] = extent > 0.0;
            if (used_[a])
                scale_[static_cast<Eigen::Index>(a)] =
                    static_cast<float>(static_cast<double>(sah_bins) / extent);
        }
    }

    [[nodiscard]] bool used(std::size_t axis) const { return used_[axis]; }

    /// The bins of r along the three axes (lane 3 unused).
    [[nodiscard]] Eigen::Array4i bins(const BuildRef& r) const
    {
        const Lanes t = ((r.centre2() - lo_) * scale_).max(0.0F).min(last_bin);
        return t.cast<int>();
    }

    void add(const BuildRef& r, Bins& bins) const
    {
        const Eigen::Array4i b = this->bins(r);
        for (std::size_t a = 0; a < 3; ++a)
        {
            const auto k = static_cast<std::size_t>(b[static_cast<Eigen::Index>(a)]);
            ++bins.count[a][k];
            bins.box[a][k].add(r);
        }
    }

private:
    static constexpr float last_bin = static_cast<float>(sah_bins - 1);
    Lanes lo_;
    Lanes scale_;
    std::array<bool, 3> used_{};
};

struct BestSplit
{
    std::size_t axis;
    std::size_t bin; ///< the last bin on the left
};

/// The cheapest split by the surface-area heuristic (bins up to `bin` on the left), or none
/// where every split leaves a side empty.
std::optional<BestSplit> best_split(const Bins& bins, std::size_t count, const Binner& binner)
{
    double best_cost = std::numeric_limits<double>::infinity();
    std::optional<BestSplit> best;
    for (std::size_t ax = 0; ax < 3; ++ax)
    {
        if (!binner.used(ax))
            continue;
        std::array<double, sah_bins> right_cost{};
        BuildBox acc;
        std::size_t acc_count = 0;
        for (std::size_t b = sah_bins - 1; b > 0; --b)
        {
            acc.merge(bins.box[ax][b]);
            acc_count += bins.count[ax][b];
            right_cost[b] = static_cast<double>(acc_count) * acc.half_area();
        }
        acc = BuildBox{};
        acc_count = 0;
        for (std::size_t b = 0; b + 1 < sah_bins; ++b)
        {
            acc.merge(bins.box[ax][b]);
            acc_count += bins.count[ax][b];
            if (acc_count == 0 || acc_count == count)
                continue;
            const double cost =
                static_cast<double>(acc_count) * acc.half_area() + right_cost[b + 1];
            if (cost < best_cost)
            {
                best_cost = cost;
                best = BestSplit{ax, b};
            }
        }
    }
    return best;
}

/// Closest point on segment [a, b] to p, as the weight t of b (point = a + t (b - a)).
double segment_parameter(const Vec3d& p, const Vec3d& a, const Vec3d& b)
{
    const Vec3d ab = b - a;
    const double len2 = ab.squaredNorm();
    if (!(len2 > 0.0))
        return 0.0;
    return std::clamp((p - a).dot(ab) / len2, 0.0, 1.0);
}

/// Degenerate triangle: the closest of its three edges (each possibly a point).
Vec3d closest_on_edges(const Vec3d& p, const Vec3d& a, const Vec3d& b, const Vec3d& c)
{
    const double tab = segment_parameter(p, a, b);
    const double tbc = segment_parameter(p, b, c);
    const double tca = segment_parameter(p, c, a);
    const std::array<Vec3d, 3> weights = {Vec3d(1.0 - tab, tab, 0.0), Vec3d(0.0, 1.0 - tbc, tbc),
                                          Vec3d(tca, 0.0, 1.0 - tca)};
    Vec3d best = weights[0];
    double best_d2 = std::numeric_limits<double>::infinity();
    for (const Vec3d& w : weights)
    {
        const double d2 = (p - (w[0] * a + w[1] * b + w[2] * c)).squaredNorm();
        if (d2 < best_d2)
        {
            best_d2 = d2;
            best = w;
        }
    }
    return best;
}

} // namespace

Vec3d closest_point_barycentric(const Vec3d& p, const Vec3d& a, const Vec3d& b, const Vec3d& c)
{
    // Region classification after Ericson, Real-Time Collision Detection §5.1.5, with guards for
    // zero-length edges and a face region computed from the normal.
    const Vec3d ab = b - a;
    const Vec3d ac = c - a;
    const Vec3d ap = p - a;
    const double d1 = ab.dot(ap);
    const double d2 = ac.dot(ap);
    if (d1 <= 0.0 && d2 <= 0.0)
        return {1.0, 0.0, 0.0}; // vertex a
    const Vec3d bp = p - b;
    const double d3 = ab.dot(bp);
    const double d4 = ac.dot(bp);
    if (d3 >= 0.0 && d4 <= d3)
        return {0.0, 1.0, 0.0}; // vertex b
    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0)
    {
        const double den = d1 - d3; // |ab|²
        if (den > 0.0)
        {
            const double v = std::clamp(d1 / den, 0.0, 1.0);
            return {1.0 - v, v, 0.0}; // edge ab
        }
    }
    const Vec3d cp = p - c;
    const double d5 = ab.dot(cp);
    const double d6 = ac.dot(cp);
    if (d6 >= 0.0 && d5 <= d6)
        return {0.0, 0.0, 1.0}; // vertex c
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0)
    {
        const double den = d2 - d6; // |ac|²
        if (den > 0.0)
        {
            const double w = std::clamp(d2 / den, 0.0, 1.0);
            return {1.0 - w, 0.0, w}; // edge ac
        }
    }
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0)
    {
        const double den = (d4 - d3) + (d5 - d6); // |bc|²
        if (den > 0.0)
        {
            const double w = std::clamp((d4 - d3) / den, 0.0, 1.0);
            return {0.0, 1.0 - w, w}; // edge bc
        }
    }
    // Face region: project onto the plane; weights from triple products with the normal, which
    // stay accurate on thin triangles where va + vb + vc would cancel.
    const Vec3d n = ab.cross(ac);
    const double nn = n.squaredNorm();
    if (!(nn > degenerate_sin2 * ab.squaredNorm() * ac.squaredNorm()))
        return closest_on_edges(p, a, b, c);
    double v = ap.cross(ac).dot(n) / nn;
    double w = ab.cross(ap).dot(n) / nn;
    v = std::max(v, 0.0);
    w = std::max(w, 0.0);
    if (v + w > 1.0)
    {
        const double s = v + w;
        v /= s;
        w /= s;
    }
    return {1.0 - v - w, v, w};
}

TriangleBvh::TriangleBvh(const TriMesh& mesh, const TriangleBvhOptions& options)
{
    const std::size_t f_count = mesh.face_count();
    const std::size_t v_count = mesh.vertex_count();
    if (f_count == 0)
        throw InvalidInput("triangle BVH: the mesh has no triangles");
    if (f_count >= std::numeric_limits<std::uint32_t>::max())
        throw InvalidInput("triangle BVH: " + std::to_string(f_count) +
                           " triangles exceed the 32-bit index range");
    if (!mesh.vertices.origin.allFinite())
        throw InvalidInput("triangle BVH: the mesh origin is not finite");
    for (std::size_t i = 0; i < v_count; ++i)
        if (!mesh.vertices.positions[i].allFinite())
            throw InvalidInput("triangle BVH: vertex " + std::to_string(i) +
                               " has a non-finite coordinate");
    for (std::size_t f = 0; f < f_count; ++f)
        for (const std::uint32_t v : mesh.triangles[f])
            if (v >= v_count)
                throw InvalidInput("triangle BVH: triangle " + std::to_string(f) +
                                   " refers to vertex " + std::to_string(v) + " but the mesh has " +
                                   std::to_string(v_count) + " vertices");

    const std::size_t group = options.group_size == 0 ? 1 : options.group_size;
    // Groups binned, partitioned and boxed in blocks of this many (a fixed count, so that the
    // tree does not depend on the thread count); ranges of at least four blocks are binned and
    // partitioned in parallel blocks.
    const std::size_t ref_block =
        options.build_block == 0 ? TriangleBvhOptions::default_build_block : options.build_block;
    const std::size_t parallel_split_refs = 4 * ref_block;
    if (f_count % group != 0)
        throw InvalidInput("triangle BVH: " + std::to_string(f_count) +
                           " triangles are not groups of " + std::to_string(group));
    origin_ = mesh.vertices.origin;
    face_count_ = f_count;
    // The build sorts the groups (items) and puts leaf_size triangles, at least one group, in
    // a leaf.
    const std::size_t items = f_count / group;
    const std::size_t leaf_size =
        std::max<std::size_t>(1, (options.leaf_size == 0 ? 4 : options.leaf_size) / group);

    // Each group's box, in one array that the build partitions in place, so that every pass
    // over a range streams.
    std::vector<BuildRef> refs(items);
    std::vector<BuildBox> block_box((items + ref_block - 1) / ref_block);
    parallel_blocks(items, ref_block, [&](std::size_t first, std::size_t last) {
        BuildBox& box = block_box[first / ref_block];
        for (std::size_t g = first; g < last; ++g)
        {
            BuildRef& r = refs[g];
            r.lo = Lanes::Constant(float_max);
            r.hi = Lanes::Constant(-float_max);
            for (std::size_t f = g * group; f < (g + 1) * group; ++f)
                for (const std::uint32_t v : mesh.triangles[f])
                {
                    const Vec3f& p = mesh.vertices.positions[v];
                    r.lo = r.lo.min(Lanes(p.x(), p.y(), p.z(), 0.0F));
                    r.hi = r.hi.max(Lanes(p.x(), p.y(), p.z(), 0.0F));
                }
            r.face = static_cast<std::uint32_t>(g);
            box.add(r);
        }
    });
    BuildBox root;
    for (const BuildBox& box : block_box)
        root.merge(box);
    // Splits [begin, end) (of node box `box`) into two children, writing their boxes, or
    // returns begin for a leaf. Large ranges are binned and partitioned in fixed blocks in
    // parallel (the same tree for any thread count: the bins' boxes and counts merge exactly),
    // through `scratch`, which is the caller's own: the subtrees are built at once, and a
    // subtree of more than parallel_split_refs groups (from meshes of a few million faces up,
    // as the top splits are unbalanced) splits its ranges in blocks too; one buffer shared by
    // them was resized and written by two threads at once (a 20M-face mesh crashed the build;
    // the 10M-sample refinement's level 4, 12M faces, aborted or measured distances to a
    // corrupted tree).
    const auto split = [&](std::size_t begin, std::size_t end, int depth, const BuildBox& box,
                           BuildBox& left, BuildBox& right,
                           std::vector<BuildRef>& scratch) -> std::size_t {
        const std::size_t count = end - begin;
        if (count <= leaf_size)
            return begin;
        const auto by_boxes = [&](std::size_t mid) {
            left = range_box(refs, begin, mid);
            right = range_box(refs, mid, end);
            return mid;
        };
        std::size_t axis = 0;
        for (std::size_t a = 1; a < 3; ++a)
            if (box.centre_extent(a) > box.centre_extent(axis))
                axis = a;
        const std::size_t middle = begin + count / 2;
        if (!(box.centre_extent(axis) > 0.0))
            return by_boxes(middle); // all centres coincide: any split is as good
        const auto median = [&]() {
            std::nth_element(
                refs.begin() + static_cast<std::ptrdiff_t>(begin),
                refs.begin() + static_cast<std::ptrdiff_t>(middle),
                refs.begin() + static_cast<std::ptrdiff_t>(end),
                [a = static_cast<Eigen::Index>(axis)](const BuildRef& x, const BuildRef& y) {
                    return centre_before(x, y, a);
                });
            return by_boxes(middle);
        };
        if (depth >= max_sah_depth)
            return median();
        if (count <= small_split_refs)
            return split_small(refs, begin, end, left, right);

        // Binned surface-area heuristic over all three axes, in one pass.
        const Binner binner(box);
        Bins bins;
        const bool in_blocks = count >= parallel_split_refs;
        if (in_blocks)
        {
            std::vector<Bins> partial((count + ref_block - 1) / ref_block);
            parallel_blocks(count, ref_block, [&](std::size_t first, std::size_t last) {
                Bins& mine = partial[first / ref_block];
                for (std::size_t i = begin + first; i < begin + last; ++i)
                    binner.add(refs[i], mine);
            });
            for (const Bins& p : partial)
                bins.merge(p);
        }
        else
        {
            for (std::size_t i = begin; i < end; ++i)
                binner.add(refs[i], bins);
        }
        const std::optional<BestSplit> best = best_split(bins, count, binner);
        if (!best)
            return median();
        left = bins.side(best->axis, 0, best->bin + 1);
        right = bins.side(best->axis, best->bin + 1, sah_bins);
        const auto goes_left = [&](const BuildRef& r) {
            return static_cast<std::size_t>(
                       binner.bins(r)[static_cast<Eigen::Index>(best->axis)]) <= best->bin;
        };
        if (!in_blocks)
        {
            const auto it =
                std::partition(refs.begin() + static_cast<std::ptrdiff_t>(begin),
                               refs.begin() + static_cast<std::ptrdiff_t>(end), goes_left);
            return static_cast<std::size_t>(it - refs.begin());
        }
        // A stable partition in fixed blocks: each block's left and right refs go to offsets
        // from the counts of the blocks before it.
        const std::size_t blocks = (count + ref_block - 1) / ref_block;
        std::vector<std::size_t> lefts(blocks + 1, 0);
        parallel_blocks(count, ref_block, [&](std::size_t first, std::size_t last) {
            std::size_t n = 0;
            for (std::size_t i = begin + first; i < begin + last; ++i)
                n += goes_left(refs[i]) ? 1U : 0U;
            lefts[first / ref_block + 1] = n;
        });
        for (std::size_t b = 0; b < blocks; ++b)
            lefts[b + 1] += lefts[b];
        const std::size_t left_count = lefts[blocks];
        scratch.resize(std::max(scratch.size(), count));
        parallel_blocks(count, ref_block, [&](std::size_t first, std::size_t last) {
            const std::size_t b = first / ref_block;
            std::size_t l = lefts[b];
            std::size_t r = left_count + first - lefts[b];
            for (std::size_t i = begin + first; i < begin + last; ++i)
                scratch[goes_left(refs[i]) ? l++ : r++] = refs[i];
        });
        parallel_blocks(count, ref_block, [&](std::size_t first, std::size_t last) {
            std::copy(scratch.begin() + static_cast<std::ptrdiff_t>(first),
                      scratch.begin() + static_cast<std::ptrdiff_t>(last),
                      refs.begin() + static_cast<std::ptrdiff_t>(begin + first));
        });
        return begin + left_count;
    };
    const auto node_of = [](const BuildBox& box) {
        Node node{};
        node.lo = {box.lo[0], box.lo[1], box.lo[2]};
        node.hi = {box.hi[0], box.hi[1], box.hi[2]};
        return node;
    };

    // Depth-first build of the range's subtree into `out` (a right child's index relative to
    // out's start), with an explicit stack of pending right children.
    const auto build_subtree = [&](std::size_t first, std::size_t last, int first_depth,
                                   const BuildBox& first_box, std::vector<Node>& out) {
        struct Pending
        {
            std::size_t begin;
            std::size_t end;
            int depth;
            std::size_t parent; ///< node whose right child this range becomes; npos for the root
            BuildBox box;
        };
        constexpr std::size_t no_parent = std::numeric_limits<std::size_t>::max();
        std::vector<Pending> pending;
        std::vector<BuildRef> scratch;
        pending.push_back({first, last, first_depth, no_parent, first_box});
        BuildBox left;
        BuildBox right;
        while (!pending.empty())
        {
            Pending range = pending.back();
            pending.pop_back();
            // Descend the left spine of this range, pushing right halves.
            for (;;)
            {
                const std::size_t node_index = out.size();
                if (range.parent != no_parent)
                {
                    out[range.parent].index = static_cast<std::uint32_t>(node_index);
                    range.parent = no_parent;
                }
                out.push_back(node_of(range.box));
                const std::size_t mid =
                    split(range.begin, range.end, range.depth, range.box, left, right, scratch);
                if (mid == range.begin || mid == range.end)
                {
                    out[node_index].index = static_cast<std::uint32_t>(range.begin);
                    out[node_index].count = static_cast<std::uint32_t>(range.end - range.begin);
                    break;
                }
                out[node_index].count = 0;
                pending.push_back({mid, range.end, range.depth + 1, node_index, right});
                range = {range.begin, mid, range.depth + 1, no_parent, left};
            }
        }
    };

    // The top levels are split first, one range after another (each large one in parallel
    // blocks); the subtrees below them are built in parallel and laid out after their parents
    // in depth-first order. Each range is split as the sequential build splits it, so the tree
    // is the same whatever the thread count.
    struct Top
    {
        std::size_t begin;
        std::size_t end;
        int depth;
        BuildBox box;
        std::size_t left = 0;    ///< index in `tops`, for an inner node
        std::size_t right = 0;   ///< index in `tops`, for an inner node
        std::size_t subtree = 0; ///< index in `subtrees` + 1, or 0 for an inner node or a leaf
        bool leaf = false;
    };
    std::vector<Top> tops;
    std::vector<std::size_t> roots; ///< the subtrees' tops, in depth-first order
    // Subtrees of at most this many triangles, or below this depth, are built in parallel.
    constexpr std::size_t subtree_triangles = 16384;
    constexpr int top_depth = 6;
    std::vector<BuildRef> scratch; // the top splits' partitions (one after another)
    const auto split_top = [&](const auto& self, std::size_t begin, std::size_t end, int depth,
                               const BuildBox& box) -> std::size_t {
        const std::size_t at = tops.size();
        tops.push_back({begin, end, depth, box});
        if (end - begin <= subtree_triangles || depth >= top_depth)
        {
            roots.push_back(at);
            tops[at].subtree = roots.size();
            return at;
        }
        BuildBox left_box;
        BuildBox right_box;
        const std::size_t mid = split(begin, end, depth, box, left_box, right_box, scratch);
        if (mid == begin || mid == end)
        {
            tops[at].leaf = true;
            return at;
        }
        const std::size_t left = self(self, begin, mid, depth + 1, left_box);
        const std::size_t right = self(self, mid, end, depth + 1, right_box);
        tops[at].left = left;
        tops[at].right = right;
        return at;
    };
    split_top(split_top, 0, items, 0, root);
    std::vector<BuildRef>().swap(scratch);
    std::vector<std::vector<Node>> subtrees(roots.size());
    parallel_blocks(roots.size(), 1, [&](std::size_t first, std::size_t last) {
        for (std::size_t r = first; r < last; ++r)
        {
            const Top& top = tops[roots[r]];
            build_subtree(top.begin, top.end, top.depth, top.box, subtrees[r]);
        }
    });
    nodes_.reserve(2 * items / leaf_size + 1);
    const auto emit = [&](const auto& self, std::size_t t) -> void {
        const Top& top = tops[t];
        if (top.subtree != 0)
        {
            const auto offset = static_cast<std::uint32_t>(nodes_.size());
            for (Node node : subtrees[top.subtree - 1])
            {
                if (node.count == 0)
                {
                    node.index += offset;
                }
                nodes_.push_back(node);
            }
            return;
        }
        const std::size_t node_index = nodes_.size();
        nodes_.push_back(node_of(top.box));
        if (top.leaf)
        {
            nodes_[node_index].index = static_cast<std::uint32_t>(top.begin);
            nodes_[node_index].count = static_cast<std::uint32_t>(top.end - top.begin);
            return;
        }
        nodes_[node_index].count = 0;
        self(self, top.left);
        nodes_[node_index].index = static_cast<std::uint32_t>(nodes_.size());
        self(self, top.right);
    };
    emit(emit, 0);
    if (group > 1)
        for (Node& node : nodes_)
            if (node.count > 0)
            {
                node.index *= static_cast<std::uint32_t>(group);
                node.count *= static_cast<std::uint32_t>(group);
            }

    corners_.resize(f_count);
    face_ids_.resize(f_count);
    parallel_blocks(f_count, ref_block, [&](std::size_t first, std::size_t last) {
        for (std::size_t i = first; i < last; ++i)
        {
            const auto f = static_cast<std::uint32_t>(refs[i / group].face * group + i % group);
            face_ids_[i] = f;
            const auto& t = mesh.triangles[f];
            corners_[i] = Corners{mesh.vertices.positions[t[0]], mesh.vertices.positions[t[1]],
                                  mesh.vertices.positions[t[2]]};
        }
    });
}

double triangle_box_depth(const TriMesh& mesh)
{
    const std::size_t v_count = mesh.vertex_count();
    const std::size_t f_count = mesh.face_count();
    Aabb all;
    for (const Triangle& t : mesh.triangles)
        for (const std::uint32_t v : t)
        {
            if (v >= v_count)
                throw InvalidInput("triangle box depth: a triangle refers to vertex " +
                                   std::to_string(v) + " of " + std::to_string(v_count));
            all.extend(mesh.vertices.positions[v].cast<double>());
        }
    const double total = half_area(all);
    if (!(total > 0.0))
        return static_cast<double>(f_count);
    // Partial sums per fixed block, added in block order: the same bits for any thread count.
    constexpr std::size_t block = 16384;
    std::vector<double> sums((f_count + block - 1) / block, 0.0);
    parallel_blocks(sums.size(), 1, [&](std::size_t first, std::size_t last) {
        for (std::size_t b = first; b < last; ++b)
        {
            double sum = 0.0;
            for (std::size_t f = b * block; f < std::min(f_count, (b + 1) * block); ++f)
            {
                Aabb box;
                for (const std::uint32_t v : mesh.triangles[f])
                    box.extend(mesh.vertices.positions[v].cast<double>());
                sum += half_area(box);
            }
            sums[b] = sum;
        }
    });
    double sum = 0.0;
    for (const double s : sums)
        sum += s;
    return sum / total;
}

void check_query_work(const TriMesh& mesh, std::size_t queries, std::string_view what,
                      double work_limit)
{
    constexpr double depth_limit = 64.0;
    if (mesh.face_count() == 0 || queries == 0)
        return;
    const double depth = triangle_box_depth(mesh);
    const double work = depth * static_cast<double>(queries);
    if (depth <= depth_limit || work <= work_limit)
        return;
    char figures[160];
    std::snprintf(figures, sizeof figures,
                  "each of %zu queries would test about %.0f of its %zu triangles (%.2g tests)",
                  queries, depth, mesh.face_count(), work);
    throw InvalidInput(std::string(what) +
                       ": the mesh's triangles are long slivers whose bounding boxes overlap (as "
                       "in a polygon of many vertices triangulated as a fan): " +
                       figures + "; remesh or retriangulate it first");
}

Aabb TriangleBvh::bounds() const
{
    Aabb box;
    if (nodes_.empty())
        return box;
    for (const Corners& k : corners_)
    {
        for (const Vec3d& corner : k.widened())
            box.extend(origin_ + corner);
    }
    return box;
}

namespace {

template <typename Node>
double box_distance2(const Node& node, const Vec3d& p)
{
    // Branch-free: a query is on one side of a slab or inside it, so at most one term is positive.
    double d2 = 0.0;
    for (std::size_t axis = 0; axis < 3; ++axis)
    {
        const double x = p[static_cast<Eigen::Index>(axis)];
        const double below = std::max(static_cast<double>(node.lo[axis]) - x, 0.0);
        const double above = std::max(x - static_cast<double>(node.hi[axis]), 0.0);
        const double d = below + above;
        d2 += d * d;
    }
    return d2;
}

} // namespace

TriangleBvh::Hit TriangleBvh::closest(const Vec3d& world_point, double max_distance) const
{
    Hit hit;
    const Vec3d p = world_point - origin_;
    double best2 = std::isfinite(max_distance) ? max_distance * max_distance
                                               : std::numeric_limits<double>::infinity();
    if (!p.allFinite() || !(max_distance > 0.0))
        return hit;
    std::uint32_t best_slot = std::numeric_limits<std::uint32_t>::max();
    Vec3d best_bary = Vec3d::Zero();

    struct Entry
    {
        std::uint32_t node;
        double d2;
    };
    std::array<Entry, stack_capacity> stack; // NOLINT(cppcoreguidelines-pro-type-member-init)
    std::size_t top = 0;
    stack[top++] = {0, box_distance2(nodes_[0], p)};
    while (top > 0)
    {
        const Entry entry = stack[--top];
        if (!(entry.d2 < best2))
            continue;
        const Node& node = nodes_[entry.node];
        if (node.count > 0)
        {
            for (std::uint32_t i = node.index; i < node.index + node.count; ++i)
            {
                const auto [a, b, c] = corners_[i].widened();
                const Vec3d bary = closest_point_barycentric(p, a, b, c);
                const Vec3d q = bary[0] * a + bary[1] * b + bary[2] * c;
                const double d2 = (p - q).squaredNorm();
                if (d2 < best2)
                {
                    best2 = d2;
                    best_slot = i;
                    best_bary = bary;
                }
            }
            continue;
        }
        const std::uint32_t left = entry.node + 1;
        const std::uint32_t right = node.index;
        const double dl = box_distance2(nodes_[left], p);
        const double dr = box_distance2(nodes_[right], p);
        // Push the farther child first so that the nearer one is visited next.
        const bool left_first = dl <= dr;
        const Entry near{left_first ? left : right, left_first ? dl : dr};
        const Entry far{left_first ? right : left, left_first ? dr : dl};
        PF_ASSERT(top + 2 <= stack_capacity);
        if (far.d2 < best2)
            stack[top++] = far;
        if (near.d2 < best2)
            stack[top++] = near;
    }
    if (best_slot == std::numeric_limits<std::uint32_t>::max())
        return hit;
    const auto [a, b, c] = corners_[best_slot].widened();
    const Vec3d q = best_bary[0] * a + best_bary[1] * b + best_bary[2] * c;
    hit.face = FaceId(face_ids_[best_slot]);
    hit.barycentric = best_bary;
    hit.point = origin_ + q;
    hit.distance = std::sqrt(best2);
    return hit;
}

bool TriangleBvh::any_within(const Vec3d& world_point, double distance) const
{
    const Vec3d p = world_point - origin_;
    if (!p.allFinite() || !(distance > 0.0))
        return false;
    const double limit2 = distance * distance;
    std::array<std::uint32_t, stack_capacity>
        stack; // NOLINT(cppcoreguidelines-pro-type-member-init)
    std::size_t top = 0;
    if (box_distance2(nodes_[0], p) < limit2)
        stack[top++] = 0;
    while (top > 0)
    {
        const Node& node = nodes_[stack[--top]];
        if (node.count > 0)
        {
            for (std::uint32_t i = node.index; i < node.index + node.count; ++i)
            {
                const auto [a, b, c] = corners_[i].widened();
                const Vec3d bary = closest_point_barycentric(p, a, b, c);
                if ((p - (bary[0] * a + bary[1] * b + bary[2] * c)).squaredNorm() < limit2)
                    return true;
            }
            continue;
        }
        const std::uint32_t left = static_cast<std::uint32_t>(&node - nodes_.data()) + 1;
        const std::uint32_t right = node.index;
        const double dl = box_distance2(nodes_[left], p);
        const double dr = box_distance2(nodes_[right], p);
        // The nearer child is visited first: its triangles are the likelier to be within.
        const bool left_first = dl <= dr;
        PF_ASSERT(top + 2 <= stack_capacity);
        if ((left_first ? dr : dl) < limit2)
            stack[top++] = left_first ? right : left;
        if ((left_first ? dl : dr) < limit2)
            stack[top++] = left_first ? left : right;
    }
    return false;
}

double TriangleBvh::distance(const Vec3d& world_point) const
{
    return closest(world_point).distance;
}

namespace {

/// body(run) for runs of the points' indices, in parallel, taking the points along a Morton
/// curve: neighbouring queries then walk the same nodes while they are in cache (on a mesh of
/// 1.1M triangles, 1M queries in random order ran twice as fast). The runs are fixed whatever
/// the thread count.
template <class Body>
void in_spatial_order(std::span<const Vec3f> positions, const ClosestPointOptions& options,
                      const Body& body)
{
    std::vector<std::uint32_t> sorted;
    std::span<const std::uint32_t> order = options.order;
    if (order.empty())
    {
        sorted = spatial_order(positions);
        order = sorted;
    }
    else
    {
        // A permutation: every query once (a repeated one would be written by two threads).
        std::vector<char> seen(positions.size(), 0);
        const bool permutation = order.size() == positions.size() &&
                                 std::all_of(order.begin(), order.end(), [&](std::uint32_t i) {
                                     return i < seen.size() && std::exchange(seen[i], char{1}) == 0;
                                 });
        if (!permutation)
            throw InvalidInput("closest points: the order given is not one of the " +
                               std::to_string(positions.size()) + " queries");
    }
    ProgressReporter progress(options.progress, "point-to-mesh distance");
    parallel_blocks(
        order.size(), query_block,
        [&](std::size_t begin, std::size_t end) { body(order.subspan(begin, end - begin)); },
        &progress);
    progress.finish();
}

} // namespace

std::vector<TriangleBvh::Hit> closest_points(const TriangleBvh& bvh, std::span<const Vec3d> queries,
                                             const ClosestPointOptions& options)
{
    std::vector<TriangleBvh::Hit> hits(queries.size());
    std::vector<Vec3f> near_origin(queries.size());
    parallel_blocks(queries.size(), query_block, [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i)
            near_origin[i] = (queries[i] - bvh.origin()).cast<float>();
    });
    // The closest point found for the query before bounds the next one's search, as in
    // nearest_triangles(): the same hits as unbounded searches.
    in_spatial_order(near_origin, options, [&](std::span<const std::uint32_t> run) {
        Vec3d previous = Vec3d::Constant(std::numeric_limits<double>::quiet_NaN());
        for (const std::uint32_t i : run)
        {
            const double bound = (queries[i] - previous).norm() * (1.0 + 1e-6);
            TriangleBvh::Hit hit;
            if (bound < options.max_distance)
                hit = bvh.closest(queries[i], bound);
            if (!hit.found())
                hit = bvh.closest(queries[i], options.max_distance);
            if (hit.found())
                previous = hit.point;
            hits[i] = hit;
        }
    });
    return hits;
}

namespace {

/// The searches of distances_to_mesh() and nearest_triangles(): `faces` may be null.
void nearest_of(const TriangleBvh& bvh, const PointCloudView& points,
                std::span<const double> upper_bounds, const ClosestPointOptions& options,
                std::span<double> distances, std::uint32_t* faces)
{
    // The closest point found for the query before bounds the next one's distance, which prunes
    // its search from the root (twice as fast far from the surface, where the queries of a run
    // are neighbours), and so does the caller's bound where it is smaller. A bound that admits
    // some triangle admits the nearest, so each distance is the one an unbounded search gives,
    // bit for bit; one that admits none falls back to the unbounded search.
    in_spatial_order(points.positions, options, [&](std::span<const std::uint32_t> run) {
        Vec3d previous = Vec3d::Constant(std::numeric_limits<double>::quiet_NaN());
        for (const std::uint32_t i : run)
        {
            const Vec3d p = points.world(i);
            double bound = (p - previous).norm(); // NaN for a run's first point
            if (!upper_bounds.empty() && (std::isnan(bound) || upper_bounds[i] < bound))
                bound = upper_bounds[i];
            bound *= 1.0 + 1e-6;
            TriangleBvh::Hit hit;
            if (bound < options.max_distance)
                hit = bvh.closest(p, bound);
            if (!hit.found())
                hit = bvh.closest(p, options.max_distance);
            if (hit.found())
                previous = hit.point;
            distances[i] = hit.distance;
            if (faces != nullptr)
                faces[i] = hit.found() ? hit.face.value : std::numeric_limits<std::uint32_t>::max();
        }
    });
}

} // namespace

std::vector<double> distances_to_mesh(const TriangleBvh& bvh, const PointCloudView& points,
                                      const ClosestPointOptions& options)
{
    std::vector<double> distances(points.size());
    nearest_of(bvh, points, {}, options, distances, nullptr);
    return distances;
}

NearestTriangles nearest_triangles(const TriangleBvh& bvh, const PointCloudView& points,
                                   std::span<const double> upper_bounds,
                                   const ClosestPointOptions& options)
{
    if (!upper_bounds.empty() && upper_bounds.size() != points.size())
        throw InvalidInput("nearest triangles: " + std::to_string(upper_bounds.size()) +
                           " upper bounds for " + std::to_string(points.size()) + " points");
    NearestTriangles out;
    out.distances.resize(points.size());
    out.faces.resize(points.size());
    nearest_of(bvh, points, upper_bounds, options, out.distances, out.faces.data());
    return out;
}

} // namespace pointform
