// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "self_intersection.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <unordered_map>

namespace pointform::test {
namespace {

// ---- Expansion arithmetic (Shewchuk 1997): a value is a sum of non-overlapping doubles in
// increasing magnitude; its sign is the sign of its last non-zero component.

using Expansion = std::vector<double>;

void two_sum(double a, double b, double& sum, double& error)
{
    sum = a + b;
    const double bv = sum - a;
    const double av = sum - bv;
    error = (a - av) + (b - bv);
}

void two_product(double a, double b, double& product, double& error)
{
    product = a * b;
    error = std::fma(a, b, -product);
}

/// e + b (Grow-Expansion), zero components dropped.
Expansion grow(const Expansion& e, double b)
{
    Expansion out;
    out.reserve(e.size() + 1);
    double q = b;
    for (const double component : e)
    {
        double sum = 0.0;
        double error = 0.0;
        two_sum(q, component, sum, error);
        if (error != 0.0)
        {
            out.push_back(error);
        }
        q = sum;
    }
    if (q != 0.0 || out.empty())
    {
        out.push_back(q);
    }
    return out;
}

Expansion add(const Expansion& e, const Expansion& f)
{
    Expansion out = e;
    for (const double component : f)
    {
        out = grow(out, component);
    }
    return out;
}

Expansion scale(const Expansion& e, double b)
{
    Expansion out{0.0};
    for (const double component : e)
    {
        double product = 0.0;
        double error = 0.0;
        two_product(component, b, product, error);
        out = grow(out, error);
        out = grow(out, product);
    }
    return out;
}

Expansion multiply(const Expansion& e, const Expansion& f)
{
    Expansion out{0.0};
    for (const double component : f)
    {
        out = add(out, scale(e, component));
    }
    return out;
}

Expansion difference(double a, double b)
{
    double sum = 0.0;
    double error = 0.0;
    two_sum(a, -b, sum, error);
    return error != 0.0 ? Expansion{error, sum} : Expansion{sum};
}

int sign(const Expansion& e)
{
    for (auto it = e.rbegin(); it != e.rend(); ++it)
    {
        if (*it != 0.0)
        {
            return *it > 0.0 ? 1 : -1;
        }
    }
    return 0;
}

Expansion negate(Expansion e)
{
    for (double& component : e)
    {
        component = -component;
    }
    return e;
}

int orient3d_slow(const double* a, const double* b, const double* c, const double* d)
{
    std::array<Expansion, 3> u;
    std::array<Expansion, 3> v;
    std::array<Expansion, 3> w;
    for (std::size_t i = 0; i < 3; ++i)
    {
        u[i] = difference(b[i], a[i]);
        v[i] = difference(c[i], a[i]);
        w[i] = difference(d[i], a[i]);
    }
    // u · (v × w)
    Expansion det{0.0};
    for (std::size_t i = 0; i < 3; ++i)
    {
        const std::size_t j = (i + 1) % 3;
        const std::size_t k = (i + 2) % 3;
        const Expansion cross = add(multiply(v[j], w[k]), negate(multiply(v[k], w[j])));
        det = add(det, multiply(u[i], cross));
    }
    return sign(det);
}

/// Sign of the 2D orientation of (a, b, c) projected by dropping axis `drop`, exactly.
int orient2d_exact(const double* a, const double* b, const double* c, int drop)
{
    const int x = drop == 0 ? 1 : 0;
    const int y = drop == 2 ? 1 : 2;
    const double det = (b[x] - a[x]) * (c[y] - a[y]) - (b[y] - a[y]) * (c[x] - a[x]);
    const double permanent =
        std::abs((b[x] - a[x]) * (c[y] - a[y])) + std::abs((b[y] - a[y]) * (c[x] - a[x]));
    if (std::abs(det) > 1e-14 * permanent)
    {
        return det > 0.0 ? 1 : -1;
    }
    const Expansion e = add(multiply(difference(b[x], a[x]), difference(c[y], a[y])),
                            negate(multiply(difference(b[y], a[y]), difference(c[x], a[x]))));
    return sign(e);
}

using Point = std::array<double, 3>;

struct Face
{
    std::array<std::uint32_t, 3> v;
    std::array<Point, 3> p;
    int drop = -1; ///< an axis whose dropping projects the face without collapsing it; -1 if none
};

/// Segment [a, b] and the closed triangle t: whether they share a point.
bool segment_meets_triangle(const Point& a, const Point& b, const Face& t)
{
    const Point& p = t.p[0];
    const Point& q = t.p[1];
    const Point& r = t.p[2];
    const int sa = orient3d_exact(p.data(), q.data(), r.data(), a.data());
    const int sb = orient3d_exact(p.data(), q.data(), r.data(), b.data());
    if (sa * sb > 0)
    {
        return false;
    }
    if (sa == 0 && sb == 0)
    {
        // In the triangle's plane: an endpoint inside, or the segment crosses an edge.
        const int d = t.drop;
        auto inside = [&](const Point& x) {
            const int s0 = orient2d_exact(p.data(), q.data(), x.data(), d);
            const int s1 = orient2d_exact(q.data(), r.data(), x.data(), d);
            const int s2 = orient2d_exact(r.data(), p.data(), x.data(), d);
            return (s0 >= 0 && s1 >= 0 && s2 >= 0) || (s0 <= 0 && s1 <= 0 && s2 <= 0);
        };
        if (inside(a) || inside(b))
        {
            return true;
        }
        for (int e = 0; e < 3; ++e)
        {
            const Point& c = t.p[static_cast<std::size_t>(e)];
            const Point& f = t.p[static_cast<std::size_t>((e + 1) % 3)];
            const int o1 = orient2d_exact(a.data(), b.data(), c.data(), d);
            const int o2 = orient2d_exact(a.data(), b.data(), f.data(), d);
            const int o3 = orient2d_exact(c.data(), f.data(), a.data(), d);
            const int o4 = orient2d_exact(c.data(), f.data(), b.data(), d);
            if (o1 * o2 <= 0 && o3 * o4 <= 0 && !(o1 == 0 && o2 == 0))
            {
                return true;
            }
            // Collinear: overlap of the projections is enough (the points are in one plane).
            if (o1 == 0 && o2 == 0)
            {
                const int x = d == 0 ? 1 : 0;
                const int y = d == 2 ? 1 : 2;
                for (const int axis : {x, y})
                {
                    const auto ax = static_cast<std::size_t>(axis);
                    const double lo1 = std::min(a[ax], b[ax]);
                    const double hi1 = std::max(a[ax], b[ax]);
                    const double lo2 = std::min(c[ax], f[ax]);
                    const double hi2 = std::max(c[ax], f[ax]);
                    if (hi1 < lo2 || hi2 < lo1)
                    {
                        goto next_edge;
                    }
                }
                return true;
            }
        next_edge:;
        }
        return false;
    }
    // The segment reaches the plane at one point; it is in the triangle iff the line through
    // a and b passes through the closed triangle.
    const int s0 = orient3d_exact(a.data(), b.data(), p.data(), q.data());
    const int s1 = orient3d_exact(a.data(), b.data(), q.data(), r.data());
    const int s2 = orient3d_exact(a.data(), b.data(), r.data(), p.data());
    return (s0 >= 0 && s1 >= 0 && s2 >= 0) || (s0 <= 0 && s1 <= 0 && s2 <= 0);
}

/// Whether the point x (≠ apex) is in the closed wedge of t at its vertex `apex`, x being in
/// t's plane.
bool in_wedge(const Face& t, int apex, const Point& x)
{
    const Point& s = t.p[static_cast<std::size_t>(apex)];
    const Point& b1 = t.p[static_cast<std::size_t>((apex + 1) % 3)];
    const Point& b2 = t.p[static_cast<std::size_t>((apex + 2) % 3)];
    const int orientation = orient2d_exact(s.data(), b1.data(), b2.data(), t.drop);
    const int beta = orient2d_exact(s.data(), b1.data(), x.data(), t.drop) * orientation;
    const int alpha = orient2d_exact(s.data(), x.data(), b2.data(), t.drop) * orientation;
    return alpha >= 0 && beta >= 0;
}

bool in_plane(const Face& t, const Point& x)
{
    return orient3d_exact(t.p[0].data(), t.p[1].data(), t.p[2].data(), x.data()) == 0;
}

bool faces_intersect(const Face& f, const Face& g)
{
    int shared = 0;
    std::array<int, 3> in_g{-1, -1, -1}; // for each corner of f, its corner in g
    for (int i = 0; i < 3; ++i)
    {
        for (int j = 0; j < 3; ++j)
        {
            if (f.v[static_cast<std::size_t>(i)] == g.v[static_cast<std::size_t>(j)])
            {
                in_g[static_cast<std::size_t>(i)] = j;
                ++shared;
            }
        }
    }
    if (shared == 3)
    {
        return true; // the same triangle twice
    }
    if (shared == 0)
    {
        for (int e = 0; e < 3; ++e)
        {
            if (segment_meets_triangle(f.p[static_cast<std::size_t>(e)],
                                       f.p[static_cast<std::size_t>((e + 1) % 3)], g) ||
                segment_meets_triangle(g.p[static_cast<std::size_t>(e)],
                                       g.p[static_cast<std::size_t>((e + 1) % 3)], f))
            {
                return true;
            }
        }
        return false;
    }
    if (shared == 2)
    {
        // Non-coplanar faces on a common edge meet only along it; coplanar ones overlap when
        // their third corners lie on the same side of it.
        int a = 0;
        while (in_g[static_cast<std::size_t>(a)] >= 0)
        {
            ++a;
        }
        int b = 0;
        while (b == in_g[0] || b == in_g[1] || b == in_g[2])
        {
            ++b;
        }
        const Point& x = f.p[static_cast<std::size_t>(a)];
        const Point& y = g.p[static_cast<std::size_t>(b)];
        if (!in_plane(g, x))
        {
            return false;
        }
        const Point& u = f.p[static_cast<std::size_t>((a + 1) % 3)];
        const Point& v = f.p[static_cast<std::size_t>((a + 2) % 3)];
        return orient2d_exact(u.data(), v.data(), x.data(), g.drop) ==
               orient2d_exact(u.data(), v.data(), y.data(), g.drop);
    }
    // One shared corner s: they meet elsewhere iff the opposite edge of one meets the other, or
    // an edge from s lies in the other's plane inside its wedge at s.
    int sf = 0;
    while (in_g[static_cast<std::size_t>(sf)] < 0)
    {
        ++sf;
    }
    const int sg = in_g[static_cast<std::size_t>(sf)];
    auto one_side = [](const Face& t, int st, const Face& other, int so) {
        const Point& a1 = t.p[static_cast<std::size_t>((st + 1) % 3)];
        const Point& a2 = t.p[static_cast<std::size_t>((st + 2) % 3)];
        if (segment_meets_triangle(a1, a2, other))
        {
            return true;
        }
        for (const Point* a : {&a1, &a2})
        {
            if (in_plane(other, *a) && in_wedge(other, so, *a))
            {
                return true;
            }
        }
        return false;
    };
    return one_side(f, sf, g, sg) || one_side(g, sg, f, sf);
}

} // namespace

int orient3d_exact(const double* a, const double* b, const double* c, const double* d)
{
    const double bx = b[0] - a[0], by = b[1] - a[1], bz = b[2] - a[2];
    const double cx = c[0] - a[0], cy = c[1] - a[1], cz = c[2] - a[2];
    const double dx = d[0] - a[0], dy = d[1] - a[1], dz = d[2] - a[2];
    const double det =
        bx * (cy * dz - cz * dy) + by * (cz * dx - cx * dz) + bz * (cx * dy - cy * dx);
    const double permanent = std::abs(bx) * (std::abs(cy * dz) + std::abs(cz * dy)) +
                             std::abs(by) * (std::abs(cz * dx) + std::abs(cx * dz)) +
                             std::abs(bz) * (std::abs(cx * dy) + std::abs(cy * dx));
    // Shewchuk's bound for this evaluation is (7 + 56ε)ε·permanent, about 7.8e-16 of it.
    if (std::abs(det) > 1e-14 * permanent)
    {
        return det > 0.0 ? 1 : -1;
    }
    return orient3d_slow(a, b, c, d);
}

SelfIntersections find_self_intersections(const TriMesh& mesh)
{
    SelfIntersections out;
    const std::size_t n = mesh.face_count();
    std::vector<Face> faces(n);
    std::vector<std::array<double, 6>> box(n);
    double extent = 0.0;
    // Vertices at one position are one point (marching cubes splits a pinched vertex into
    // copies, one per sheet): faces share a corner when they share its position.
    std::vector<std::uint32_t> canonical(mesh.vertex_count());
    {
        std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> by_hash;
        for (std::uint32_t v = 0; v < canonical.size(); ++v)
        {
            const Vec3f& q = mesh.vertices.positions[v];
            const std::uint64_t h = std::hash<float>{}(q.x()) * 73856093ULL ^
                                    std::hash<float>{}(q.y()) * 19349663ULL ^
                                    std::hash<float>{}(q.z()) * 83492791ULL;
            auto& list = by_hash[h];
            canonical[v] = v;
            for (const std::uint32_t w : list)
            {
                if (mesh.vertices.positions[w] == q)
                {
                    canonical[v] = w;
                    break;
                }
            }
            if (canonical[v] == v)
            {
                list.push_back(v);
            }
        }
    }
    for (std::size_t i = 0; i < n; ++i)
    {
        Face& face = faces[i];
        face.v = mesh.triangles[i];
        for (std::uint32_t& v : face.v)
        {
            v = canonical[v];
        }
        for (std::size_t c = 0; c < 3; ++c)
        {
            const Vec3f& q = mesh.vertices.positions[face.v[c]];
            face.p[c] = {static_cast<double>(q.x()), static_cast<double>(q.y()),
                         static_cast<double>(q.z())};
        }
        for (int drop = 0; drop < 3 && face.drop < 0; ++drop)
        {
            if (orient2d_exact(face.p[0].data(), face.p[1].data(), face.p[2].data(), drop) != 0)
            {
                face.drop = drop;
            }
        }
        if (face.drop < 0)
        {
            out.degenerate.push_back(static_cast<std::uint32_t>(i));
        }
        for (std::size_t a = 0; a < 3; ++a)
        {
            box[i][a] = std::min({face.p[0][a], face.p[1][a], face.p[2][a]});
            box[i][a + 3] = std::max({face.p[0][a], face.p[1][a], face.p[2][a]});
            extent = std::max(extent, box[i][a + 3] - box[i][a]);
        }
    }
    if (n < 2)
    {
        return out;
    }
    // Bin by the grid cell of each box's corners: cell side = the largest face extent, so a
    // box spans at most 2 cells per axis.
    const double cell = extent > 0.0 ? extent : 1.0;
    auto key = [&](double x, double y, double z) {
        const auto ix = static_cast<std::int64_t>(std::floor(x / cell)) & 0x1FFFFF;
        const auto iy = static_cast<std::int64_t>(std::floor(y / cell)) & 0x1FFFFF;
        const auto iz = static_cast<std::int64_t>(std::floor(z / cell)) & 0x1FFFFF;
        return static_cast<std::uint64_t>(ix) | static_cast<std::uint64_t>(iy) << 21 |
               static_cast<std::uint64_t>(iz) << 42;
    };
    std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> bins;
    for (std::size_t i = 0; i < n; ++i)
    {
        const auto& b = box[i];
        for (const double x : {b[0], b[3]})
        {
            for (const double y : {b[1], b[4]})
            {
                for (const double z : {b[2], b[5]})
                {
                    auto& list = bins[key(x, y, z)];
                    if (list.empty() || list.back() != i)
                    {
                        list.push_back(static_cast<std::uint32_t>(i));
                    }
                }
            }
        }
    }
    for (auto& [k, list] : bins)
    {
        std::sort(list.begin(), list.end());
        list.erase(std::unique(list.begin(), list.end()), list.end());
        for (std::size_t s = 0; s < list.size(); ++s)
        {
            const std::uint32_t i = list[s];
            if (faces[i].drop < 0)
            {
                continue;
            }
            for (std::size_t t = s + 1; t < list.size(); ++t)
            {
                const std::uint32_t j = list[t];
                if (faces[j].drop < 0)
                {
                    continue;
                }
                const auto& a = box[i];
                const auto& b = box[j];
                if (a[0] > b[3] || b[0] > a[3] || a[1] > b[4] || b[1] > a[4] || a[2] > b[5] ||
                    b[2] > a[5])
                {
                    continue;
                }
                // Test each pair once: in the bin of the low corner of the boxes' overlap.
                if (key(std::max(a[0], b[0]), std::max(a[1], b[1]), std::max(a[2], b[2])) != k)
                {
                    continue;
                }
                ++out.candidate_pairs;
                if (faces_intersect(faces[i], faces[j]))
                {
                    out.pairs.emplace_back(i, j);
                }
            }
        }
    }
    std::sort(out.pairs.begin(), out.pairs.end());
    return out;
}

} // namespace pointform::test
