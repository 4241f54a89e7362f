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

float round_down(double x)
{
    float f = static_cast<float>(x);
    if (static_cast<double>(f) > x)
        f = std::nextafter(f, -std::numeric_limits<float>::infinity());
    return f;
}

float round_up(double x)
{
    float f = static_cast<float>(x);
    if (static_cast<double>(f) < x)
        f = std::nextafter(f, std::numeric_limits<float>::infinity());
    return f;
}

double half_area(const Aabb& box)
{
    if (box.is_empty())
        return 0.0;
    const Vec3d s = box.size();
    return s.x() * s.y() + s.y() * s.z() + s.z() * s.x();
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

    origin_ = mesh.vertices.origin;
    face_count_ = f_count;
    const std::size_t leaf_size = options.leaf_size == 0 ? 4 : options.leaf_size;

    // Each triangle's box and centroid (the corners are read again, in leaf order, at the end).
    const auto corners_of = [&mesh](std::size_t f) {
        const auto& t = mesh.triangles[f];
        return Corners{mesh.vertices.positions[t[0]].cast<double>(),
                       mesh.vertices.positions[t[1]].cast<double>(),
                       mesh.vertices.positions[t[2]].cast<double>()};
    };
    std::vector<Aabb> boxes(f_count);
    std::vector<Vec3d> centroids(f_count);
    parallel_blocks(f_count, 16384, [&](std::size_t first, std::size_t last) {
        for (std::size_t f = first; f < last; ++f)
        {
            const Corners k = corners_of(f);
            boxes[f].extend(k.a);
            boxes[f].extend(k.b);
            boxes[f].extend(k.c);
            centroids[f] = (k.a + k.b + k.c) / 3.0;
        }
    });

    std::vector<std::uint32_t> order(f_count);
    for (std::size_t f = 0; f < f_count; ++f)
        order[f] = static_cast<std::uint32_t>(f);
    nodes_.reserve(2 * f_count / leaf_size + 1);

    const auto make_node = [&](std::size_t begin, std::size_t end, std::vector<Node>& out) {
        Aabb box;
        for (std::size_t i = begin; i < end; ++i)
        {
            box.extend(boxes[order[i]].min);
            box.extend(boxes[order[i]].max);
        }
        Node node{};
        for (int axis = 0; axis < 3; ++axis)
        {
            const auto slot = static_cast<std::size_t>(axis);
            node.lo[slot] = round_down(box.min[axis]);
            node.hi[slot] = round_up(box.max[axis]);
        }
        out.push_back(node);
    };

    // Returns the split position in [begin, end), or begin if the range should be a leaf.
    const auto split = [&](std::size_t begin, std::size_t end, int depth) {
        const std::size_t count = end - begin;
        if (count <= leaf_size)
            return begin;
        Aabb centroid_box;
        for (std::size_t i = begin; i < end; ++i)
            centroid_box.extend(centroids[order[i]]);
        const Vec3d extent = centroid_box.size();
        Eigen::Index axis = 0;
        extent.maxCoeff(&axis);
        const auto middle = begin + count / 2;
        const auto by_axis = [&](Eigen::Index ax) {
            return [&centroids, ax](std::uint32_t x, std::uint32_t y) {
                return centroids[x][ax] < centroids[y][ax] ||
                       (centroids[x][ax] == centroids[y][ax] && x < y);
            };
        };
        if (!(extent[axis] > 0.0))
            return middle; // all centroids coincide: any split is as good
        if (depth >= max_sah_depth)
        {
            std::nth_element(order.begin() + static_cast<std::ptrdiff_t>(begin),
                             order.begin() + static_cast<std::ptrdiff_t>(middle),
                             order.begin() + static_cast<std::ptrdiff_t>(end), by_axis(axis));
            return middle;
        }

        // Binned surface-area heuristic over all three axes.
        double best_cost = std::numeric_limits<double>::infinity();
        Eigen::Index best_axis = -1;
        std::size_t best_bin = 0;
        for (Eigen::Index ax = 0; ax < 3; ++ax)
        {
            if (!(extent[ax] > 0.0))
                continue;
            std::array<Aabb, sah_bins> bin_box{};
            std::array<std::size_t, sah_bins> bin_count{};
            const double scale = static_cast<double>(sah_bins) / extent[ax];
            for (std::size_t i = begin; i < end; ++i)
            {
                const std::uint32_t f = order[i];
                const auto b = std::min(
                    sah_bins - 1,
                    static_cast<std::size_t>((centroids[f][ax] - centroid_box.min[ax]) * scale));
                bin_count[b]++;
                bin_box[b].extend(boxes[f].min);
                bin_box[b].extend(boxes[f].max);
            }
            std::array<double, sah_bins> right_cost{};
            Aabb acc;
            std::size_t acc_count = 0;
            for (std::size_t b = sah_bins - 1; b > 0; --b)
            {
                acc.extend(bin_box[b].min);
                acc.extend(bin_box[b].max);
                acc_count += bin_count[b];
                right_cost[b] = static_cast<double>(acc_count) * half_area(acc);
            }
            acc = Aabb{};
            acc_count = 0;
            for (std::size_t b = 0; b + 1 < sah_bins; ++b)
            {
                acc.extend(bin_box[b].min);
                acc.extend(bin_box[b].max);
                acc_count += bin_count[b];
                if (acc_count == 0 || acc_count == count)
                    continue;
                const double cost =
                    static_cast<double>(acc_count) * half_area(acc) + right_cost[b + 1];
                if (cost < best_cost)
                {
                    best_cost = cost;
                    best_axis = ax;
                    best_bin = b;
                }
            }
        }
        if (best_axis < 0)
        {
            std::nth_element(order.begin() + static_cast<std::ptrdiff_t>(begin),
                             order.begin() + static_cast<std::ptrdiff_t>(middle),
                             order.begin() + static_cast<std::ptrdiff_t>(end), by_axis(axis));
            return middle;
        }
        const double scale = static_cast<double>(sah_bins) / extent[best_axis];
        const double lo = centroid_box.min[best_axis];
        const auto it = std::partition(
            order.begin() + static_cast<std::ptrdiff_t>(begin),
            order.begin() + static_cast<std::ptrdiff_t>(end), [&](std::uint32_t f) {
                const auto b = std::min(
                    sah_bins - 1, static_cast<std::size_t>((centroids[f][best_axis] - lo) * scale));
                return b <= best_bin;
            });
        return static_cast<std::size_t>(it - order.begin());
    };

    // Depth-first build of the range's subtree into `out` (a right child's index relative to
    // out's start), with an explicit stack of pending right children.
    const auto build_subtree = [&](std::size_t first, std::size_t last, int first_depth,
                                   std::vector<Node>& out) {
        struct Pending
        {
            std::size_t begin;
            std::size_t end;
            int depth;
            std::size_t parent; ///< node whose right child this range becomes; npos for the root
        };
        constexpr std::size_t no_parent = std::numeric_limits<std::size_t>::max();
        std::vector<Pending> pending;
        pending.push_back({first, last, first_depth, no_parent});
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
                make_node(range.begin, range.end, out);
                const std::size_t mid = split(range.begin, range.end, range.depth);
                if (mid == range.begin || mid == range.end)
                {
                    out[node_index].index = static_cast<std::uint32_t>(range.begin);
                    out[node_index].count = static_cast<std::uint32_t>(range.end - range.begin);
                    break;
                }
                out[node_index].count = 0;
                pending.push_back({mid, range.end, range.depth + 1, node_index});
                range = {range.begin, mid, range.depth + 1, no_parent};
            }
        }
    };

    // The top levels are split first, one range after another; the subtrees below them are
    // built in parallel and laid out after their parents in depth-first order. Each range is
    // split as the sequential build splits it, so the tree is the same whatever the thread count.
    struct Top
    {
        std::size_t begin;
        std::size_t end;
        int depth;
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
    const auto split_top = [&](const auto& self, std::size_t begin, std::size_t end,
                               int depth) -> std::size_t {
        const std::size_t at = tops.size();
        tops.push_back({begin, end, depth});
        if (end - begin <= subtree_triangles || depth >= top_depth)
        {
            roots.push_back(at);
            tops[at].subtree = roots.size();
            return at;
        }
        const std::size_t mid = split(begin, end, depth);
        if (mid == begin || mid == end)
        {
            tops[at].leaf = true;
            return at;
        }
        const std::size_t left = self(self, begin, mid, depth + 1);
        const std::size_t right = self(self, mid, end, depth + 1);
        tops[at].left = left;
        tops[at].right = right;
        return at;
    };
    split_top(split_top, 0, f_count, 0);
    std::vector<std::vector<Node>> subtrees(roots.size());
    parallel_blocks(roots.size(), 1, [&](std::size_t first, std::size_t last) {
        for (std::size_t r = first; r < last; ++r)
        {
            const Top& top = tops[roots[r]];
            build_subtree(top.begin, top.end, top.depth, subtrees[r]);
        }
    });
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
        make_node(top.begin, top.end, nodes_);
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

    corners_.resize(f_count);
    face_ids_ = std::move(order);
    parallel_blocks(f_count, 16384, [&](std::size_t first, std::size_t last) {
        for (std::size_t i = first; i < last; ++i)
            corners_[i] = corners_of(face_ids_[i]);
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
        box.extend(origin_ + k.a);
        box.extend(origin_ + k.b);
        box.extend(origin_ + k.c);
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
                const Corners& k = corners_[i];
                const Vec3d bary = closest_point_barycentric(p, k.a, k.b, k.c);
                const Vec3d q = bary[0] * k.a + bary[1] * k.b + bary[2] * k.c;
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
    const Corners& k = corners_[best_slot];
    const Vec3d q = best_bary[0] * k.a + best_bary[1] * k.b + best_bary[2] * k.c;
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
                const Corners& k = corners_[i];
                const Vec3d bary = closest_point_barycentric(p, k.a, k.b, k.c);
                if ((p - (bary[0] * k.a + bary[1] * k.b + bary[2] * k.c)).squaredNorm() < limit2)
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
