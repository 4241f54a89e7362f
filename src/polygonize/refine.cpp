// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/polygonize/refine.h"

#include "pointform/core/error.h"
#include "pointform/core/parallel.h"
#include "pointform/geometry/level_topology.h"
#include "pointform/metrics/quality.h"
#include "pointform/polygonize/projection.h"
#include "pointform/spatial/kd_tree.h"
#include "pointform/spatial/spatial_sort.h"
#include "pointform/spatial/triangle_bvh.h"

#include "crease_fill.h"
#include "relax.h"
#include "thin_plate.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <string>
#include <tuple>
#include <utility>

namespace pointform {

namespace {

constexpr std::uint32_t none = std::numeric_limits<std::uint32_t>::max();
constexpr std::size_t vertex_block = 512;

using Level = LevelTopology;
constexpr auto next_of = LevelTopology::next_of;
constexpr auto prev_of = LevelTopology::prev_of;

/// u × v of a triangle: twice its area times its unit normal.
Vec3d area_normal(const Vec3d& a, const Vec3d& b, const Vec3d& c)
{
    return (b - a).cross(c - b);
}

enum class State : std::uint8_t
{
    Projected,   ///< on the surface (AW_FEN, VEN or after relaxation)
    Unprojected, ///< kept at the prediction: no crossing along AW_FEN
    Reverted,    ///< kept at the prediction (or midpoint): a fold VEN did not remove
};

/// What a relaxation round did to one new vertex.
enum class Move : std::uint8_t
{
    None,       ///< not relaxed (not on the surface)
    Made,       ///< moved and re-projected
    NoCrossing, ///< the re-projection found no crossing: not moved
    Undone,     ///< moved, then put back because it folded a face
};

/// The field's unit normals at an edge's two ends whose cosine is below this say that the edge
/// crosses a crease (cos 30°).
constexpr double crease_cosine = 0.8660254037844386;
/// A crease point (crease_point()) is taken when |f| there is at most this share of its distance
/// from the edge's midpoint. At a crease the tangent planes meet on the surface (|f| ≈ 0); over a
/// smooth bend they meet above it, at about half that distance (an arc of a circle: 1 / (1 +
/// cos φ) of it), and the projection along the edge normal is the better point.
constexpr double crease_residual = 0.1;

/// A crease point is taken only where it splits its edge no more unevenly than 1 : 2 (measured
/// along the edge). Where the crease passes near one end, the vertex there would make a child
/// edge, and triangles, a few times shorter than their neighbours; that vertex is projected along
/// AW_FEN instead, and a later level's edges cross the crease nearer their middles. Measured on a
/// block turned against the grid (an exact field, level 3, crease_truth_test): splits down to
/// 1 : 3 left 1.5% of the triangles with an angle under 20°, any split 13.6%; 1 : 2 left 0.5%.
constexpr double crease_split = 1.0 / 3.0;

/// The point of the crease that the edge ab crosses: the point nearest the edge's midpoint m
/// where the tangent planes at a and b (unit normals na and nb) meet, m + λ·na + μ·nb. None when
/// the normals are (nearly) parallel: the two sides of a thin part have no crease between them.
std::optional<Vec3d> crease_point(const Vec3d& a, const Vec3d& na, const Vec3d& b, const Vec3d& nb)
{
    const Vec3d m = 0.5 * (a + b);
    const double c = na.dot(nb);
    const double det = 1.0 - c * c;
    if (!(det > 1e-3))
        return std::nullopt;
    const double ra = na.dot(a - m);
    const double rb = nb.dot(b - m);
    const double lambda = (ra - c * rb) / det;
    const double mu = (rb - c * ra) / det;
    const Vec3d p = m + lambda * na + mu * nb;
    if (!p.allFinite())
        return std::nullopt;
    return p;
}

/// The field's orientation at one point: its gradient where it is defined and finite, else none.
std::optional<Vec3d> field_orientation(const Field& field, const Vec3d& point)
{
    const FieldSample s = field.evaluate(point);
    if (!s.defined || !std::isfinite(s.value) || !s.gradient.allFinite() ||
        !(s.gradient.squaredNorm() > 0.0))
        return std::nullopt;
    return s.gradient;
}

/// The four children of face f of `level`: (a, ab, ca), (ab, b, bc), (ca, bc, c), (ab, bc, ca).
std::array<Triangle, 4> child_triangles(const Level& level, std::size_t f)
{
    const auto [a, b, c] = level.faces[f];
    const std::uint32_t ab = level.edge_vertex[3 * f];
    const std::uint32_t bc = level.edge_vertex[3 * f + 1];
    const std::uint32_t ca = level.edge_vertex[3 * f + 2];
    return {Triangle{a, ab, ca}, Triangle{ab, b, bc}, Triangle{ca, bc, c}, Triangle{ab, bc, ca}};
}

/// Marks, per child face of level i + 1 (4f + c), whether it is folded: its normal is against
/// its parent face's (cosine <= fold_cosine) and against the field's gradient at its centroid as
/// well (or it is degenerate, or the field is undefined there). A parent face that straddles a
/// crease (its corners on the two sides, its normal between theirs) has children that lie on one
/// side each, turned by up to the crease's angle from the parent; those agree with the field and
/// are no folds. A child turned inside out disagrees with both.
void find_folds(const Level& level, std::span<const Vec3d> x, std::span<const Vec3d> parent_normal,
                double fold_cosine, const Field& field, const Vec3d& origin,
                std::vector<char>& folded)
{
    folded.assign(4 * level.faces.size(), 0);
    parallel_blocks(level.faces.size(), 1024, [&](std::size_t begin, std::size_t end) {
        for (std::size_t f = begin; f < end; ++f)
        {
            const Vec3d& n = parent_normal[f];
            const double n_norm = n.norm();
            if (!(n_norm > 0.0))
                continue; // a degenerate parent gives no reference
            const std::array<Triangle, 4> children = child_triangles(level, f);
            for (std::size_t k = 0; k < 4; ++k)
            {
                const Triangle& t = children[k];
                const Vec3d m = area_normal(x[t[0]], x[t[1]], x[t[2]]);
                const double m_norm = m.norm();
                bool bad = !(m_norm > 0.0) || m.dot(n) <= fold_cosine * m_norm * n_norm;
                if (bad && m_norm > 0.0)
                {
                    const Vec3d centroid = origin + (x[t[0]] + x[t[1]] + x[t[2]]) / 3.0;
                    if (const std::optional<Vec3d> g = field_orientation(field, centroid))
                        bad = m.dot(*g) <= fold_cosine * m_norm * g->norm();
                }
                folded[4 * f + k] = bad ? 1 : 0;
            }
        }
    });
}

/// The new vertices (local indices) of the folded child faces, ascending, without repeats.
std::vector<std::uint32_t> vertices_of_folds(const Level& level, const std::vector<char>& folded)
{
    std::vector<std::uint32_t> out;
    for (std::size_t c = 0; c < folded.size(); ++c)
    {
        if (folded[c] == 0)
            continue;
        const std::size_t f = c / 4;
        const std::uint32_t ab = level.edge_vertex[3 * f] - level.first_new;
        const std::uint32_t bc = level.edge_vertex[3 * f + 1] - level.first_new;
        const std::uint32_t ca = level.edge_vertex[3 * f + 2] - level.first_new;
        switch (c % 4)
        {
            case 0:
                out.insert(out.end(), {ab, ca});
                break;
            case 1:
                out.insert(out.end(), {ab, bc});
                break;
            case 2:
                out.insert(out.end(), {ca, bc});
                break;
            default:
                out.insert(out.end(), {ab, bc, ca});
                break;
        }
    }
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
}

std::size_t count_folds(const std::vector<char>& folded)
{
    return static_cast<std::size_t>(std::count(folded.begin(), folded.end(), char{1}));
}

void check_options(const RefineOptions& options)
{
    if (options.denoise_rounds > max_denoise_rounds)
        throw InvalidInput("refine: denoise_rounds must be at most " +
                           std::to_string(max_denoise_rounds) + ", got " +
                           std::to_string(options.denoise_rounds));
    if (!(options.search_scale > 0.0) || !std::isfinite(options.search_scale))
        throw InvalidInput("refine: search_scale must be positive and finite");
    if (!std::isfinite(options.fold_cosine) || options.fold_cosine >= 1.0 ||
        options.fold_cosine < -1.0)
        throw InvalidInput("refine: fold_cosine must lie in [-1, 1)");
    if (options.relax_iterations < 0)
        throw InvalidInput("refine: relax_iterations must not be negative");
    if (options.thin_relax_iterations < 0)
        throw InvalidInput("refine: thin_relax_iterations must not be negative");
    if (!(options.sampling_density >= 0.0) || !std::isfinite(options.sampling_density))
        throw InvalidInput("refine: sampling_density must be 0 (estimate) or positive");
    if (!(options.min_improvement >= 0.0 && options.min_improvement < 1.0))
        throw InvalidInput("refine: min_improvement must lie in [0, 1)");
    if (!(options.detail_factor > 0.0 && options.detail_factor <= 1.0))
        throw InvalidInput("refine: detail_factor must lie in (0, 1]");
    if (!(options.noise_decay > 0.0 && options.noise_decay < 1.0))
        throw InvalidInput("refine: noise_decay must lie in (0, 1)");
    if (!(options.tail_factor >= 1.0) || !std::isfinite(options.tail_factor))
        throw InvalidInput("refine: tail_factor must be finite and at least 1");
}

/// Share of the distances, the smallest first, that the robust distance averages.
constexpr double robust_share = 0.95;

struct RobustStats
{
    double robust = 0.0; ///< mean of the smallest robust_share of the values
    double p90 = 0.0;
};

/// The robust statistics of `values` (reordered: nth_element).
RobustStats robust_stats(std::vector<double>& values)
{
    RobustStats out;
    if (values.empty())
        return out;
    const std::size_t n = values.size();
    const std::size_t kept = std::max<std::size_t>(
        1, static_cast<std::size_t>(std::ceil(robust_share * static_cast<double>(n))));
    if (kept < n)
        std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(kept),
                         values.end());
    double sum = 0.0;
    for (std::size_t i = 0; i < kept; ++i)
        sum += values[i];
    out.robust = sum / static_cast<double>(kept);
    const auto p90 = std::min(n - 1, static_cast<std::size_t>(0.9 * static_cast<double>(n)));
    std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(p90),
                     values.begin() + static_cast<std::ptrdiff_t>(std::max(kept, p90 + 1)));
    out.p90 = values[p90];
    return out;
}

struct Distances
{
    double hausdorff = 0.0;
    double mean = 0.0;
    double robust = 0.0;
    double p90 = 0.0;
    /// Per sample, its closest face (an index into the faces measured), which bounds the search
    /// of the next measurement (NearestHint).
    std::vector<std::uint32_t> nearest;
};

/// The closest faces of an earlier measurement (Distances::nearest), on the same faces or on
/// the level below, whose face f has the children 4f ... 4f + 3 (child_faces()): the distance
/// to the nearest of those bounds each sample's search, which then visits little more than the
/// faces that close (a fresh search takes the previous sample's closest point as its bound).
struct NearestHint
{
    std::span<const std::uint32_t> faces;
    bool children = false;
};

Distances distances_from(const PointCloud& samples, const MultiresMesh& mesh,
                         std::span<const Triangle> faces, std::size_t level,
                         const ProgressCallback& progress, const NearestHint& hint = {},
                         std::span<const std::uint32_t> order = {})
{
    TriMesh surface;
    surface.vertices.origin = mesh.origin();
    const std::size_t n = mesh.vertex_count(level);
    surface.vertices.positions.resize(n);
    for (std::size_t v = 0; v < n; ++v)
        surface.vertices.positions[v] = mesh.positions()[v].cast<float>();
    surface.triangles.assign(faces.begin(), faces.end());
    // Above the base mesh the faces are the level below's children in order (child_faces()):
    // the BVH keeps each face's four children together and sorts a quarter as many boxes.
    const TriangleBvh bvh(surface, {.group_size = level > 0 && faces.size() % 4 == 0 ? 4U : 1U});
    std::vector<double> bounds;
    if (hint.faces.size() == samples.size())
    {
        // Each bound is a distance to a face of this mesh, worked out as the BVH does (its
        // corners in double from the float positions, relative to the origin), so it is never
        // below the sample's distance.
        bounds.assign(samples.size(), std::numeric_limits<double>::infinity());
        const std::size_t per_hint = hint.children ? 4 : 1;
        const auto& x = surface.vertices.positions;
        // In the samples' spatial order where the caller has it: neighbouring samples then read
        // the same faces and corners while they are in cache.
        const bool ordered = order.size() == samples.size();
        parallel_blocks(samples.size(), 4096, [&](std::size_t begin, std::size_t end) {
            for (std::size_t k = begin; k < end; ++k)
            {
                const std::size_t i = ordered ? order[k] : k;
                const std::uint32_t f = hint.faces[i];
                if (f == none || per_hint * f + per_hint > faces.size())
                    continue;
                const Vec3d p = samples.world(i) - surface.vertices.origin;
                double best = std::numeric_limits<double>::infinity();
                for (std::size_t c = per_hint * f; c < per_hint * f + per_hint; ++c)
                {
                    const Vec3d a = x[faces[c][0]].cast<double>();
                    const Vec3d b = x[faces[c][1]].cast<double>();
                    const Vec3d d = x[faces[c][2]].cast<double>();
                    const Vec3d w = closest_point_barycentric(p, a, b, d);
                    best = std::min(best, (p - (w[0] * a + w[1] * b + w[2] * d)).norm());
                }
                bounds[i] = best;
            }
        });
    }
    NearestTriangles nearest =
        nearest_triangles(bvh, samples, bounds, {.progress = progress, .order = order});
    std::vector<double>& d = nearest.distances;
    Distances out;
    double sum = 0.0;
    for (const double value : d)
    {
        out.hausdorff = std::max(out.hausdorff, value);
        sum += value;
    }
    out.mean = d.empty() ? 0.0 : sum / static_cast<double>(d.size());
    const RobustStats robust = robust_stats(d);
    out.robust = robust.robust;
    out.p90 = robust.p90;
    out.nearest = std::move(nearest.faces);
    return out;
}

/// Faces of level i + 1 (the children, in order).
std::vector<Triangle> child_faces(const Level& level)
{
    std::vector<Triangle> out(4 * level.faces.size());
    for (std::size_t f = 0; f < level.faces.size(); ++f)
    {
        const std::array<Triangle, 4> children = child_triangles(level, f);
        std::copy(children.begin(), children.end(),
                  out.begin() + static_cast<std::ptrdiff_t>(4 * f));
    }
    return out;
}

/// A triangle is thin when one of its angles is below this.
constexpr double thin_degrees = 20.0;

/// Per new vertex of `level` (0 ... added - 1): 1 where it is a corner of a child face with an
/// angle under thin_degrees (triangle_min_angle(), as the quality report measures), at
/// positions x.
std::vector<char> thin_vertices(const Level& level, std::span<const Vec3d> x, std::size_t added)
{
    const double bound = thin_degrees * std::numbers::pi / 180.0;
    const auto thin_child = [&x, bound](const Triangle& t) {
        return triangle_min_angle(x[t[0]], x[t[1]], x[t[2]]) < bound;
    };
    // Per parent face, a bit per thin child (in parallel), then their new vertices marked.
    std::vector<std::uint8_t> thin_children(level.faces.size(), 0);
    parallel_blocks(level.faces.size(), 4096, [&](std::size_t begin, std::size_t end) {
        for (std::size_t f = begin; f < end; ++f)
        {
            const std::array<Triangle, 4> children = child_triangles(level, f);
            std::uint8_t bits = 0;
            for (std::size_t k = 0; k < 4; ++k)
                bits |= thin_child(children[k]) ? std::uint8_t(1U << k) : std::uint8_t{0};
            thin_children[f] = bits;
        }
    });
    std::vector<char> thin(added, 0);
    for (std::size_t f = 0; f < level.faces.size(); ++f)
    {
        if (thin_children[f] == 0)
            continue;
        const std::array<Triangle, 4> children = child_triangles(level, f);
        for (std::size_t k = 0; k < 4; ++k)
            if ((thin_children[f] >> k) & 1U)
                for (const std::uint32_t v : children[k])
                    if (v >= level.first_new && v - level.first_new < added)
                        thin[v - level.first_new] = 1;
    }
    return thin;
}

/// The refinement proper, on a hierarchy whose finest level was just split; returns the faces
/// of the new level.
std::vector<Triangle> refine_split_level(MultiresMesh& mesh, MultiresMesh::SplitResult split,
                                         const Field& field, const RefineOptions& options,
                                         RefineLevelStats& stats)
{
    const Level level = level_topology(mesh, std::move(split));
    const std::span<Vec3d> new_positions = mesh.finest_new_positions();
    const std::span<const Vec3d> x = mesh.positions(); // all vertices; new ones change below
    const std::size_t added = new_positions.size();
    const Vec3d& origin = mesh.origin();
    const std::size_t old_count = level.first_new;

    // Normals of level i: per face (area-weighted), per vertex (sum over its faces, serial so
    // the sums do not depend on the thread count).
    std::vector<Vec3d> face_normal(level.faces.size());
    parallel_blocks(level.faces.size(), 4096, [&](std::size_t begin, std::size_t end) {
        for (std::size_t f = begin; f < end; ++f)
        {
            const auto [a, b, c] = level.faces[f];
            face_normal[f] = area_normal(x[a], x[b], x[c]);
        }
    });
    std::vector<Vec3d> vertex_normal(old_count, Vec3d::Zero());
    for (std::size_t f = 0; f < level.faces.size(); ++f)
        for (const std::uint32_t v : level.faces[f])
            vertex_normal[v] += face_normal[f];

    // Per new vertex: prediction, AW_FEN, VEN and search reach.
    std::vector<Vec3d> prediction(added);
    std::vector<Vec3d> aw_fen(added);
    std::vector<Vec3d> ven(added);
    std::vector<double> reach(added);
    {
        ProgressReporter reporter(options.progress, "refine: predict");
        parallel_blocks(
            added, vertex_block,
            [&](std::size_t begin, std::size_t end) {
                std::vector<std::uint32_t> ring;
                std::vector<StencilTerm> stencil;
                for (std::size_t j = begin; j < end; ++j)
                {
                    const auto [h1, h2] = level.halfedges[j];
                    const std::uint32_t a = level.from(h1);
                    const std::uint32_t b = level.to(h1);
                    prediction_stencil(level, j, options.predictor, stencil, ring);
                    prediction[j] = apply_stencil(stencil, x);
                    Vec3d n = face_normal[h1 / 3];
                    if (h2 != none)
                        n += face_normal[h2 / 3];
                    aw_fen[j] = n;
                    const Vec3d na = vertex_normal[a].normalized();
                    const Vec3d nb = vertex_normal[b].normalized();
                    ven[j] = na + nb;
                    reach[j] = options.search_scale * (x[a] - x[b]).norm();
                }
            },
            &reporter);
        reporter.finish();
    }

    // The field's unit normals at the old vertices (zero where it is undefined).
    std::vector<Vec3d> field_normal(old_count, Vec3d::Zero());
    parallel_blocks(old_count, vertex_block, [&](std::size_t begin, std::size_t end) {
        for (std::size_t v = begin; v < end; ++v)
            if (const std::optional<Vec3d> g = field_orientation(field, origin + x[v]))
                field_normal[v] = g->normalized();
    });

    // Project: an edge whose ends' normals differ by more than 30° crosses a crease, and its
    // vertex goes to the crease itself (crease_point()) where the tangent planes meet on the
    // surface and the point splits the edge evenly enough (crease_split); every other vertex
    // along AW_FEN. A vertex on the crease splits the crossing into
    // two child edges that lie on the two faces; a projection along AW_FEN lands on one face
    // beside the crease, and the child edge to the other face cuts the crease's corner again,
    // at every level.
    std::vector<State> state(added, State::Unprojected);
    std::vector<char> on_crease(added, 0);
    {
        ProgressReporter reporter(options.progress, "refine: project");
        parallel_blocks(
            added, vertex_block,
            [&](std::size_t begin, std::size_t end) {
                for (std::size_t j = begin; j < end; ++j)
                {
                    const auto [h1, h2] = level.halfedges[j];
                    const std::uint32_t a = level.from(h1);
                    const std::uint32_t b = level.to(h1);
                    const Vec3d& na = field_normal[a];
                    const Vec3d& nb = field_normal[b];
                    std::optional<Vec3d> hit;
                    if (na != Vec3d::Zero() && nb != Vec3d::Zero() && na.dot(nb) < crease_cosine)
                    {
                        const Vec3d pa = origin + x[a];
                        const Vec3d pb = origin + x[b];
                        const Vec3d midpoint = 0.5 * (pa + pb);
                        const std::optional<Vec3d> corner = crease_point(pa, na, pb, nb);
                        const double u =
                            corner ? (*corner - pa).dot(pb - pa) / (pb - pa).squaredNorm() : 0.0;
                        if (corner && u >= crease_split && u <= 1.0 - crease_split &&
                            (*corner - midpoint).norm() <= reach[j])
                        {
                            const FieldSample s = field.evaluate(*corner);
                            if (s.defined &&
                                std::abs(s.value) <= crease_residual * (*corner - midpoint).norm())
                                hit = newton_to_zero(field, *corner, reach[j]);
                        }
                        on_crease[j] = hit ? 1 : 0;
                    }
                    if (!hit)
                    {
                        // Where the field is undefined at both ends of the edge and at the
                        // prediction, the vertex lies over a hole (the base mesh's patch),
                        // which the finest level's fairing shapes: it stays predicted. A search
                        // from there finds no crossing 97 times in 100 (simulated fandisk scans)
                        // and costs 40-50 field evaluations each, far from the samples.
                        const Vec3d start = origin + prediction[j];
                        const FieldSample at = field.evaluate(start);
                        if (at.defined || na != Vec3d::Zero() || nb != Vec3d::Zero())
                            hit = project_to_zero(field, at, start, aw_fen[j], reach[j]);
                    }
                    new_positions[j] = hit ? Vec3d(*hit - origin) : prediction[j];
                    state[j] = hit ? State::Projected : State::Unprojected;
                }
            },
            &reporter);
        reporter.finish();
    }

    // Folds: VEN for the vertices of folded child faces, then fall back to the prediction, then
    // to the midpoint.
    std::vector<char> folded;
    // The folded child faces of the positions as they are now (x sees every move).
    const auto refold = [&] {
        find_folds(level, x, face_normal, options.fold_cosine, field, origin, folded);
    };
    refold();
    const std::vector<std::uint32_t> marked = vertices_of_folds(level, folded);
    stats.fold_vertices = marked.size();
    std::vector<char> used_ven(added, 0);
    if (!marked.empty())
    {
        parallel_blocks(marked.size(), 64, [&](std::size_t begin, std::size_t end) {
            for (std::size_t m = begin; m < end; ++m)
            {
                const std::uint32_t j = marked[m];
                on_crease[j] = 0;
                const std::optional<Vec3d> hit =
                    project_to_zero(field, origin + prediction[j], ven[j], reach[j]);
                new_positions[j] = hit ? Vec3d(*hit - origin) : prediction[j];
                state[j] = hit ? State::Projected : State::Reverted;
                used_ven[j] = hit ? 1 : 0;
            }
        });
        // Still folded: the nearest point of f = 0 by Newton steps from the prediction (a
        // midpoint that cuts a crease's corner lies inside; put back there, it stays a spike).
        std::vector<std::optional<Vec3d>> nearest(added);
        {
            refold();
            const std::vector<std::uint32_t> still = vertices_of_folds(level, folded);
            parallel_blocks(still.size(), 64, [&](std::size_t begin, std::size_t end) {
                for (std::size_t m = begin; m < end; ++m)
                {
                    const std::uint32_t j = still[m];
                    if (const auto hit = newton_to_zero(field, origin + prediction[j], reach[j]))
                        nearest[j] = *hit - origin;
                }
            });
        }
        for (int fallback = 0; fallback < 3; ++fallback)
        {
            refold();
            std::vector<std::uint32_t> still = vertices_of_folds(level, folded);
            // Repeat: putting one vertex back can fold a neighbour's face.
            while (!still.empty())
            {
                bool changed = false;
                for (const std::uint32_t j : still)
                {
                    const auto [h1, h2] = level.halfedges[j];
                    const Vec3d midpoint = 0.5 * (x[level.from(h1)] + x[level.to(h1)]);
                    if (fallback == 0 && !nearest[j])
                        continue;
                    if (fallback == 0)
                    {
                        if (new_positions[j] != *nearest[j])
                        {
                            new_positions[j] = *nearest[j];
                            state[j] = State::Projected;
                            used_ven[j] = 0;
                            changed = true;
                        }
                        continue;
                    }
                    const Vec3d target = fallback == 1 ? prediction[j] : midpoint;
                    if (new_positions[j] != target)
                    {
                        new_positions[j] = target;
                        state[j] = State::Reverted;
                        used_ven[j] = 0;
                        changed = true;
                    }
                }
                if (!changed)
                    break;
                refold();
                still = vertices_of_folds(level, folded);
            }
        }
        for (const std::uint32_t j : marked)
            if (used_ven[j] != 0 && state[j] == State::Projected)
                ++stats.folds_fixed_by_ven;
    }

    // Relaxation (§5.2.3): tangential umbrella moves of the projected new vertices, re-projected;
    // Jacobi style (every move computed from the same positions).
    std::vector<Vec3d> moved(added);
    std::vector<Move> move(added, Move::None);
    // Then the new vertices of the level's thin triangles only (thin_relax_iterations): on the
    // simulated fandisk scans of bench/peers the triangles under 20° came from 1.28 / 2.36 /
    // 1.30% to 1.23 / 1.89 / 1.30% with two such rounds (a second round of every vertex, which
    // costs a whole round, gave scan 2 2.00%).
    std::vector<char> only;
    const int rounds =
        options.relax_iterations > 0 ? options.relax_iterations + options.thin_relax_iterations : 0;
    for (int round = 0; round < rounds; ++round)
    {
        if (round >= options.relax_iterations)
        {
            only = thin_vertices(level, x, added);
            if (std::find(only.begin(), only.end(), char{1}) == only.end())
                break;
        }
        ProgressReporter reporter(options.progress, "refine: relax");
        parallel_blocks(
            added, vertex_block,
            [&](std::size_t begin, std::size_t end) {
                for (std::size_t j = begin; j < end; ++j)
                {
                    move[j] = Move::None;
                    if (state[j] != State::Projected || on_crease[j] != 0)
                        continue; // a vertex on a crease stays on it
                    if (!only.empty() && only[j] == 0)
                        continue;
                    const auto [h1, h2] = level.halfedges[j];
                    const Vec3d& p = new_positions[j];
                    Vec3d sum = x[level.from(h1)] + x[level.to(h1)];
                    std::size_t count = 2;
                    Vec3d normal = Vec3d::Zero();
                    for (const std::uint32_t h : {h1, h2})
                    {
                        if (h == none)
                            continue;
                        const std::uint32_t f = h / 3;
                        const std::uint32_t k = h % 3;
                        const Vec3d& q1 = x[level.edge_vertex[3 * f + (k + 1) % 3]];
                        const Vec3d& q2 = x[level.edge_vertex[3 * f + (k + 2) % 3]];
                        sum += q1 + q2;
                        count += 2;
                        // The three children of f around the vertex: (from, p, q2),
                        // (p, to, q1) and (p, q1, q2).
                        const Vec3d& s = x[level.from(h)];
                        const Vec3d& t = x[level.to(h)];
                        normal +=
                            area_normal(s, p, q2) + area_normal(p, t, q1) + area_normal(p, q1, q2);
                    }
                    const Vec3d direction = aw_fen[j].normalized();
                    Vec3d n = normal.normalized();
                    if (!(normal.norm() > 0.0) || !(n.dot(direction) > 0.0))
                        n = direction;
                    // On the boundary the umbrella of the two boundary neighbours only, so the
                    // border is evened out along itself instead of pulled inwards.
                    const Vec3d target = h2 == none
                                             ? Vec3d(0.5 * (x[level.from(h1)] + x[level.to(h1)]))
                                             : Vec3d(sum / static_cast<double>(count));
                    const Vec3d umbrella = target - p;
                    Vec3d tangential = umbrella - n * n.dot(umbrella);
                    if (h2 != none && options.relaxation == Relaxation::AcrossEdge)
                    {
                        const Vec3d along = (x[level.to(h1)] - x[level.from(h1)]).normalized();
                        tangential -= along * along.dot(tangential);
                    }
                    const std::optional<Vec3d> hit =
                        project_to_zero(field, origin + p + tangential, n, reach[j]);
                    if (hit)
                    {
                        moved[j] = *hit - origin;
                        move[j] = Move::Made;
                    }
                    else
                    {
                        move[j] = Move::NoCrossing;
                    }
                }
            },
            &reporter);
        reporter.finish();
        std::vector<Vec3d> before(added);
        for (std::size_t j = 0; j < added; ++j)
        {
            if (move[j] == Move::NoCrossing)
                ++stats.relax_undone;
            if (move[j] == Move::Made)
            {
                before[j] = new_positions[j];
                new_positions[j] = moved[j];
            }
        }
        // Undo the moves of vertices in folded faces until no folded face has a moved vertex.
        for (;;)
        {
            refold();
            bool changed = false;
            for (const std::uint32_t j : vertices_of_folds(level, folded))
                if (move[j] == Move::Made)
                {
                    new_positions[j] = before[j];
                    move[j] = Move::Undone;
                    ++stats.relax_undone;
                    changed = true;
                }
            if (!changed)
                break;
        }
        for (std::size_t j = 0; j < added; ++j)
            if (move[j] == Move::Made)
                ++stats.relaxed;
    }

    refold();
    stats.folded_faces = count_folds(folded);
    for (std::size_t j = 0; j < added; ++j)
    {
        if (state[j] != State::Projected)
            ++stats.unprojected;
        if (state[j] == State::Reverted)
            ++stats.folds_unresolved;
    }
    return child_faces(level);
}

} // namespace

Relaxation parse_relaxation(std::string_view text)
{
    if (text == "across")
        return Relaxation::AcrossEdge;
    if (text == "umbrella")
        return Relaxation::Umbrella;
    throw InvalidInput("unknown relaxation '" + std::string(text) +
                       "' (expected across or umbrella)");
}

std::string_view to_string(Relaxation relaxation)
{
    return relaxation == Relaxation::Umbrella ? "umbrella" : "across";
}

std::string_view to_string(RefineStop stop)
{
    switch (stop)
    {
        case RefineStop::BelowSamplingDensity:
            return "below sampling density";
        case RefineStop::LevelCap:
            return "level cap";
        case RefineStop::Stalled:
            return "stalled";
        case RefineStop::VertexBudget:
            return "vertex budget";
        case RefineStop::SmallDetails:
            return "small details";
        case RefineStop::NoisyDetails:
            return "noisy details";
    }
    return "unknown";
}

StopRule parse_stop_rule(std::string_view text)
{
    if (text == "auto")
        return StopRule::Automatic;
    if (text == "paper")
        return StopRule::Paper;
    if (text == "exact")
        return StopRule::Exact;
    throw InvalidInput("unknown stop rule '" + std::string(text) +
                       "' (expected auto, paper or exact)");
}

std::string_view to_string(StopRule rule)
{
    switch (rule)
    {
        case StopRule::Paper:
            return "paper";
        case StopRule::Exact:
            return "exact";
        case StopRule::Automatic:
            break;
    }
    return "auto";
}

namespace {

/// refine_once(); `nearest` (null, or every sample's closest face on the finest level before)
/// bounds the distance searches and becomes the new level's; `faces` (null, or where the new
/// level's faces go) saves a caller rebuilding them (MultiresMesh::faces()).
RefineLevelStats refine_level(MultiresMesh& mesh, const Field& field, const RefineOptions& options,
                              const PointCloud* samples, std::vector<std::uint32_t>* nearest,
                              std::span<const std::uint32_t> order = {},
                              std::vector<Triangle>* faces = nullptr)
{
    check_options(options);
    if (mesh.level_count() == 0)
        throw InvalidInput("refine: the hierarchy is empty");
    if (mesh.finest_level() == 0)
        mesh.set_predictor(options.predictor);
    else if (mesh.predictor() != options.predictor)
        throw InvalidInput("refine: the hierarchy's levels were predicted by the " +
                           std::string(to_string(mesh.predictor())) +
                           " rule; a level predicted by the " +
                           std::string(to_string(options.predictor)) + " rule cannot follow them");
    const auto start = std::chrono::steady_clock::now();
    const std::size_t previous = mesh.finest_level();
    RefineLevelStats stats;
    MultiresMesh::SplitResult split = mesh.split();
    stats.level = split.level;
    try
    {
        std::vector<Triangle> level_faces =
            refine_split_level(mesh, std::move(split), field, options, stats);
        if (samples != nullptr && !samples->empty())
        {
            Distances d = distances_from(
                *samples, mesh, level_faces, stats.level,
                [&](std::string_view, double fraction) {
                    return !options.progress || options.progress("refine: distance", fraction);
                },
                {.faces = nearest != nullptr ? std::span<const std::uint32_t>(*nearest)
                                             : std::span<const std::uint32_t>(),
                 .children = true},
                order);
            if (nearest != nullptr)
                *nearest = std::move(d.nearest);
            stats.hausdorff = d.hausdorff;
            stats.mean_distance = d.mean;
            stats.robust_distance = d.robust;
            stats.p90_distance = d.p90;
        }
        if (faces != nullptr)
            *faces = std::move(level_faces);
    }
    catch (...)
    {
        mesh.truncate(previous);
        throw;
    }
    stats.faces = mesh.face_count(stats.level);
    stats.vertices = mesh.vertex_count(stats.level);
    stats.new_vertices = stats.vertices - mesh.vertex_count(previous);
    stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return stats;
}

} // namespace

RefineLevelStats refine_once(MultiresMesh& mesh, const Field& field, const RefineOptions& options,
                             const PointCloud* samples)
{
    return refine_level(mesh, field, options, samples, nullptr);
}

namespace {

/// Samples of which field_residual() measures every one; larger clouds every k-th, at least
/// this many (RefineReport::field_residual).
constexpr std::size_t residual_samples = std::size_t{1} << 18U;

/// The field's own robust distance from the samples: the robust statistic of |f(s)|. The
/// samples measured (every stride-th) are evaluated in their spatial `order` (a permutation of
/// the samples), which the field's batch answers fastest, and their values taken in sample order.
double field_residual(const Field& field, const PointCloud& samples,
                      std::span<const std::uint32_t> order)
{
    PF_ASSERT(order.size() == samples.size());
    const std::size_t stride = std::max<std::size_t>(1, samples.size() / residual_samples);
    std::vector<std::uint32_t> measured; // the samples measured, in spatial order
    measured.reserve((samples.size() + stride - 1) / stride);
    for (const std::uint32_t i : order)
        if (i % stride == 0)
            measured.push_back(i);
    std::vector<Vec3d> points(measured.size());
    for (std::size_t k = 0; k < measured.size(); ++k)
        points[k] = samples.world(measured[k]);
    std::vector<FieldSample> values(points.size());
    field.evaluate(points, values);
    std::vector<FieldSample> in_sample_order(values.size());
    for (std::size_t k = 0; k < measured.size(); ++k)
        in_sample_order[measured[k] / stride] = values[k];
    std::vector<double> residual;
    residual.reserve(values.size());
    for (const FieldSample& v : in_sample_order)
        if (v.defined)
            residual.push_back(std::abs(v.value));
    return robust_stats(residual).robust;
}

/// The unique edges of `faces` as sorted (low, high) vertex pairs.
std::vector<std::uint64_t> unique_edges(std::span<const Triangle> faces)
{
    std::vector<std::uint64_t> edges;
    edges.reserve(3 * faces.size());
    for (const Triangle& t : faces)
        for (int k = 0; k < 3; ++k)
        {
            const std::uint64_t a = std::min(t[k], t[(k + 1) % 3]);
            const std::uint64_t b = std::max(t[k], t[(k + 1) % 3]);
            edges.push_back(a << 32U | b);
        }
    parallel_sort(edges);
    edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
    return edges;
}

/// The Euler characteristic of the base mesh, which every level keeps.
long long euler_characteristic(const MultiresMesh& mesh)
{
    return static_cast<long long>(mesh.vertex_count(0)) -
           static_cast<long long>(unique_edges(mesh.base_faces()).size()) +
           static_cast<long long>(mesh.base_faces().size());
}

/// Vertices of the level after the finest: V + E, with E = V + F − χ.
std::size_t next_level_vertices(const MultiresMesh& mesh, long long chi)
{
    const std::size_t level = mesh.finest_level();
    const auto v = static_cast<long long>(mesh.vertex_count(level));
    const auto f = static_cast<long long>(mesh.face_count(level));
    return static_cast<std::size_t>(v + (v + f - chi));
}

/// The expected detail of the next level (see NextDetail).
struct NextDetail
{
    /// The robust statistic of |f| at the midpoints of the finest level's edges. Where f is
    /// undefined (beyond every influence radius) the detail is unknown and counts as infinite:
    /// more than 5% of such midpoints make the next level needed; unless f is undefined at both
    /// ends of the edge too (a filled hole, BaseMeshOptions::fill_holes): those are left out.
    double robust = 0.0;
    /// The largest details: the 99th percentile of |f| over the midpoints where f is defined.
    double tail = 0.0;
};

NextDetail next_detail(const MultiresMesh& mesh, std::span<const Triangle> faces,
                       const Field& field)
{
    const std::vector<std::uint64_t> edges = unique_edges(faces);
    std::vector<Vec3d> midpoints(edges.size());
    for (std::size_t e = 0; e < edges.size(); ++e)
        midpoints[e] = 0.5 * (mesh.world(static_cast<std::uint32_t>(edges[e] >> 32U)) +
                              mesh.world(static_cast<std::uint32_t>(edges[e] & 0xffffffffU)));
    std::vector<FieldSample> values(midpoints.size());
    field.evaluate(midpoints, values);
    // Where both ends lie beyond the field too (a filled hole), the midpoint says nothing: the
    // ends of the edges whose midpoint is undefined, two per edge.
    std::vector<std::size_t> undefined;
    for (std::size_t e = 0; e < values.size(); ++e)
        if (!values[e].defined)
            undefined.push_back(e);
    std::vector<Vec3d> ends(2 * undefined.size());
    for (std::size_t u = 0; u < undefined.size(); ++u)
    {
        const std::uint64_t edge = edges[undefined[u]];
        ends[2 * u] = mesh.world(static_cast<std::uint32_t>(edge >> 32U));
        ends[2 * u + 1] = mesh.world(static_cast<std::uint32_t>(edge & 0xffffffffU));
    }
    std::vector<FieldSample> at_ends(ends.size());
    field.evaluate(ends, at_ends);
    std::vector<char> beyond(values.size(), 0);
    for (std::size_t u = 0; u < undefined.size(); ++u)
        beyond[undefined[u]] = !at_ends[2 * u].defined && !at_ends[2 * u + 1].defined ? 1 : 0;
    std::vector<double> detail;
    detail.reserve(values.size());
    std::vector<double> defined;
    defined.reserve(values.size());
    for (std::size_t e = 0; e < values.size(); ++e)
    {
        if (beyond[e] != 0)
            continue;
        detail.push_back(values[e].defined ? std::abs(values[e].value)
                                           : std::numeric_limits<double>::infinity());
        if (values[e].defined && std::isfinite(values[e].value))
            defined.push_back(detail.back());
    }
    NextDetail out;
    out.robust = robust_stats(detail).robust;
    if (!defined.empty())
    {
        const auto at =
            std::min(defined.size() - 1,
                     static_cast<std::size_t>(0.99 * static_cast<double>(defined.size())));
        std::nth_element(defined.begin(), defined.begin() + static_cast<std::ptrdiff_t>(at),
                         defined.end());
        out.tail = defined[at];
    }
    return out;
}

/// The vertex rings of `faces` over `n` vertices, in compressed rows: the neighbours of v are
/// adjacent[offsets[v], offsets[v + 1]), sorted and without repeats; `boundary` marks the ends
/// of an edge used by one face only.
struct Rings
{
    std::vector<std::uint32_t> offsets;
    std::vector<std::uint32_t> adjacent;
    std::vector<std::uint8_t> boundary;
};

Rings vertex_rings(std::span<const Triangle> faces, std::size_t n)
{
    std::vector<std::uint64_t> directed;
    directed.reserve(6 * faces.size());
    for (const Triangle& t : faces)
        for (std::size_t c = 0; c < 3; ++c)
        {
            const std::uint64_t a = t[c];
            const std::uint64_t b = t[(c + 1) % 3];
            directed.push_back(a << 32U | b);
            directed.push_back(b << 32U | a);
        }
    parallel_sort(directed);
    Rings rings;
    rings.boundary.assign(n, 0);
    rings.offsets.assign(n + 1, 0);
    rings.adjacent.reserve(directed.size() / 2);
    for (std::size_t i = 0; i < directed.size();)
    {
        std::size_t j = i;
        while (j < directed.size() && directed[j] == directed[i])
            ++j;
        const auto from = static_cast<std::uint32_t>(directed[i] >> 32U);
        if (j - i == 1)
            rings.boundary[from] = 1; // the edge has one face: it appears once each way
        rings.adjacent.push_back(static_cast<std::uint32_t>(directed[i] & 0xffffffffU));
        ++rings.offsets[from + 1];
        i = j;
    }
    for (std::size_t v = 0; v < n; ++v)
        rings.offsets[v + 1] += rings.offsets[v];
    return rings;
}

/// The crease edges of `faces`: those whose two faces' normals differ by more than 30°
/// (crease_cosine, the projection's crease test), and by more than the noise turns them: three
/// times atan(noise / the edge's length), `noise` the field's residual at the samples (ends
/// that noise moves by r tilt a face of side h by about atan(r / h): at 100k noisy samples of
/// bench/peers, level 1, about 8°; at 1M, level 2, about 30°). Per entry of `rings.adjacent`,
/// 1 where the edge to that neighbour is one.
std::vector<std::uint8_t> crease_edges(std::span<const Vec3d> x, std::span<const Triangle> faces,
                                       const Rings& rings, double noise)
{
    std::vector<Vec3d> normal(faces.size());
    parallel_blocks(faces.size(), vertex_block, [&](std::size_t begin, std::size_t end) {
        for (std::size_t f = begin; f < end; ++f)
        {
            const Triangle& t = faces[f];
            normal[f] = (x[t[1]] - x[t[0]]).cross(x[t[2]] - x[t[0]]).normalized();
        }
    });
    // Each edge with the faces beside it: (smaller end, larger end, face), sorted.
    // Every pair differs (a face has an edge once), so the parallel sort's order is the one.
    std::vector<std::pair<std::uint64_t, std::uint32_t>> sides(3 * faces.size());
    parallel_blocks(faces.size(), vertex_block, [&](std::size_t begin, std::size_t end) {
        for (std::size_t f = begin; f < end; ++f)
            for (std::size_t c = 0; c < 3; ++c)
            {
                const std::uint64_t a = faces[f][c];
                const std::uint64_t b = faces[f][(c + 1) % 3];
                sides[3 * f + c] = {std::min(a, b) << 32U | std::max(a, b),
                                    static_cast<std::uint32_t>(f)};
            }
    });
    parallel_sort(sides);
    std::vector<std::uint8_t> crease(rings.adjacent.size(), 0);
    const auto mark = [&](std::uint32_t v, std::uint32_t w) {
        const auto first = rings.adjacent.begin() + rings.offsets[v];
        const auto last = rings.adjacent.begin() + rings.offsets[v + 1];
        const auto at = std::lower_bound(first, last, w);
        if (at != last && *at == w)
            crease[static_cast<std::size_t>(at - rings.adjacent.begin())] = 1;
    };
    const double least = std::acos(crease_cosine);
    // Each edge marks its own two slots: the blocks write apart.
    parallel_blocks(sides.size(), 4 * vertex_block, [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end && i + 1 < sides.size(); ++i)
        {
            if (sides[i].first != sides[i + 1].first ||
                (i + 2 < sides.size() && sides[i + 2].first == sides[i].first))
                continue; // a boundary edge, or a non-manifold one
            const auto a = static_cast<std::uint32_t>(sides[i].first >> 32U);
            const auto b = static_cast<std::uint32_t>(sides[i].first & 0xffffffffU);
            const double length = (x[a] - x[b]).norm();
            const double bound = std::max(least, 3.0 * std::atan(noise / std::max(length, 1e-300)));
            const double cosine = normal[sides[i].second].dot(normal[sides[i + 1].second]);
            if (bound < std::numbers::pi && cosine < std::cos(bound))
            {
                mark(a, b);
                mark(b, a);
            }
        }
    });
    return crease;
}

/// Taubin's λ|μ smoothing of the finest level, of `faces` (RefineOptions::denoise_rounds): `rounds`
/// times every vertex moves λ of the way to the mean of its neighbours, then μ of it; a vertex on a
/// boundary edge stays. Creases (edges whose faces meet at more than 30° and more than the noise
/// turns them, crease_edges()) are kept: a vertex on exactly two crease edges moves along them (the
/// mean of those two neighbours), one on one or on three or more (a corner) stays. Jacobi steps in
/// parallel blocks: the same positions whatever the thread count. Returns the farthest move.
double denoise_finest(MultiresMesh& mesh, std::span<const Triangle> faces, const Rings& rings,
                      std::size_t rounds, double noise, std::span<const char> faired)
{
    constexpr double lambda = 0.5;
    constexpr double mu = -0.53;
    const std::size_t n = mesh.vertex_count();
    const std::span<Vec3d> x = mesh.mutable_positions();
    const std::vector<std::uint8_t> crease = crease_edges(x, faces, rings, noise);
    // Per vertex: smoothed over all its neighbours (0), over its two crease neighbours (1), or
    // held (2).
    std::vector<std::uint8_t> kind(n, 0);
    for (std::size_t v = 0; v < n; ++v)
    {
        std::size_t on = 0;
        for (std::uint32_t e = rings.offsets[v]; e < rings.offsets[v + 1]; ++e)
            on += crease[e];
        kind[v] = rings.boundary[v] != 0 || rings.offsets[v + 1] == rings.offsets[v] ? 2
                  : on == 0 || faired[v] != 0                                        ? 0
                  : on == 2                                                          ? 1
                                                                                     : 2;
    }
    const std::vector<Vec3d> start(x.begin(), x.end());
    std::vector<Vec3d> next(n);
    for (std::size_t round = 0; round < 2 * rounds; ++round)
    {
        const double step = round % 2 == 0 ? lambda : mu;
        parallel_blocks(n, vertex_block, [&](std::size_t begin, std::size_t end) {
            for (std::size_t v = begin; v < end; ++v)
            {
                next[v] = x[v];
                if (kind[v] == 2)
                    continue;
                Vec3d mean = Vec3d::Zero();
                std::size_t count = 0;
                for (std::uint32_t e = rings.offsets[v]; e < rings.offsets[v + 1]; ++e)
                    if (kind[v] == 0 || crease[e] != 0)
                    {
                        mean += x[rings.adjacent[e]];
                        ++count;
                    }
                mean /= static_cast<double>(count);
                next[v] = x[v] + step * (mean - x[v]);
            }
        });
        std::copy(next.begin(), next.end(), x.begin());
    }
    double farthest = 0.0;
    for (std::size_t v = 0; v < n; ++v)
        farthest = std::max(farthest, (x[v] - start[v]).norm());
    return farthest;
}

/// What fit_faces() did.
struct FaceFit
{
    std::size_t vertices = 0;
    double max_move = 0.0;
    /// The median of the moves the fit asked for, made or not (below fit_least_move).
    double median_move = 0.0;
    /// How many probe vertices' moves median_move is the median of (fit_probes); 0 when it is
    /// that of the whole level.
    std::size_t probes = 0;
};

/// fit_faces(): the field is evaluated at the faces in batches of this many faces (three points
/// each), so that the points and their values take at most about 12 MB at once.
constexpr std::size_t fit_face_batch = 65536;

/// fit_faces(): a vertex moves at most this share of the mean length of its ring's edges.
constexpr double fit_reach = 0.25;

/// fit_faces() moves no vertex when the median move is below this share of the field's residual
/// at the samples (the noise the field leaves): then the moves follow the field's unevenness
/// between the vertices more than the faces' sag. Median move over residual, measured: a clean
/// 100k sphere 2,100, the shipped bunny scan 0.67 (Chamfer to bun_zipper 0.0507 -> 0.0478% of
/// the diagonal with the fit), simulated scans of data/meshes/ 0.034-0.048 (fandisk, teapot and
/// spot, seed 1: Chamfer 0.1552 / 0.2012 / 0.1074 -> 0.1561 / 0.2020 / 0.1079 with a fit of
/// every vertex of the level, and with its moves averaged over one or two rings no better than
/// without the fit).
constexpr double fit_least_move = 0.25;

/// fit_faces() first measures the moves of about this many free vertices, evenly spread over
/// the level's (all the faces around each, so each move is exactly the whole fit's), and makes
/// no fit where their median is below fit_probe_margin of the bar and at least fit_probe_least
/// of them move: on the simulated scans above, whose median is a fifth to a seventh of the bar,
/// the fit's field evaluations (281,000 on fandisk scan 3, about a tenth of refinement's time)
/// then drop to a twentieth. The median of 2,048 moves is within about 3% of the whole level's
/// (its standard error, for any spread of the moves); where the probes' is not far below the
/// bar, the whole fit is measured and decides as before, and the probes cost it a few percent
/// more (1% of the faces at 1M samples).
constexpr std::size_t fit_probes = 2048;
constexpr double fit_probe_margin = 0.5;
constexpr std::size_t fit_probe_least = 256;

/// The finest level's flat faces fitted to the field's zero set in the least-squares sense
/// (RefineOptions::fit_faces): each vertex moves along its normal by the mean, over its faces and
/// weighted by area and by its barycentric share, of the step that would take each point of the
/// faces onto the zero set (−f ∇f / |∇f|², at the three points of the rule exact for quadratics).
/// A uniform sag comes out exactly; vertices on a boundary, on a crease edge (crease_edges()), in
/// a faired region or with a ring of no defined field are held. The moves are taken from the
/// positions before any of them (the same whatever the thread count).
FaceFit fit_faces(MultiresMesh& mesh, std::span<const Triangle> faces, const Rings& rings,
                  const Field& field, double noise, std::span<const char> faired)
{
    const std::size_t n = mesh.vertex_count();
    const std::span<Vec3d> x = mesh.mutable_positions();
    const Vec3d origin = mesh.origin();
    // The vertices that move: the finest level's own (the coarser levels' stay as they were
    // measured), off boundaries, creases and faired regions.
    const std::size_t coarser =
        mesh.finest_level() > 0 ? mesh.vertex_count(mesh.finest_level() - 1) : 0;
    std::vector<char> free(n, 0);
    {
        const std::vector<std::uint8_t> crease = crease_edges(x, faces, rings, noise);
        parallel_blocks(n, vertex_block, [&](std::size_t begin, std::size_t end) {
            for (std::size_t v = std::max(begin, coarser); v < end; ++v)
            {
                const std::uint32_t e0 = rings.offsets[v];
                const std::uint32_t e1 = rings.offsets[v + 1];
                bool held = e0 == e1 || rings.boundary[v] != 0 || faired[v] != 0;
                for (std::uint32_t e = e0; e < e1 && !held; ++e)
                    held = crease[e] != 0;
                free[v] = held ? 0 : 1;
            }
        });
    }
    constexpr std::array<std::array<double, 3>, 3> rule{{{2.0 / 3.0, 1.0 / 6.0, 1.0 / 6.0},
                                                         {1.0 / 6.0, 2.0 / 3.0, 1.0 / 6.0},
                                                         {1.0 / 6.0, 1.0 / 6.0, 2.0 / 3.0}}};
    std::vector<Vec3d> pull(n, Vec3d::Zero());
    std::vector<double> weight(n, 0.0);
    std::vector<Vec3d> normal(n, Vec3d::Zero());
    // The pulls of the faces `which` (ascending) on their vertices, in face order.
    const auto accumulate = [&](std::span<const std::uint32_t> which) {
        std::fill(pull.begin(), pull.end(), Vec3d::Zero());
        std::fill(weight.begin(), weight.end(), 0.0);
        std::fill(normal.begin(), normal.end(), Vec3d::Zero());
        std::vector<Vec3d> at;
        std::vector<FieldSample> value;
        for (std::size_t first = 0; first < which.size(); first += fit_face_batch)
        {
            const std::size_t last = std::min(which.size(), first + fit_face_batch);
            at.resize(3 * (last - first));
            value.resize(at.size());
            parallel_blocks(last - first, vertex_block, [&](std::size_t begin, std::size_t end) {
                for (std::size_t i = begin; i < end; ++i)
                {
                    const Triangle& t = faces[which[first + i]];
                    for (std::size_t k = 0; k < 3; ++k)
                        at[3 * i + k] = origin + rule[k][0] * x[t[0]] + rule[k][1] * x[t[1]] +
                                        rule[k][2] * x[t[2]];
                }
            });
            field.evaluate(at, value);
            // In face order, one thread: the sums are the same whatever the thread count.
            for (std::size_t i = first; i < last; ++i)
            {
                const Triangle& t = faces[which[i]];
                const Vec3d area = area_normal(x[t[0]], x[t[1]], x[t[2]]);
                const double a = area.norm();
                for (const std::uint32_t v : t)
                    normal[v] += area;
                if (free[t[0]] == 0 && free[t[1]] == 0 && free[t[2]] == 0)
                    continue;
                for (std::size_t k = 0; k < 3; ++k)
                {
                    const FieldSample& s = value[3 * (i - first) + k];
                    const double g2 = s.gradient.squaredNorm();
                    if (!s.defined || !(g2 > 0.0) || !std::isfinite(s.value) || !std::isfinite(g2))
                        continue;
                    const Vec3d step = (-s.value / g2) * s.gradient;
                    for (std::size_t c = 0; c < 3; ++c)
                    {
                        pull[t[c]] += (a * rule[k][c]) * step;
                        weight[t[c]] += a * rule[k][c];
                    }
                }
            }
        }
    };
    // The moves of the free vertices with `of[v]` (all where it is empty), from the pulls.
    std::vector<double> move(n, 0.0);
    const auto moves = [&](std::span<const char> of) {
        parallel_blocks(n, vertex_block, [&](std::size_t begin, std::size_t end) {
            for (std::size_t v = begin; v < end; ++v)
            {
                move[v] = 0.0;
                if (free[v] == 0 || (!of.empty() && of[v] == 0) || !(weight[v] > 0.0) ||
                    !(normal[v].squaredNorm() > 0.0))
                    continue;
                double ring = 0.0;
                for (std::uint32_t e = rings.offsets[v]; e < rings.offsets[v + 1]; ++e)
                    ring += (x[rings.adjacent[e]] - x[v]).norm();
                const double reach =
                    fit_reach * ring / static_cast<double>(rings.offsets[v + 1] - rings.offsets[v]);
                const double along = (pull[v] / weight[v]).dot(normal[v].normalized());
                if (std::isfinite(along))
                    move[v] = std::clamp(along, -reach, reach);
            }
        });
        // Noise: the moves are the field's own unevenness more than the faces' sag.
        std::vector<double> sizes;
        for (const double m : move)
            if (m != 0.0)
                sizes.push_back(std::abs(m));
        if (sizes.empty())
            return std::pair<double, std::size_t>{0.0, 0};
        const auto middle = sizes.begin() + static_cast<std::ptrdiff_t>(sizes.size() / 2);
        std::nth_element(sizes.begin(), middle, sizes.end());
        return std::pair<double, std::size_t>{*middle, sizes.size()};
    };
    FaceFit fit;
    // First the median over about fit_probes free vertices (every face around each of them, so
    // their moves are exactly those of the whole fit): where it is far below the bar, noise
    // rules and the fit is not made.
    {
        const auto free_count = static_cast<std::size_t>(
            std::count(free.begin() + static_cast<std::ptrdiff_t>(coarser), free.end(), char{1}));
        const std::size_t stride = std::max<std::size_t>(1, free_count / fit_probes);
        std::vector<char> probe(n, 0);
        std::size_t probes = 0;
        for (std::size_t v = coarser; v < n; ++v)
            if (free[v] != 0 && probes++ % stride == 0)
                probe[v] = 1;
        std::vector<std::uint32_t> around;
        for (std::size_t f = 0; f < faces.size(); ++f)
            if (probe[faces[f][0]] != 0 || probe[faces[f][1]] != 0 || probe[faces[f][2]] != 0)
                around.push_back(static_cast<std::uint32_t>(f));
        accumulate(around);
        const auto [median, count] = moves(probe);
        fit.median_move = median;
        fit.probes = count;
        if (count >= fit_probe_least && median < fit_probe_margin * fit_least_move * noise)
            return fit;
    }
    std::vector<std::uint32_t> all(faces.size());
    for (std::size_t f = 0; f < faces.size(); ++f)
        all[f] = static_cast<std::uint32_t>(f);
    accumulate(all);
    const auto [median, count] = moves({});
    fit.median_move = median;
    fit.probes = 0;
    if (count == 0 || median < fit_least_move * noise)
        return fit;
    for (std::size_t v = 0; v < n; ++v)
        if (move[v] != 0.0)
        {
            x[v] += move[v] * normal[v].normalized();
            ++fit.vertices;
            fit.max_move = std::max(fit.max_move, std::abs(move[v]));
        }
    return fit;
}

/// fair_unsupported(): a vertex is a region's core when its nearest sample is farther than
/// this many sample spacings (the spacing there: that sample's influence radius over the
/// cloud's median ratio of radius to nearest-neighbour distance). A point dropped at random
/// among samples of spacing s is farther than c·s from all of them with probability about
/// 2^(-c²): 6% at 2, on a regular mesh as fine as its samples scattered vertices, which the
/// next rule leaves alone (a vertex and its six neighbours all that far by chance: about
/// 0.06^7 if independent). Against 2.5 (1.3%), with the band below: on twenty simulated scans
/// (fandisk and spot, seeds 1-10) mean F@0.5% 0.9476 -> 0.9490 and Chamfer 0.1535 -> 0.1519%
/// of the diagonal; the bunny scan's Chamfer 0.0496 -> 0.0490%; the clean 100k part and
/// plate of bench/peers, where the mesh cuts a few corners, Hausdorff 0.55 -> 0.44% and 0.39
/// -> 0.29% (Chamfer 0.0067 -> 0.0068, 0.0036 -> 0.0037); the noisy 100k inputs the same to
/// 0.0001; the clean sphere and torus still keep no region.
constexpr double unsupported_core = 2.0;
/// ... and a region is kept only when one of its core vertices has every neighbour in the core
/// too: a hole's patch, not a scattered vertex or a line of them (a crease whose corner the
/// mesh cuts); or when one of its vertices is farther than this many spacings from every sample,
/// which no random gap is (about 2^-25 of them): a spike, or a hole too narrow for an interior
/// vertex.
constexpr double unsupported_far = 5.0;
/// A kept region then takes in its neighbours, ring by ring, as far as this many spacings (the
/// cloud's median) from it along the mesh's edges ...
constexpr double unsupported_band_reach = 14.0;
/// ... that are farther than this many spacings from every sample: the rim around a hole, where
/// the field extrapolates the last few (noisy) samples' fits and the mesh follows them. A
/// vertex among samples of spacing s lies within about s / √3 of one (the circumradius of
/// their triangles), so farther than 0.75 s it sits in a gap of the sampling. A scanner's
/// sampling thins out over a wide rim before a hole (grazing rays), and the fits there
/// extrapolate worst. Against the earlier band (3 rings beyond 1.5 spacings), on twenty
/// simulated scans (bench/peers/virtual_scan.py, fandisk and spot, seeds 1-10) every one came
/// closer to its truth: mean F@0.5% 0.9414 -> 0.9476 (precision 0.948 -> 0.959), Chamfer
/// 0.162 -> 0.154% of the diagonal, the largest distance 6.19 -> 5.80%; as far as 7 and 10
/// spacings 0.9452 and 0.9465. The 100k noisy inputs of bench/peers, whose holes' rims are
/// sharp: Chamfer of the sphere 0.0475 -> 0.0454%, torus 0.0496 -> 0.0475, plate 0.0667 ->
/// 0.0605, part 0.0732 -> 0.0734, blobby 0.0609 -> 0.0620 (0.0608 as far as 7 spacings); the
/// bunny scan 0.0526 -> 0.0496. Where the field's quadrics extrapolate well it can be worse
/// (HoleFill.ThinningRimsAreFairedWithTheirHoles).
constexpr double unsupported_band = 0.75;
/// The held vertices within this many rings of a faired region relax with it (not faired):
/// the fairing and its relaxation leave the region's vertices spread for its own shape, the
/// held ones around spaced as the projections of the levels left them, and the triangles
/// across that seam thin. On the twenty scans above, with the earlier band, the share of
/// triangles under 20° went 0.80% -> 0.53% on average and 2.55% -> 1.69% at most (fandisk
/// scan 6), F@0.5% and Chamfer the same to 0.0001; with this band 0.54% and 1.80% (1 ring,
/// with a band of 6 rings beyond 0.75 spacings: 0.62% and 2.02%).
constexpr std::size_t unsupported_relax_rings = 2;

/// A thin-plate region of fair_unsupported() whose rim parts into the faces of a crease
/// (detail::crease_fill_for_rim()).
struct CreasedRegion
{
    std::vector<std::uint32_t> members;
    std::vector<Vec3d> rim;
    detail::CreaseFill fill;
};

/// A faired region is moved onto the faces of a crease (onto_crease_faces()) only when one of
/// its vertices is farther than this many local spacings from every sample: a hole. A clean
/// thin part's rim, whose corners the mesh cuts by a spacing or two, is not one: on the clean
/// 100k thin plate of bench/peers (0.02 thick) the regions whose rims part into faces reach 2.8
/// to 4.1 spacings, and those faces, each fitted to a strip of rim as wide as the plate is
/// thick, moved vertices of its sides 0.003 out (Chamfer 0.0044 -> 0.0049% of the diagonal);
/// the holes over the noisy 100k cone's rim reach 8.8 to 12.1.
constexpr double crease_fill_depth = 5.0;

/// A crease fill whose faces include two facing nearly opposite ways (their normals more than
/// about 150 degrees apart) spans a thin wall: its region is a wall's rim, not one crease's
/// corner. Where the wall is thinner than the field's fits reach, the field rounds its rim
/// off into a cap standing several spacings beyond the samples (a clean 100k plate 0.02 thick,
/// about five spacings: regions 5-8 spacings deep), and the rim's strips on the wall's side,
/// as narrow as the wall is thick, fit faces that bend or never meet: the crease fill moved
/// such caps up to 0.066 out past the plate's side (3.3 thicknesses; Hausdorff distance 2.33%
/// of the diagonal against 0.60% as faired). The thin plate's fairing takes such a cap back to
/// within about 3-4 spacings of the samples, while a hole through a wall's rim stays as deep as
/// it is wide: so such a fill is kept only when its faired region is still crease_fill_depth
/// deep. A cone's acute rim (normals 135 degrees apart) is not a wall.
constexpr double wall_faces_cosine = -0.866;

/// Whether two of a crease fill's faces face nearly opposite ways (wall_faces_cosine).
bool spans_a_wall(const detail::CreaseFill& fill)
{
    for (std::size_t a = 0; a < fill.faces.size(); ++a)
        for (std::size_t b = a + 1; b < fill.faces.size(); ++b)
            if (fill.faces[a].axis.dot(fill.faces[b].axis) < wall_faces_cosine)
                return true;
    return false;
}

/// onto_crease_faces() moves a vertex farther than its nearest rim vertex only when the face it
/// meets there faces the move within 60°, or when it lands on the crease (the other faces' value
/// there within this share of the move): on the 1M noisy plate of bench/peers, vertices in a
/// hole over the plate's edge (its rim parted into the top and bottom faces alone) slid 0.05
/// out past the edge along their normals to meet the bottom face (Hausdorff distance 1.82% of
/// the diagonal), while over the acute rim of a cone the faces meet at 67° from the thin
/// plate's normal there.
constexpr double crease_far_move_alignment = 0.5;
constexpr double crease_far_move_gap = 0.25;

/// Steps of onto_crease_faces()'s search for the faces' envelope along a vertex's normal, each way.
constexpr int crease_search_steps = 16;

/// onto_crease_faces() of one region, with the faired surface's normals (`normal`, at
/// `slot[v]` for vertex v). Returns how many of its vertices moved.
std::size_t onto_crease_faces(std::span<Vec3d> x, std::span<const Vec3d> normal,
                              std::span<const std::uint32_t> slot, const CreasedRegion& region)
{
    const std::size_t count = region.members.size();
    if (count == 0 || region.fill.faces.empty())
        return 0;
    const double rim_spread = detail::crease_fill_internal::rms_spread(region.rim);
    std::vector<Vec3d> moved(count);
    parallel_blocks(count, 64, [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i)
        {
            const Vec3d start = x[region.members[i]];
            moved[i] = start;
            const Vec3d& n = normal[slot[region.members[i]]];
            const double length = n.norm();
            if (!(length > 0.0) || !std::isfinite(length))
                continue;
            const Vec3d along = n / length;
            double near = std::numeric_limits<double>::infinity();
            for (const Vec3d& r : region.rim)
                near = std::min(near, (r - start).squaredNorm());
            near = std::sqrt(near);
            const double reach = std::max(near, rim_spread);
            const auto value = [&](double t) {
                return region.fill.value(start + t * along);
            };
            const double at_start = value(0.0);
            if (!(at_start != 0.0) || !std::isfinite(at_start) || !(reach > 0.0))
                continue;
            // Only across the corner the thin plate cuts: out to a convex crease from inside
            // its faces, in to a concave one from outside them; either way onto curved faces
            // (CreaseFill::curved), which a thin plate can also cut the other way. The nearest
            // sign change that way.
            if ((at_start > 0.0) == region.fill.convex && !region.fill.curved)
                continue;
            const double sign = at_start > 0.0 ? -1.0 : 1.0;
            double inner = 0.0;
            double outer = 0.0;
            for (int step = 1; step <= crease_search_steps; ++step)
            {
                const double t = sign * reach * step / crease_search_steps;
                const double v = value(t);
                if (std::isfinite(v) && (v > 0.0) != (at_start > 0.0))
                {
                    inner = sign * reach * (step - 1) / crease_search_steps;
                    outer = t;
                    break;
                }
            }
            if (outer == 0.0)
                continue;
            for (int round = 0; round < 40; ++round)
            {
                const double middle = 0.5 * (inner + outer);
                if ((value(middle) > 0.0) == (at_start > 0.0))
                    inner = middle;
                else
                    outer = middle;
            }
            const double t = 0.5 * (inner + outer);
            // Past the nearest rim vertex only towards the face met, or onto the crease itself
            // (the other faces there within a quarter of the move of it): a vertex whose
            // normal runs along a face (the middle of a hole over a plate's edge, between its
            // top and bottom faces) would slide out to where that face is met far off.
            if (std::abs(t) > near)
            {
                const Vec3d end_point = start + t * along;
                const std::size_t met = region.fill.active_face(end_point);
                const double runner_up = region.fill.envelope(end_point, met);
                const bool facing =
                    std::abs(region.fill.faces[met].axis.dot(along)) >= crease_far_move_alignment;
                const bool on_crease = std::abs(runner_up) <= crease_far_move_gap * std::abs(t);
                if (!facing && !on_crease)
                    continue;
            }
            moved[i] = start + t * along;
        }
    });
    std::size_t changed = 0;
    for (std::size_t i = 0; i < count; ++i)
    {
        changed += moved[i] != x[region.members[i]] ? 1U : 0U;
        x[region.members[i]] = moved[i];
    }
    return changed;
}

/// Moves the faired regions' vertices along the faired surface's normals onto the zero set of
/// their crease fills (detail::CreaseFill), each at most as far as the farther of its nearest rim
/// vertex and the rim's root-mean-square spread about its centroid (the nearest zero crossing
/// found by steps of a sixteenth of that, then bisected): the thin plate rounds the crease off,
/// the faces meet at it. Bounded by the nearest rim vertex alone, the middle of a hole over a
/// plate's edge (0.05 thick, the hole 0.22 wide) could not reach the side wall, 0.065 out and
/// its top and bottom rims 0.04-0.05 away: the 1M noisy plate's rim holes 1.83 / 1.67 / 1.54 /
/// 0.67% of the diagonal from the truth, with the spread 0.60 / 0.99 / 0.48 / 0.48. Returns how
/// many regions moved.
std::size_t onto_crease_faces(std::span<Vec3d> x, std::span<const Triangle> faces,
                              std::span<const CreasedRegion> regions)
{
    // The faired surface's area-weighted normals at the regions' vertices (the regions are
    // disjoint), in one pass over the faces.
    std::vector<std::uint32_t> slot(x.size(), none);
    std::uint32_t slots = 0;
    for (const CreasedRegion& region : regions)
        for (const std::uint32_t v : region.members)
            slot[v] = slots++;
    std::vector<Vec3d> normal(slots, Vec3d::Zero());
    for (const Triangle& t : faces)
    {
        if (slot[t[0]] == none && slot[t[1]] == none && slot[t[2]] == none)
            continue;
        const Vec3d area = area_normal(x[t[0]], x[t[1]], x[t[2]]);
        for (const std::uint32_t v : t)
            if (slot[v] != none)
                normal[slot[v]] += area;
    }
    std::size_t moved_regions = 0;
    for (const CreasedRegion& region : regions)
        moved_regions += onto_crease_faces(x, normal, slot, region) > 0 ? 1U : 0U;
    return moved_regions;
}

/// Fairs the finest level where no sample supports it (RefineOptions::fair_unsupported): the
/// regions of vertices far from every sample (filled holes and the rims around them, see
/// unsupported_core) take the smoothest surface that continues the mesh around them, thin-plate
/// fairing as the base mesh's hole patches (Σ ‖L x‖² least over the region and its neighbours,
/// L the uniform Laplacian, every other vertex held). Vertices on the mesh's boundary are held.
UnsupportedFairing fair_unsupported(MultiresMesh& mesh, std::span<const Triangle> faces,
                                    const Rings& rings, const PointCloud& samples,
                                    const KdTree& tree, double spacing, std::vector<char>& faired)
{
    faired.assign(mesh.vertex_count(), 0);
    UnsupportedFairing out;
    const std::size_t n = mesh.vertex_count();
    if (samples.empty() || n == 0 || !(spacing > 0.0))
        return out;
    // The local spacing at a sample: its influence radius scaled by the cloud's median ratio.
    double radius_scale = 0.0;
    if (samples.radii.size() == samples.size())
    {
        std::vector<float> radii(samples.radii);
        const auto middle = radii.begin() + static_cast<std::ptrdiff_t>(radii.size() / 2);
        std::nth_element(radii.begin(), middle, radii.end());
        if (*middle > 0.0F && std::isfinite(*middle))
            radius_scale = spacing / static_cast<double>(*middle);
    }
    const Vec3d shift = mesh.origin() - samples.origin;
    const std::span<Vec3d> x = mesh.mutable_positions();
    // Distance to the nearest sample in local spacings. Level by level: a base vertex searches
    // the whole tree, and a later one starts from the nearest sample of its parent edge's first
    // end (an edge of the level below away), whose distance bounds its search.
    // The distance from `at` to its nearest sample (searched from sample `start` when there is
    // one) in local spacings; the sample into `nearest` (none when there is no sample).
    const auto depth_at = [&](const Vec3d& at, std::uint32_t start, std::uint32_t& nearest) {
        float squared = 0.0F;
        const Vec3f query = (at + shift).cast<float>();
        const PointId found =
            start == none ? tree.nearest(query, &squared)
                          : tree.nearest_within_factor(query, 1.0F, PointId{start}, &squared);
        nearest = found.is_valid() ? found.value : none;
        if (!found.is_valid())
            return 0.0;
        double local = spacing;
        if (radius_scale > 0.0)
        {
            const double r = radius_scale * static_cast<double>(samples.radii[found.value]);
            if (r > 0.0 && std::isfinite(r))
                local = r;
        }
        return std::sqrt(static_cast<double>(squared)) / local;
    };
    std::vector<float> excess(n, 0.0F);
    std::vector<std::uint32_t> nearest_sample(n, none);
    const std::size_t base = mesh.vertex_count(0);
    const std::span<const ParentEdge> parents = mesh.parent_edges();
    for (std::size_t level = 0; level <= mesh.finest_level(); ++level)
    {
        const std::size_t first = level == 0 ? 0 : mesh.vertex_count(level - 1);
        const std::size_t last = mesh.vertex_count(level);
        parallel_blocks(last - first, vertex_block, [&](std::size_t begin, std::size_t end) {
            for (std::size_t v = first + begin; v < first + end; ++v)
            {
                const std::uint32_t start = v < base ? none : nearest_sample[parents[v - base].a];
                excess[v] = static_cast<float>(depth_at(x[v], start, nearest_sample[v]));
            }
        });
    }
    const auto ring = [&](std::size_t v) {
        return std::span<const std::uint32_t>(rings.adjacent)
            .subspan(rings.offsets[v], rings.offsets[v + 1] - rings.offsets[v]);
    };
    const auto core = [&](std::size_t v) {
        return rings.boundary[v] == 0 && static_cast<double>(excess[v]) > unsupported_core &&
               rings.offsets[v + 1] > rings.offsets[v];
    };
    // The core's connected regions; those with an interior vertex, or one beyond
    // unsupported_far, are kept.
    constexpr std::uint32_t unset = std::numeric_limits<std::uint32_t>::max();
    std::vector<std::uint32_t> region(n, unset);
    std::vector<char> free(n, 0);
    std::vector<std::uint32_t> members;
    std::vector<std::uint32_t> stack;
    std::uint32_t regions = 0;
    for (std::size_t seed = 0; seed < n; ++seed)
    {
        if (region[seed] != unset || !core(seed))
            continue;
        members.clear();
        stack.assign(1, static_cast<std::uint32_t>(seed));
        region[seed] = regions;
        bool interior = false;
        while (!stack.empty())
        {
            const std::uint32_t v = stack.back();
            stack.pop_back();
            members.push_back(v);
            bool all = true;
            for (const std::uint32_t w : ring(v))
            {
                if (!core(w))
                {
                    all = false;
                    continue;
                }
                if (region[w] == unset)
                {
                    region[w] = regions;
                    stack.push_back(w);
                }
            }
            interior = interior || all || static_cast<double>(excess[v]) > unsupported_far;
        }
        ++regions;
        if (interior)
            for (const std::uint32_t v : members)
                free[v] = 1;
    }
    // The band around the kept regions.
    std::vector<std::uint32_t> front;
    for (std::size_t v = 0; v < n; ++v)
        if (free[v] != 0)
            front.push_back(static_cast<std::uint32_t>(v));
    // Ring by ring, each vertex taken at the shortest path along the rings' edges from the
    // kept regions (through the vertices taken), within unsupported_band_reach spacings.
    const double band_reach = unsupported_band_reach * spacing;
    std::vector<double> path(n, std::numeric_limits<double>::infinity());
    for (const std::uint32_t v : front)
        path[v] = 0.0;
    while (!front.empty())
    {
        std::vector<std::uint32_t> next;
        for (const std::uint32_t v : front)
            for (const std::uint32_t w : ring(v))
                if (free[w] == 0 && rings.boundary[w] == 0 &&
                    static_cast<double>(excess[w]) > unsupported_band)
                {
                    const double along = path[v] + (x[w] - x[v]).norm();
                    if (along <= band_reach && along < path[w])
                    {
                        if (!std::isfinite(path[w]))
                            next.push_back(w);
                        path[w] = along;
                    }
                }
        for (const std::uint32_t w : next)
            free[w] = 1;
        std::sort(next.begin(), next.end());
        front = std::move(next);
    }
    // Regions of the free vertices; one with no held neighbour (a whole component far from
    // the samples) has nothing to continue and stays. Each is faired on its own, as a thin
    // plate or a membrane as its rim says (choose_fill()).
    const auto for_each_neighbour = [&](std::uint32_t v, const auto& visit) {
        for (const std::uint32_t w : ring(v))
            visit(w);
    };
    const auto position = [&](std::uint32_t v) {
        return x[v];
    };
    // The held surface's normals (area-weighted, over the faces with no free vertex), for the
    // rims' slopes.
    std::vector<Vec3d> normal(n, Vec3d::Zero());
    for (const Triangle& t : faces)
    {
        if (free[t[0]] != 0 || free[t[1]] != 0 || free[t[2]] != 0)
            continue;
        const Vec3d area = area_normal(x[t[0]], x[t[1]], x[t[2]]);
        for (const std::uint32_t v : t)
            normal[v] += area;
    }
    std::vector<char> on_rim(n, 0);
    // The rim of one region: the held vertices next to it, at their positions, with the held
    // surface's normals there.
    const auto rim_of = [&](std::span<const std::uint32_t> region_vertices) {
        std::vector<std::uint32_t> rim;
        for (const std::uint32_t v : region_vertices)
            for (const std::uint32_t w : ring(v))
                if (free[w] == 0 && on_rim[w] == 0)
                {
                    on_rim[w] = 1;
                    rim.push_back(w);
                }
        for (const std::uint32_t w : rim)
            on_rim[w] = 0;
        std::sort(rim.begin(), rim.end());
        std::vector<Vec3d> at(rim.size());
        std::vector<Vec3d> normals(rim.size());
        for (std::size_t i = 0; i < rim.size(); ++i)
        {
            at[i] = x[rim[i]];
            normals[i] = normal[rim[i]];
        }
        return std::pair{std::move(at), std::move(normals)};
    };
    std::fill(region.begin(), region.end(), unset);
    std::vector<std::uint32_t> unknowns;
    std::vector<char> flat_fill(n, 0);
    // The thin plates across a crease, moved onto the crease's faces once every region is faired.
    std::vector<CreasedRegion> creased;
    const auto hole_depth = [&](std::span<const std::uint32_t> region_vertices) {
        float deepest = 0.0F;
        for (const std::uint32_t v : region_vertices)
            deepest = std::max(deepest, excess[v]);
        return static_cast<double>(deepest);
    };
    // The same depth of a region's faired positions (`at`, in its members' order).
    const auto faired_depth = [&](std::span<const std::uint32_t> region_vertices,
                                  std::span<const Vec3d> at) {
        double deepest = 0.0;
        std::uint32_t nearest = none;
        for (std::size_t i = 0; i < at.size(); ++i)
            deepest =
                std::max(deepest, depth_at(at[i], nearest_sample[region_vertices[i]], nearest));
        return deepest;
    };
    // The regions first, then their fairings, in waves of regions solved in parallel: a
    // region's system reads the positions of the vertices two rings out from it (its rim's
    // neighbours), which may be another region's, and it must see them as a pass over the
    // regions in order would: faired for an earlier region, not yet for a later one. So a
    // region's wave comes after that of every earlier region within two rings, and each wave's
    // solutions go in once the whole wave is solved: the same positions whatever the thread
    // count, and the same as one region after another.
    struct Found
    {
        std::vector<std::uint32_t> members;
        std::vector<Vec3d> rim_at;
        std::vector<Vec3d> rim_normals;
        detail::Fairing fill = detail::Fairing::thin_plate;
        std::size_t wave = 0;
        std::optional<std::vector<Vec3d>> solution;
        std::vector<Vec3d> before; ///< the members' positions before the fairing
    };
    std::vector<Found> found;
    for (std::size_t seed = 0; seed < n; ++seed)
    {
        if (free[seed] == 0 || region[seed] != unset)
            continue;
        members.clear();
        stack.assign(1, static_cast<std::uint32_t>(seed));
        region[seed] = 0;
        bool held = false;
        while (!stack.empty())
        {
            const std::uint32_t v = stack.back();
            stack.pop_back();
            members.push_back(v);
            for (const std::uint32_t w : ring(v))
            {
                if (free[w] == 0)
                    held = true;
                else if (region[w] == unset)
                {
                    region[w] = 0;
                    stack.push_back(w);
                }
            }
        }
        if (!held)
            continue;
        std::sort(members.begin(), members.end());
        Found& f = found.emplace_back();
        f.members = members;
        std::tie(f.rim_at, f.rim_normals) = rim_of(members);
        f.fill = detail::fill_for_rim(f.rim_at, f.rim_normals);
    }
    std::size_t waves = 0;
    {
        std::vector<std::uint32_t> found_of(n, none);
        for (std::size_t r = 0; r < found.size(); ++r)
        {
            Found& f = found[r];
            for (const std::uint32_t v : f.members)
                found_of[v] = static_cast<std::uint32_t>(r);
            for (const std::uint32_t v : f.members)
                for (const std::uint32_t w : ring(v))
                    if (free[w] == 0)
                        for (const std::uint32_t u : ring(w))
                            if (found_of[u] != none && found_of[u] < r)
                                f.wave = std::max(f.wave, found[found_of[u]].wave + 1);
            waves = std::max(waves, f.wave + 1);
        }
    }
    std::vector<std::uint32_t> in_wave;
    for (std::size_t wave = 0; wave < waves; ++wave)
    {
        in_wave.clear();
        for (std::size_t r = 0; r < found.size(); ++r)
            if (found[r].wave == wave)
                in_wave.push_back(static_cast<std::uint32_t>(r));
        parallel_blocks(in_wave.size(), 1, [&](std::size_t begin, std::size_t end) {
            for (std::size_t i = begin; i < end; ++i)
            {
                Found& f = found[in_wave[i]];
                f.solution =
                    detail::thin_plate_fairing(n, f.members, for_each_neighbour, position, f.fill);
            }
        });
        for (const std::uint32_t r : in_wave)
        {
            Found& f = found[r];
            if (!f.solution)
                continue;
            f.before.resize(f.members.size());
            for (std::size_t i = 0; i < f.members.size(); ++i)
            {
                f.before[i] = x[f.members[i]];
                x[f.members[i]] = (*f.solution)[i];
            }
        }
    }
    for (const Found& f : found)
    {
        if (!f.solution)
            continue;
        ++out.regions;
        if (f.fill == detail::Fairing::membrane)
            ++out.membranes;
        else if (hole_depth(f.members) >= crease_fill_depth)
        {
            std::optional<detail::CreaseFill> crease =
                detail::crease_fill_for_rim(f.rim_at, f.rim_normals);
            if (crease && spans_a_wall(*crease) &&
                faired_depth(f.members, *f.solution) < crease_fill_depth)
                crease.reset();
            if (crease)
                creased.push_back({f.members, f.rim_at, std::move(*crease)});
        }
        for (const std::uint32_t v : f.members)
        {
            flat_fill[v] = f.fill == detail::Fairing::membrane ? 1 : 0;
            faired[v] = 1;
            unknowns.push_back(v);
        }
    }
    if (unknowns.empty())
        return out;
    out.vertices = unknowns.size();
    out.creases = onto_crease_faces(x, faces, creased);
    // The faired vertices and the held ones around them (unsupported_relax_rings), but not the
    // mesh's boundary: the membranes' first, towards their faces' centroids (RelaxTarget), then
    // the thin plates'.
    std::vector<char> taken(faired.begin(), faired.end());
    for (const bool membranes : {true, false})
    {
        std::vector<std::uint32_t> relaxed;
        for (const std::uint32_t v : unknowns)
            if ((flat_fill[v] != 0) == membranes)
                relaxed.push_back(v);
        std::vector<std::uint32_t> ring_front = relaxed;
        for (std::size_t r = 0; r < unsupported_relax_rings && !ring_front.empty(); ++r)
        {
            std::vector<std::uint32_t> next;
            for (const std::uint32_t v : ring_front)
                for (const std::uint32_t w : ring(v))
                    if (taken[w] == 0 && rings.boundary[w] == 0)
                    {
                        taken[w] = 1;
                        next.push_back(w);
                    }
            relaxed.insert(relaxed.end(), next.begin(), next.end());
            ring_front = std::move(next);
        }
        std::sort(relaxed.begin(), relaxed.end());
        if (!membranes)
        {
            detail::relax_tangentially(x, faces, rings.offsets, rings.adjacent, relaxed,
                                       detail::faired_relax_rounds,
                                       detail::RelaxTarget::neighbours_mean);
            continue;
        }
        if (!relaxed.empty())
            detail::relax_membranes(
                x, faces, rings.offsets, rings.adjacent, relaxed,
                detail::depth_in_rings(rings.offsets, rings.adjacent, flat_fill));
    }
    for (const Found& f : found)
        for (std::size_t i = 0; i < f.before.size(); ++i)
            out.max_move = std::max(out.max_move, (x[f.members[i]] - f.before[i]).norm());
    return out;
}

} // namespace

RefineReport refine(MultiresMesh& mesh, const Field& field, const PointCloud& samples,
                    const RefineOptions& options)
{
    check_options(options);
    if (mesh.level_count() == 0)
        throw InvalidInput("refine: the hierarchy is empty");
    RefineReport report;
    report.stop_rule = options.stop_rule;
    if (samples.empty())
    {
        if (options.stop_rule != StopRule::Exact)
            throw InvalidInput("refine: no samples to measure the Hausdorff distance from");
        // Exactly to max_level with nothing to measure (a modeled surface).
        while (mesh.finest_level() < options.max_level)
            report.levels.push_back(refine_once(mesh, field, options));
        report.stop = RefineStop::LevelCap;
        return report;
    }
    // One k-d tree of the samples, for their sampling density and for the fairing's distances
    // from the vertices to them: the caller's, or one built here.
    const bool fair = options.stop_rule == StopRule::Automatic && options.fair_unsupported;
    if (options.sample_tree != nullptr &&
        (options.sample_tree->positions().data() != samples.positions.data() ||
         options.sample_tree->size() != samples.size()))
        throw InvalidInput("refine: the k-d tree given is not over the samples' positions");
    std::optional<KdTree> own_tree;
    const KdTree* sample_tree = options.sample_tree;
    if (sample_tree == nullptr && (!(options.sampling_density > 0.0) || fair))
        sample_tree = &own_tree.emplace(samples.positions);
    report.sampling_density = options.sampling_density > 0.0
                                  ? options.sampling_density
                                  : measure_sampling_density(*sample_tree, samples).median;
    if (!fair)
    {
        own_tree.reset();
        sample_tree = nullptr;
    }
    // Every level is measured from the same samples: sorted along the Morton curve once.
    const std::vector<std::uint32_t> order = spatial_order(samples.positions);
    const ProgressCallback distance_progress = [&](std::string_view, double fraction) {
        return !options.progress || options.progress("refine: distance", fraction);
    };
    // The finest level's faces, kept by the automatic stop from level to level.
    std::vector<Triangle> faces = mesh.faces(mesh.finest_level());
    Distances initial =
        distances_from(samples, mesh, faces, mesh.finest_level(), distance_progress, {}, order);
    report.initial_hausdorff = initial.hausdorff;
    report.initial_mean_distance = initial.mean;
    report.initial_robust_distance = initial.robust;
    report.initial_p90_distance = initial.p90;
    std::vector<std::uint32_t> nearest = std::move(initial.nearest);
    const bool automatic = options.stop_rule == StopRule::Automatic;
    if (automatic)
    {
        report.vertex_budget = options.vertex_budget > 0 ? options.vertex_budget : samples.size();
        report.field_residual = field_residual(field, samples, order);
        report.detail_threshold =
            std::max(options.detail_factor * report.field_residual, 1e-3 * report.sampling_density);
    }
    const long long chi = automatic ? euler_characteristic(mesh) : 0;
    const std::size_t start_level = mesh.finest_level();
    if (initial.hausdorff < report.sampling_density)
        report.paper_level = 0;
    double hausdorff = initial.hausdorff;
    // The automatic stop reads no distance from the samples: it measures a level once the next
    // one's stop test has run, so that a level which then ends on noise is measured once, after
    // its smoothing. `nearest` stays on the level below until then (its children bound the
    // searches).
    bool unmeasured = false;
    const auto measure = [&](bool children) {
        const auto start = std::chrono::steady_clock::now();
        Distances d = distances_from(samples, mesh, faces, mesh.finest_level(), distance_progress,
                                     {.faces = nearest, .children = children}, order);
        nearest = std::move(d.nearest);
        unmeasured = false;
        if (report.levels.empty())
        {
            report.initial_hausdorff = d.hausdorff;
            report.initial_mean_distance = d.mean;
            report.initial_robust_distance = d.robust;
            report.initial_p90_distance = d.p90;
            return;
        }
        RefineLevelStats& finest = report.levels.back();
        finest.hausdorff = d.hausdorff;
        finest.mean_distance = d.mean;
        finest.robust_distance = d.robust;
        finest.p90_distance = d.p90;
        finest.seconds +=
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        hausdorff = d.hausdorff;
        if (!report.paper_level && hausdorff < report.sampling_density)
            report.paper_level = finest.level - start_level;
    };
    while (true)
    {
        if (options.stop_rule == StopRule::Paper && hausdorff < report.sampling_density)
        {
            report.stop = RefineStop::BelowSamplingDensity;
            break;
        }
        if (mesh.finest_level() >= options.max_level)
        {
            report.stop = RefineStop::LevelCap;
            break;
        }
        if (automatic)
        {
            if (next_level_vertices(mesh, chi) > report.vertex_budget)
            {
                report.stop = RefineStop::VertexBudget;
                break;
            }
            const NextDetail next = next_detail(mesh, faces, field);
            const double detail = next.robust;
            const double previous = report.levels.empty() ? std::numeric_limits<double>::infinity()
                                    : report.levels.size() == 1
                                        ? report.initial_next_detail
                                        : *report.levels[report.levels.size() - 2].next_detail;
            if (report.levels.empty())
                report.initial_next_detail = detail;
            else
                report.levels.back().next_detail = detail;
            if (detail <= report.detail_threshold)
            {
                report.stop = RefineStop::SmallDetails;
                break;
            }
            if (detail < report.field_residual && detail > options.noise_decay * previous &&
                next.tail <= options.tail_factor * report.field_residual)
            {
                report.stop = RefineStop::NoisyDetails;
                break;
            }
        }
        if (automatic)
        {
            if (unmeasured)
                measure(true);
            report.levels.push_back(
                refine_level(mesh, field, options, nullptr, nullptr, {}, &faces));
            unmeasured = true;
            continue;
        }
        // A level dropped by the paper's rule leaves `nearest` on it; its rule stops then.
        RefineLevelStats stats = refine_level(mesh, field, options, &samples, &nearest, order);
        const double previous_hausdorff = hausdorff;
        hausdorff = *stats.hausdorff;
        if (!report.paper_level && hausdorff < report.sampling_density)
            report.paper_level = stats.level - start_level;
        if (options.stop_rule == StopRule::Paper && hausdorff >= report.sampling_density &&
            hausdorff > (1.0 - options.min_improvement) * previous_hausdorff)
        {
            mesh.truncate(mesh.finest_level() - 1);
            report.dropped = stats;
            report.stop = RefineStop::Stalled;
            break;
        }
        report.levels.push_back(stats);
    }
    bool moved = false;
    const bool denoise = report.stop == RefineStop::NoisyDetails && options.denoise_rounds > 0;
    // The finest level's vertex rings, for the fairing, the smoothing and the spikes (all of
    // them under the automatic stop only).
    const Rings rings = automatic ? vertex_rings(faces, mesh.vertex_count()) : Rings{};
    std::vector<char> faired(mesh.vertex_count(), 0);
    if (fair)
    {
        report.unsupported = fair_unsupported(mesh, faces, rings, samples, *sample_tree,
                                              report.sampling_density, faired);
        moved = report.unsupported.vertices > 0;
    }
    if (denoise)
    {
        report.denoise_rounds = options.denoise_rounds;
        report.denoise_max_move = denoise_finest(mesh, faces, rings, options.denoise_rounds,
                                                 report.field_residual, faired);
        moved = true;
    }
    if (automatic && options.fit_faces && !denoise)
    {
        const FaceFit fit = fit_faces(mesh, faces, rings, field, report.field_residual, faired);
        report.face_fit_vertices = fit.vertices;
        report.face_fit_max_move = fit.max_move;
        report.face_fit_median_move = fit.median_move;
        report.face_fit_probes = fit.probes;
        moved = moved || fit.vertices > 0;
    }
    if (automatic)
    {
        report.spikes = detail::despike(mesh.mutable_positions(), mesh.origin(), field,
                                        rings.offsets, rings.adjacent, rings.boundary);
        moved = moved || report.spikes > 0;
    }
    if (moved || unmeasured)
        measure(unmeasured);
    return report;
}

} // namespace pointform
