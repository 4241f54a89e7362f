// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/polygonize/handles.h"

#include "pointform/core/disjoint_sets.h"
#include "pointform/core/error.h"
#include "pointform/core/parallel.h"
#include "pointform/geometry/mesh_topology.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <numeric>
#include <optional>
#include <queue>
#include <span>
#include <utility>
#include <vector>

namespace pointform {
namespace {

constexpr std::uint32_t none = std::numeric_limits<std::uint32_t>::max();

/// Rounds of cut_short_handles() at most: a round cuts up to 64 loops (the hashes' width), so
/// 1,024 handles in all, which bounds the time a pathological mesh takes (each round rebuilds
/// the edges and the homology basis).
constexpr std::size_t max_cut_rounds = 16;

/// The undirected edges of a manifold mesh, each with its (one or two) triangles, and the
/// edges round each vertex in CSR form.
struct EdgeGraph
{
    std::vector<std::array<std::uint32_t, 2>> ends;  ///< lower vertex first
    std::vector<std::array<std::uint32_t, 2>> faces; ///< [1] = none on the boundary
    std::vector<double> length;
    std::vector<std::size_t> offsets;  ///< vertex_count + 1
    std::vector<std::uint32_t> around; ///< edge ids round each vertex, increasing
    std::vector<char> on_boundary;     ///< per vertex

    [[nodiscard]] std::span<const std::uint32_t> edges_of(std::uint32_t v) const
    {
        return std::span<const std::uint32_t>(around).subspan(offsets[v],
                                                              offsets[v + 1] - offsets[v]);
    }
    [[nodiscard]] std::uint32_t other(std::uint32_t e, std::uint32_t v) const
    {
        return ends[e][0] == v ? ends[e][1] : ends[e][0];
    }
};

EdgeGraph edge_graph(const TriMesh& mesh)
{
    const std::size_t nv = mesh.vertex_count();
    struct Half
    {
        std::uint64_t key;
        std::uint32_t face;
    };
    std::vector<Half> halves;
    halves.reserve(3 * mesh.face_count());
    for (std::size_t f = 0; f < mesh.face_count(); ++f)
    {
        const Triangle& t = mesh.triangles[f];
        for (int c = 0; c < 3; ++c)
        {
            const std::uint32_t a = std::min(t[c], t[(c + 1) % 3]);
            const std::uint32_t b = std::max(t[c], t[(c + 1) % 3]);
            halves.push_back({(std::uint64_t{a} << 32) | b, static_cast<std::uint32_t>(f)});
        }
    }
    std::sort(halves.begin(), halves.end(), [](const Half& x, const Half& y) {
        return x.key != y.key ? x.key < y.key : x.face < y.face;
    });
    EdgeGraph g;
    g.on_boundary.assign(nv, 0);
    for (std::size_t i = 0; i < halves.size();)
    {
        std::size_t j = i;
        while (j < halves.size() && halves[j].key == halves[i].key)
            ++j;
        const auto a = static_cast<std::uint32_t>(halves[i].key >> 32);
        const auto b = static_cast<std::uint32_t>(halves[i].key & 0xffffffffU);
        g.ends.push_back({a, b});
        g.faces.push_back({halves[i].face, j - i > 1 ? halves[i + 1].face : none});
        g.length.push_back((mesh.vertices.world(a) - mesh.vertices.world(b)).norm());
        if (j - i == 1)
            g.on_boundary[a] = g.on_boundary[b] = 1;
        i = j;
    }
    g.offsets.assign(nv + 1, 0);
    for (const auto& e : g.ends)
    {
        ++g.offsets[e[0] + 1];
        ++g.offsets[e[1] + 1];
    }
    std::partial_sum(g.offsets.begin(), g.offsets.end(), g.offsets.begin());
    g.around.resize(2 * g.ends.size());
    std::vector<std::size_t> fill(g.offsets.begin(), g.offsets.end() - 1);
    for (std::size_t e = 0; e < g.ends.size(); ++e)
        for (const std::uint32_t v : g.ends[e])
            g.around[fill[v]++] = static_cast<std::uint32_t>(e);
    return g;
}

std::uint64_t splitmix(std::uint64_t& state)
{
    std::uint64_t z = (state += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

/// Each edge's Z/2 homology class of the surface with its holes capped, hashed to 64 bits by a
/// fixed random linear map: the XOR of a loop's edge hashes is zero exactly when the loop
/// separates the surface (but for a chance of 2⁻⁶⁴ per loop). Tree-cotree (Eppstein 2003): a
/// spanning tree T of the vertices, a spanning tree C of the faces and caps across the edges not
/// in T; each of the 2g edges in neither closes a dual cycle δᵢ, and an edge's class is the set
/// of δᵢ it crosses, whose random vectors it carries XORed. \return the hashes; `genus` = g
struct Homology
{
    std::vector<std::uint64_t> hash;
    std::size_t genus = 0;
};

Homology edge_homology(const TriMesh& mesh, const EdgeGraph& g)
{
    const std::size_t nv = mesh.vertex_count();
    const std::size_t nf = mesh.face_count();
    const std::size_t ne = g.ends.size();
    // Holes: boundary loops, joined through their vertices (one cap each).
    DisjointSets rims(nv);
    for (std::size_t e = 0; e < ne; ++e)
        if (g.faces[e][1] == none)
            rims.unite(g.ends[e][0], g.ends[e][1]);
    std::vector<std::uint32_t> cap_of(nv, none);
    std::size_t caps = 0;
    for (std::size_t e = 0; e < ne; ++e)
        if (g.faces[e][1] == none)
        {
            std::uint32_t& c = cap_of[rims.find(g.ends[e][0])];
            if (c == none)
                c = static_cast<std::uint32_t>(nf + caps++);
        }
    auto dual_ends = [&](std::size_t e) -> std::array<std::uint32_t, 2> {
        return {g.faces[e][0],
                g.faces[e][1] != none ? g.faces[e][1] : cap_of[rims.find(g.ends[e][0])]};
    };

    // T: breadth first from each component's lowest vertex.
    std::vector<char> in_tree(ne, 0);
    std::vector<char> seen(nv, 0);
    std::vector<std::uint32_t> queue;
    for (std::uint32_t root = 0; root < nv; ++root)
    {
        if (seen[root] != 0 || g.offsets[root] == g.offsets[root + 1])
            continue;
        seen[root] = 1;
        queue.assign(1, root);
        for (std::size_t q = 0; q < queue.size(); ++q)
            for (const std::uint32_t e : g.edges_of(queue[q]))
            {
                const std::uint32_t w = g.other(e, queue[q]);
                if (seen[w] == 0)
                {
                    seen[w] = 1;
                    in_tree[e] = 1;
                    queue.push_back(w);
                }
            }
    }
    // C: a spanning forest of the dual across the other edges; the rest are the leftovers.
    const std::size_t nd = nf + caps;
    DisjointSets dual(nd);
    std::vector<char> in_cotree(ne, 0);
    std::vector<std::uint32_t> leftover;
    for (std::size_t e = 0; e < ne; ++e)
    {
        if (in_tree[e] != 0)
            continue;
        const auto d = dual_ends(e);
        if (dual.unite(d[0], d[1]))
            in_cotree[e] = 1;
        else
            leftover.push_back(static_cast<std::uint32_t>(e));
    }
    Homology h;
    h.genus = leftover.size() / 2;
    h.hash.assign(ne, 0);
    if (leftover.empty())
        return h;
    // C rooted: each dual node's parent edge, in breadth-first order.
    std::vector<std::size_t> offsets(nd + 1, 0);
    for (std::size_t e = 0; e < ne; ++e)
        if (in_cotree[e] != 0)
            for (const std::uint32_t d : dual_ends(e))
                ++offsets[d + 1];
    std::partial_sum(offsets.begin(), offsets.end(), offsets.begin());
    std::vector<std::uint32_t> adjacent(offsets.back());
    {
        std::vector<std::size_t> fill(offsets.begin(), offsets.end() - 1);
        for (std::size_t e = 0; e < ne; ++e)
            if (in_cotree[e] != 0)
                for (const std::uint32_t d : dual_ends(e))
                    adjacent[fill[d]++] = static_cast<std::uint32_t>(e);
    }
    std::vector<std::uint32_t> parent_edge(nd, none);
    std::vector<std::uint32_t> parent(nd, none);
    std::vector<char> reached(nd, 0);
    std::vector<std::uint32_t> order;
    order.reserve(nd);
    for (std::uint32_t root = 0; root < nd; ++root)
    {
        if (reached[root] != 0)
            continue;
        reached[root] = 1;
        const std::size_t first = order.size();
        order.push_back(root);
        for (std::size_t q = first; q < order.size(); ++q)
        {
            const std::uint32_t d = order[q];
            for (std::size_t k = offsets[d]; k < offsets[d + 1]; ++k)
            {
                const std::uint32_t e = adjacent[k];
                const auto ends = dual_ends(e);
                const std::uint32_t w = ends[0] == d ? ends[1] : ends[0];
                if (reached[w] == 0)
                {
                    reached[w] = 1;
                    parent[w] = d;
                    parent_edge[w] = e;
                    order.push_back(w);
                }
            }
        }
    }
    // δᵢ = the leftover edge plus C's path between its dual ends: each end gets the random
    // vector, and a cotree edge is on the path when its subtree holds one end (an odd count).
    std::vector<std::uint64_t> label(nd, 0);
    std::uint64_t state = 0x706f696e74666f72ULL; // fixed: the same hashes every run
    for (const std::uint32_t e : leftover)
    {
        const std::uint64_t r = splitmix(state);
        h.hash[e] = r;
        for (const std::uint32_t d : dual_ends(e))
            label[d] ^= r;
    }
    for (std::size_t k = order.size(); k-- > 0;)
    {
        const std::uint32_t d = order[k];
        if (parent[d] == none)
            continue;
        h.hash[parent_edge[d]] = label[d];
        label[parent[d]] ^= label[d];
    }
    return h;
}

/// The shortest loop found from one seed: two shortest paths from it, to the ends of `edge`.
struct Candidate
{
    double length = std::numeric_limits<double>::infinity();
    std::uint32_t seed = none;
    std::uint32_t edge = none;
    std::uint64_t hash = 0;
};

/// A bounded Dijkstra search from a seed, with its scratch kept across seeds (reset through
/// the vertices it touched).
class Search
{
public:
    explicit Search(std::size_t vertex_count)
        : distance_(vertex_count, std::numeric_limits<double>::infinity()),
          parent_edge_(vertex_count, none),
          hash_(vertex_count, 0),
          settled_(vertex_count, 0)
    {}

    /// Settles the vertices within `reach` of `seed` (along the edges, boundary vertices left
    /// out), each with its distance, its tree edge and, given `edge_hash`, the XOR of the hashes
    /// of its path from the seed.
    void grow(std::uint32_t seed, const EdgeGraph& g, double reach,
              std::span<const std::uint64_t> edge_hash)
    {
        for (const std::uint32_t v : touched_)
        {
            distance_[v] = std::numeric_limits<double>::infinity();
            parent_edge_[v] = none;
            hash_[v] = 0;
            settled_[v] = 0;
        }
        touched_.clear();
        settled_list_.clear();
        using Entry = std::pair<double, std::uint32_t>;
        std::priority_queue<Entry, std::vector<Entry>, std::greater<>> heap;
        distance_[seed] = 0.0;
        touched_.push_back(seed);
        heap.emplace(0.0, seed);
        while (!heap.empty())
        {
            const auto [d, u] = heap.top();
            heap.pop();
            if (settled_[u] != 0 || d > distance_[u])
                continue;
            settled_[u] = 1;
            settled_list_.push_back(u);
            for (const std::uint32_t e : g.edges_of(u))
            {
                const std::uint32_t w = g.other(e, u);
                if (g.on_boundary[w] != 0 || settled_[w] != 0)
                    continue;
                const double dw = d + g.length[e];
                if (dw > reach || !(dw < distance_[w]))
                    continue;
                if (distance_[w] == std::numeric_limits<double>::infinity())
                    touched_.push_back(w);
                distance_[w] = dw;
                parent_edge_[w] = e;
                if (!edge_hash.empty())
                    hash_[w] = hash_[u] ^ edge_hash[e];
                heap.emplace(dw, w);
            }
        }
    }

    /// The shortest non-separating loop through `seed` within `max_length` (an edge between two
    /// vertices within max_length / 2, neither's tree edge, whose loop's hash is not zero).
    Candidate run(std::uint32_t seed, const EdgeGraph& g, const Homology& h, double max_length)
    {
        grow(seed, g, 0.5 * max_length, h.hash);
        Candidate best;
        best.seed = seed;
        for (const std::uint32_t u : settled_list_)
            for (const std::uint32_t e : g.edges_of(u))
            {
                const std::uint32_t w = g.other(e, u);
                if (w < u || settled_[w] == 0 || parent_edge_[u] == e || parent_edge_[w] == e)
                    continue;
                const double length = distance_[u] + g.length[e] + distance_[w];
                const std::uint64_t hash = hash_[u] ^ hash_[w] ^ h.hash[e];
                if (hash == 0 || length > max_length)
                    continue;
                if (length < best.length || (length == best.length && e < best.edge))
                {
                    best.length = length;
                    best.edge = e;
                    best.hash = hash;
                }
            }
        return best;
    }

    /// The vertices the last grow() settled (all within its reach; the seed first).
    [[nodiscard]] std::span<const std::uint32_t> settled() const { return settled_list_; }

    /// The vertices the last run settled within `reach` of its seed (the seed first).
    void settled_within(double reach, std::vector<std::uint32_t>& out) const
    {
        for (const std::uint32_t v : settled_list_)
            if (distance_[v] <= reach)
                out.push_back(v);
    }

    /// The loop of a candidate this search just ran for: from the lowest common ancestor of the
    /// edge's ends down one path, across the edge and back up the other.
    MeshLoop loop(const Candidate& c, const EdgeGraph& g) const
    {
        auto path_up = [&](std::uint32_t v) {
            std::vector<std::uint32_t> path{v};
            while (parent_edge_[v] != none)
            {
                v = g.other(parent_edge_[v], v);
                path.push_back(v);
            }
            return path; // v ... seed
        };
        std::vector<std::uint32_t> a = path_up(g.ends[c.edge][0]);
        std::vector<std::uint32_t> b = path_up(g.ends[c.edge][1]);
        // Drop the shared part above the common ancestor (kept once).
        while (a.size() >= 2 && b.size() >= 2 && a[a.size() - 2] == b[b.size() - 2])
        {
            a.pop_back();
            b.pop_back();
        }
        MeshLoop out;
        // a: u ... lca, b: w ... lca. Loop: lca ... u, w ... (before lca).
        out.vertices.assign(a.rbegin(), a.rend());
        for (std::size_t k = 0; k + 1 < b.size(); ++k)
            out.vertices.push_back(b[k]);
        // Re-measure (the common part above the ancestor is not in the loop).
        for (std::size_t k = 0; k < out.vertices.size(); ++k)
        {
            const std::uint32_t p = out.vertices[k];
            const std::uint32_t q = out.vertices[(k + 1) % out.vertices.size()];
            for (const std::uint32_t e : g.edges_of(p))
                if (g.other(e, p) == q)
                {
                    out.length += g.length[e];
                    break;
                }
        }
        return out;
    }

private:
    std::vector<double> distance_;
    std::vector<std::uint32_t> parent_edge_;
    std::vector<std::uint64_t> hash_;
    std::vector<char> settled_;
    std::vector<std::uint32_t> touched_;
    std::vector<std::uint32_t> settled_list_;
};

/// The shortest candidate of each of `seeds` that has one, in order of length then seed. The
/// seeds are split into a few blocks a thread (each block's search keeps its scratch across its
/// seeds); a seed's candidate does not depend on the split.
std::vector<Candidate> candidates(const TriMesh& mesh, const EdgeGraph& g, const Homology& h,
                                  std::span<const std::uint32_t> seeds, double max_length)
{
    const std::size_t nv = mesh.vertex_count();
    const std::size_t blocks = 4 * static_cast<std::size_t>(std::max(1, thread_count()));
    const std::size_t block = std::max<std::size_t>(256, (seeds.size() + blocks - 1) / blocks);
    std::vector<Candidate> found = parallel_collect<Candidate>(
        seeds.size(), block, [&](std::size_t begin, std::size_t end, std::vector<Candidate>& out) {
            Search search(nv);
            for (std::size_t k = begin; k < end; ++k)
            {
                const std::uint32_t v = seeds[k];
                if (g.on_boundary[v] != 0 || g.offsets[v] == g.offsets[v + 1])
                    continue;
                const Candidate c = search.run(v, g, h, max_length);
                if (c.edge != none)
                    out.push_back(c);
            }
        });
    std::sort(found.begin(), found.end(), [](const Candidate& a, const Candidate& b) {
        return a.length != b.length ? a.length < b.length : a.seed < b.seed;
    });
    return found;
}

/// A geodesic cover: vertices in index order, each not yet within `spacing` (along the edges,
/// away from the boundary) of one taken before it is taken. Every interior vertex is then within
/// `spacing` of one of them. Serial; each vertex is reached from a few of them.
std::vector<std::uint32_t> cover(const EdgeGraph& g, std::size_t vertex_count, double spacing)
{
    std::vector<char> covered(vertex_count, 0);
    std::vector<std::uint32_t> centres;
    Search search(vertex_count);
    for (std::uint32_t v = 0; v < vertex_count; ++v)
    {
        if (covered[v] != 0 || g.on_boundary[v] != 0 || g.offsets[v] == g.offsets[v + 1])
            continue;
        centres.push_back(v);
        search.grow(v, g, spacing, {});
        for (const std::uint32_t u : search.settled())
            covered[u] = 1;
    }
    return centres;
}

/// The seeds whose searches can find a loop of at most `max_length`. Take such a loop γ, a
/// vertex v on it and a centre c of a cover() within `spacing` of v. The loops through c made of
/// its shortest paths to the ends of an edge of γ sum to γ's class, so one of them is not zero,
/// and each is at most max_length + 2 spacing and an edge of γ long: c's search to that bound
/// finds a loop. So only the vertices within `spacing` of a centre whose search found a loop
/// are seeds; where there is no short handle, searches from the centres alone show it. Their
/// cost goes as (max_length / 2 + 2 spacing)² / spacing², least for wide spacings; half the
/// bound is three times cheaper than a quarter, and leaves fewer seeds round a handle than the
/// whole bound.
std::vector<std::uint32_t> hot_seeds(const TriMesh& mesh, const EdgeGraph& g, const Homology& h,
                                     double max_length)
{
    const std::size_t nv = mesh.vertex_count();
    const double spacing = 0.5 * max_length;
    double longest_edge = 0.0; // of those a loop within the bound can have
    for (const double length : g.length)
        if (length <= max_length)
            longest_edge = std::max(longest_edge, length);
    const double bound = max_length + 2.0 * spacing + longest_edge;
    const std::vector<std::uint32_t> centres = cover(g, nv, spacing);
    const std::size_t blocks = 4 * static_cast<std::size_t>(std::max(1, thread_count()));
    const std::size_t block = std::max<std::size_t>(64, (centres.size() + blocks - 1) / blocks);
    std::vector<std::uint32_t> seeds = parallel_collect<std::uint32_t>(
        centres.size(), block,
        [&](std::size_t begin, std::size_t end, std::vector<std::uint32_t>& out) {
            Search search(nv);
            for (std::size_t k = begin; k < end; ++k)
                if (search.run(centres[k], g, h, bound).edge != none)
                    search.settled_within(spacing, out);
        });
    std::sort(seeds.begin(), seeds.end());
    seeds.erase(std::unique(seeds.begin(), seeds.end()), seeds.end());
    return seeds;
}

/// Z/2 row reduction over 64-bit hashes: whether `hash` is independent of those added so far
/// (and then adds it).
class Basis
{
public:
    bool add(std::uint64_t hash)
    {
        for (const std::uint64_t row : rows_)
            hash = std::min(hash, hash ^ row);
        if (hash == 0)
            return false;
        rows_.push_back(hash);
        std::sort(rows_.begin(), rows_.end(), std::greater<>());
        return true;
    }
    [[nodiscard]] std::size_t size() const { return rows_.size(); }

private:
    std::vector<std::uint64_t> rows_; // decreasing, distinct leading bits
};

/// Cuts the mesh along a simple loop of interior vertices and caps both sides. \return false
/// (mesh untouched) if a vertex's fan does not run from one loop edge to the other.
bool cut_and_cap(TriMesh& mesh, const MeshLoop& loop, const VertexFans& fans)
{
    const std::size_t k = loop.vertices.size();
    if (k < 3)
        return false;
    // The faces on the left of the loop (the side that holds the triangle using each edge
    // in the loop's direction), per loop vertex: a sweep round it from the next vertex to the
    // previous one.
    std::vector<std::vector<std::uint32_t>> left(k);
    for (std::size_t i = 0; i < k; ++i)
    {
        const std::uint32_t v = loop.vertices[i];
        const std::uint32_t next = loop.vertices[(i + 1) % k];
        const std::uint32_t prev = loop.vertices[(i + k - 1) % k];
        auto face_from = [&](std::uint32_t a) -> std::pair<std::uint32_t, std::uint32_t> {
            // The face holding the halfedge v → a, and its third vertex.
            for (const std::uint32_t f : fans.faces_of(v))
            {
                const Triangle& t = mesh.triangles[f];
                for (int c = 0; c < 3; ++c)
                    if (t[c] == v && t[(c + 1) % 3] == a)
                        return {f, t[(c + 2) % 3]};
            }
            return {none, none};
        };
        std::uint32_t a = next;
        for (std::size_t step = 0;; ++step)
        {
            const auto [f, b] = face_from(a);
            if (f == none || step > fans.faces_of(v).size())
                return false;
            left[i].push_back(f);
            if (b == prev)
                break;
            a = b;
        }
        if (left[i].size() >= fans.faces_of(v).size())
            return false; // the sweep took every face: not a loop through v's interior
    }
    PointCloud& points = mesh.vertices;
    Vec3d centroid = Vec3d::Zero();
    for (const std::uint32_t v : loop.vertices)
        centroid += points.world(v);
    centroid /= static_cast<double>(k);
    double radius = 0.0;
    Vec3d area = Vec3d::Zero();
    for (std::size_t i = 0; i < k; ++i)
    {
        const Vec3d p = points.world(loop.vertices[i]) - centroid;
        const Vec3d q = points.world(loop.vertices[(i + 1) % k]) - centroid;
        radius += p.norm();
        area += p.cross(q);
    }
    radius /= static_cast<double>(k);
    const Vec3d normal = area.norm() > 0.0 ? Vec3d(area.normalized()) : Vec3d::Zero();
    auto append = [&](std::uint32_t from, const Vec3d* at) {
        const auto index = static_cast<std::uint32_t>(points.size());
        points.positions.push_back(at != nullptr ? Vec3f((*at - points.origin).cast<float>())
                                                 : points.positions[from]);
        if (!points.normals.empty())
            points.normals.push_back(at != nullptr ? normal.cast<float>() : points.normals[from]);
        if (!points.colors.empty())
            points.colors.push_back(points.colors[from]);
        if (!points.radii.empty())
            points.radii.push_back(points.radii[from]);
        return index;
    };
    std::vector<std::uint32_t> copy(k);
    for (std::size_t i = 0; i < k; ++i)
        copy[i] = append(loop.vertices[i], nullptr);
    for (std::size_t i = 0; i < k; ++i)
        for (const std::uint32_t f : left[i])
            for (std::uint32_t& corner : mesh.triangles[f])
                if (corner == loop.vertices[i])
                    corner = copy[i];
    // The left side's cap turns against its faces' halfedges v'→next' (so its normal, the
    // loop's vector area, points to the right side): its centre moves to the left, and the right
    // cap's to the right, so the two do not coincide.
    const double offset = 0.1 * radius;
    const Vec3d left_centre = centroid - offset * normal;
    const Vec3d right_centre = centroid + offset * normal;
    const std::uint32_t cl = append(loop.vertices[0], &left_centre);
    const std::uint32_t cr = append(loop.vertices[0], &right_centre);
    for (std::size_t i = 0; i < k; ++i)
    {
        const std::size_t j = (i + 1) % k;
        mesh.triangles.push_back({copy[j], copy[i], cl});
        mesh.triangles.push_back({loop.vertices[i], loop.vertices[j], cr});
    }
    return true;
}

} // namespace

MeshLoop shortest_handle_loop(const TriMesh& mesh, double max_length)
{
    if (!(max_length > 0.0) || mesh.face_count() == 0)
        return {};
    const EdgeGraph g = edge_graph(mesh);
    const Homology h = edge_homology(mesh, g);
    if (h.genus == 0)
        return {};
    const std::vector<Candidate> found =
        candidates(mesh, g, h, hot_seeds(mesh, g, h, max_length), max_length);
    if (found.empty())
        return {};
    Search search(mesh.vertex_count());
    const Candidate c = search.run(found.front().seed, g, h, max_length);
    return search.loop(c, g);
}

HandleCutReport cut_short_handles(TriMesh& mesh, double max_length)
{
    HandleCutReport report;
    report.max_length = max_length;
    if (mesh.face_count() == 0)
        return report;
    if (!analyze_topology(mesh).is_oriented_manifold())
    {
        report.skipped_not_manifold = true;
        return report;
    }
    // The first round searches from the hot_seeds(); a later one only from the seeds that found
    // a loop in the round before and the vertices the cuts made (a cut removes loops, and a loop
    // it makes short runs through a cap).
    std::vector<std::uint32_t> seeds;
    for (bool first = true;; first = false)
    {
        if (report.rounds == max_cut_rounds)
            return report; // genus_after counts what is left
        const EdgeGraph g = edge_graph(mesh);
        const Homology h = edge_homology(mesh, g);
        if (first)
            report.genus_before = h.genus;
        report.genus_after = h.genus;
        if (h.genus == 0 || !(max_length > 0.0))
            return report;
        if (first)
            seeds = hot_seeds(mesh, g, h, max_length);
        const std::vector<Candidate> found = candidates(mesh, g, h, seeds, max_length);
        if (found.empty())
            return report;
        // Shortest first, each independent of those taken (so the cuts together split
        // nothing) and clear of them by a ring (so no vertex is on two loops).
        std::vector<char> blocked(mesh.vertex_count(), 0);
        Basis basis;
        Search search(mesh.vertex_count());
        std::vector<MeshLoop> taken;
        for (const Candidate& candidate : found)
        {
            if (basis.size() == 64)
                break;
            if (blocked[candidate.seed] != 0)
                continue;
            Basis trial = basis;
            if (!trial.add(candidate.hash))
                continue;
            const Candidate c = search.run(candidate.seed, g, h, max_length);
            MeshLoop loop = search.loop(c, g);
            if (std::any_of(loop.vertices.begin(), loop.vertices.end(),
                            [&](std::uint32_t v) { return blocked[v] != 0; }))
                continue;
            basis = trial;
            for (const std::uint32_t v : loop.vertices)
            {
                blocked[v] = 1;
                for (const std::uint32_t e : g.edges_of(v))
                    blocked[g.other(e, v)] = 1;
            }
            taken.push_back(std::move(loop));
        }
        const std::size_t old_count = mesh.vertex_count();
        const VertexFans fans = vertex_fans(mesh.triangles, old_count);
        std::size_t cut = 0;
        for (const MeshLoop& loop : taken)
        {
            // Faces keep their index through a cut (the caps are appended), so the fans stay
            // right for the other loops, whose vertices no cut touched.
            if (cut_and_cap(mesh, loop, fans))
            {
                ++cut;
                report.longest_cut = std::max(report.longest_cut, loop.length);
                report.lengths.push_back(loop.length);
            }
        }
        report.cuts += cut;
        ++report.rounds;
        if (cut == 0)
            return report;
        seeds.clear();
        for (const Candidate& c : found)
            seeds.push_back(c.seed);
        std::sort(seeds.begin(), seeds.end());
        for (std::size_t v = old_count; v < mesh.vertex_count(); ++v)
            seeds.push_back(static_cast<std::uint32_t>(v));
    }
}

std::size_t sponge_genus(const TriMesh& mesh)
{
    // A sponge: at least this many handles, and one for every sponge_vertices_per_handle
    // vertices or fewer.
    constexpr std::size_t sponge_least_genus = 64;
    constexpr std::size_t sponge_vertices_per_handle = 500;
    const MeshTopology topology = analyze_topology(mesh);
    // 2 C − χ − B = 2 g, summed over the components.
    const std::int64_t twice = static_cast<std::int64_t>(2 * topology.components) -
                               topology.euler_characteristic -
                               static_cast<std::int64_t>(topology.boundary_loops);
    const std::size_t genus = twice > 0 ? static_cast<std::size_t>(twice / 2) : 0;
    return genus >= sponge_least_genus && genus * sponge_vertices_per_handle >= topology.vertices
               ? genus
               : 0;
}

NoiseScaleRegion spongy_cells(const TriMesh& mesh, double radius)
{
    // Cells of 8 influence radii: a sponge of the noisy 1M thin plate (genus 7,355 over 8 m²,
    // radii 0.013) has about 18 handles a cell; a smooth sheet's cell, its integral of Gaussian
    // curvature, under 2π on a sphere of 4 cells' radius.
    const double cell = 8.0 * radius;
    NoiseScaleRegion region;
    region.size = cell;
    if (!(cell > 0.0) || mesh.face_count() == 0)
        return region;
    const std::size_t n = mesh.vertex_count();
    // Boundary vertices (an edge of one triangle) have no angle defect of their own.
    const std::vector<char> boundary = edge_graph(mesh).on_boundary;
    std::vector<double> defect(n, 2.0 * std::numbers::pi);
    const auto& positions = mesh.vertices.positions;
    for (const Triangle& t : mesh.triangles)
        for (int c = 0; c < 3; ++c)
        {
            const Vec3d p = positions[t[c]].cast<double>();
            const Vec3d u = positions[t[(c + 1) % 3]].cast<double>() - p;
            const Vec3d v = positions[t[(c + 2) % 3]].cast<double>() - p;
            const double angle = std::atan2(u.cross(v).norm(), u.dot(v));
            if (std::isfinite(angle))
                defect[t[c]] -= angle;
        }
    // Per cell: the sum of its interior vertices' defects.
    std::vector<std::pair<std::array<std::int32_t, 3>, double>> sums;
    sums.reserve(n);
    for (std::size_t v = 0; v < n; ++v)
    {
        if (boundary[v] != 0)
            continue;
        if (const auto key = region.cell_of(mesh.vertices.origin + positions[v].cast<double>()))
            sums.emplace_back(*key, defect[v]);
    }
    std::sort(sums.begin(), sums.end(),
              [](const auto& a, const auto& b) { return a.first < b.first; });
    constexpr double spongy_defect = -8.0 * std::numbers::pi; // two handles
    for (std::size_t s = 0; s < sums.size();)
    {
        std::size_t same = s;
        double total = 0.0;
        for (; same < sums.size() && sums[same].first == sums[s].first; ++same)
            total += sums[same].second;
        if (total <= spongy_defect)
            for (std::int32_t dx = -1; dx <= 1; ++dx)
                for (std::int32_t dy = -1; dy <= 1; ++dy)
                    for (std::int32_t dz = -1; dz <= 1; ++dz)
                        region.cells.push_back(
                            {sums[s].first[0] + dx, sums[s].first[1] + dy, sums[s].first[2] + dz});
        s = same;
    }
    std::sort(region.cells.begin(), region.cells.end());
    region.cells.erase(std::unique(region.cells.begin(), region.cells.end()), region.cells.end());
    return region;
}

std::optional<SpongeRefit> sponge_refit(const PointField& field, const TriMesh& mesh)
{
    if (!field.noisy() || field.options().fit != PlaneFit::Quadric)
        return std::nullopt;
    const std::size_t genus = sponge_genus(mesh);
    if (genus == 0)
        return std::nullopt;
    SpongeRefit refit{.genus = genus, .options = field.options()};
    refit.options.noise_scale = true;
    refit.options.noise_scale_region = spongy_cells(mesh, field.median_radius());
    return refit;
}

} // namespace pointform
