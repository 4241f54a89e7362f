// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/polygonize/marching_cubes.h"

#include "pointform/core/error.h"
#include "pointform/core/memory.h"
#include "pointform/core/parallel.h"
#include "pointform/geometry/mesh_topology.h"
#include "pointform/implicit/point_field.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <numeric>
#include <span>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

namespace pointform {

namespace {

// Grid coordinates are packed 20 bits per axis; an edge key adds 2 bits for its axis.
constexpr int coord_bits = 20;
constexpr std::int64_t max_cells = (std::int64_t{1} << coord_bits) - 2;
constexpr std::uint64_t coord_mask = (std::uint64_t{1} << coord_bits) - 1;

using Coord = std::array<std::int64_t, 3>;

std::uint64_t pack(const Coord& c)
{
    return static_cast<std::uint64_t>(c[0]) | (static_cast<std::uint64_t>(c[1]) << coord_bits) |
           (static_cast<std::uint64_t>(c[2]) << (2 * coord_bits));
}

Coord unpack(std::uint64_t key)
{
    return {static_cast<std::int64_t>(key & coord_mask),
            static_cast<std::int64_t>((key >> coord_bits) & coord_mask),
            static_cast<std::int64_t>((key >> (2 * coord_bits)) & coord_mask)};
}

// ---------------------------------------------------------------------------------------------
// The unit cube. Corner c has offset (c & 1, (c >> 1) & 1, (c >> 2) & 1). Edge e joins corner
// edge_base[e] to edge_base[e] + e_axis. Face f lists its corners counter-clockwise as seen from
// outside the cube, and face_edge[f][i] joins face corner i to face corner i + 1.

struct CubeTables
{
    std::array<int, 12> edge_base{};
    std::array<int, 12> edge_axis{};
    std::array<std::array<int, 8>, 8> edge_between{};
    std::array<std::array<int, 4>, 6> face_corner{};
    std::array<std::array<int, 4>, 6> face_edge{};
    std::array<int, 6> face_axis{};
    std::array<int, 6> face_side{};
    /// The two faces (axis · 2 + side) that contain edge e.
    std::array<std::array<int, 2>, 12> edge_face{};

    CubeTables()
    {
        int e = 0;
        for (auto& row : edge_between)
        {
            row.fill(-1);
        }
        for (int axis = 0; axis < 3; ++axis)
        {
            for (int c = 0; c < 8; ++c)
            {
                if ((c >> axis & 1) == 0)
                {
                    const int d = c | (1 << axis);
                    edge_base[static_cast<std::size_t>(e)] = c;
                    edge_axis[static_cast<std::size_t>(e)] = axis;
                    edge_between[static_cast<std::size_t>(c)][static_cast<std::size_t>(d)] = e;
                    const int b = (axis + 1) % 3;
                    const int c2 = (axis + 2) % 3;
                    edge_face[static_cast<std::size_t>(e)] = {2 * b + (c >> b & 1),
                                                              2 * c2 + (c >> c2 & 1)};
                    edge_between[static_cast<std::size_t>(d)][static_cast<std::size_t>(c)] = e;
                    ++e;
                }
            }
        }
        int f = 0;
        for (int axis = 0; axis < 3; ++axis)
        {
            const int b = (axis + 1) % 3;
            const int c = (axis + 2) % 3;
            for (int side = 0; side < 2; ++side)
            {
                // (b, c) = (0,0), (1,0), (1,1), (0,1) turns counter-clockwise about e_b × e_c =
                // e_a, i.e. as seen from outside the face on the side = 1 face; reversed on side =
                // 0.
                constexpr std::array<std::array<int, 2>, 4> square = {
                    {{0, 0}, {1, 0}, {1, 1}, {0, 1}}};
                auto& corners = face_corner[static_cast<std::size_t>(f)];
                for (std::size_t i = 0; i < 4; ++i)
                {
                    const auto& uv = side == 1 ? square[i] : square[3 - i];
                    corners[i] = (side << axis) | (uv[0] << b) | (uv[1] << c);
                }
                for (std::size_t i = 0; i < 4; ++i)
                {
                    face_edge[static_cast<std::size_t>(f)][i] =
                        edge_between[static_cast<std::size_t>(corners[i])]
                                    [static_cast<std::size_t>(corners[(i + 1) % 4])];
                }
                face_axis[static_cast<std::size_t>(f)] = axis;
                face_side[static_cast<std::size_t>(f)] = side;
                ++f;
            }
        }
    }
};

const CubeTables& cube()
{
    static const CubeTables tables;
    return tables;
}

Coord corner_of(const Coord& cell, int c)
{
    return {cell[0] + (c & 1), cell[1] + (c >> 1 & 1), cell[2] + (c >> 2 & 1)};
}

std::uint64_t edge_key(const Coord& base, int axis)
{
    return pack(base) << 2 | static_cast<std::uint64_t>(axis);
}

/// Appends the triangles of one cell, as global edge keys, counter-clockwise seen from f > 0.
/// `value` are the eight corner values (all defined). The zero set draws segments on the six
/// faces, each directed with the inside on its right as seen from outside the cube; a face with
/// two diagonal inside corners is split by the asymptotic decider. Every crossed edge starts one
/// segment and ends another, so the segments close into loops, which are fanned into triangles.
/// The key of a cell's own vertex, which triangulate_cell() adds where a loop cannot be cut into
/// triangles without a chord on an upper face: axis 3 after the cell's lowest corner. It lies on
/// the zero crossing between two of the cell's corners of opposite sign (cell_vertex_corners).
std::uint64_t cell_vertex_key(const Coord& cell)
{
    return pack(cell) << 2 | 3U;
}

/// The two corners whose segment holds a cell's own vertex: the first of the cube's four
/// diagonals (corner c to 7 − c, c = 0 … 3) with one end inside, else the first pair (c, d), c < d,
/// in order, with one end inside. \pre the corners are not all on one side
std::pair<int, int> cell_vertex_corners(const std::array<float, 8>& value)
{
    const auto inside = [&](int c) {
        return value[static_cast<std::size_t>(c)] < 0.0F;
    };
    for (int c = 0; c < 4; ++c)
    {
        if (inside(c) != inside(7 - c))
        {
            return {c, 7 - c};
        }
    }
    for (int c = 0; c < 8; ++c)
    {
        for (int d = c + 1; d < 8; ++d)
        {
            if (inside(c) != inside(d))
            {
                return {c, d};
            }
        }
    }
    return {0, 7};
}

/// Costs of a loop's chord on a face of the cube (triangulate_cell): on a lower face (its cell
/// alone draws it), on an upper face (the neighbour across may draw it too).
constexpr int lower_face_chord = 1;
constexpr int upper_face_chord = 1000;

void triangulate_cell(const Coord& cell, const std::array<float, 8>& value,
                      std::vector<std::uint64_t>& out)
{
    const CubeTables& t = cube();
    std::array<int, 12> next{};
    next.fill(-1);
    auto inside = [&](int c) {
        return value[static_cast<std::size_t>(c)] < 0.0F;
    };
    for (std::size_t f = 0; f < 6; ++f)
    {
        const auto& q = t.face_corner[f];
        const auto& fe = t.face_edge[f];
        std::array<bool, 4> in{};
        int inside_count = 0;
        for (std::size_t i = 0; i < 4; ++i)
        {
            in[i] = inside(q[i]);
            inside_count += in[i] ? 1 : 0;
        }
        if (inside_count == 0 || inside_count == 4)
        {
            continue;
        }
        if (inside_count == 2 && in[0] == in[2])
        {
            // Ambiguous face: the bilinear interpolant's saddle decides whether the two inside
            // corners are joined (saddle inside) or cut off separately.
            const double v0 = value[static_cast<std::size_t>(q[0])];
            const double v1 = value[static_cast<std::size_t>(q[1])];
            const double v2 = value[static_cast<std::size_t>(q[2])];
            const double v3 = value[static_cast<std::size_t>(q[3])];
            const double denominator = v0 + v2 - v1 - v3;
            const double saddle = denominator != 0.0 ? (v0 * v2 - v1 * v3) / denominator : 0.0;
            const bool cut_inside = saddle >= 0.0;
            for (std::size_t i = 0; i < 4; ++i)
            {
                if (in[i] != cut_inside)
                {
                    continue;
                }
                const int before = fe[(i + 3) % 4];
                const int after = fe[i];
                // Inside corner: before → after; outside corner: after → before.
                if (in[i])
                {
                    next[static_cast<std::size_t>(before)] = after;
                }
                else
                {
                    next[static_cast<std::size_t>(after)] = before;
                }
            }
            continue;
        }
        // One segment: from the crossing entering the inside (walking counter-clockwise) to the
        // crossing leaving it.
        int enter = -1;
        int leave = -1;
        for (std::size_t i = 0; i < 4; ++i)
        {
            const bool a = in[i];
            const bool b = in[(i + 1) % 4];
            if (!a && b)
            {
                enter = fe[i];
            }
            else if (a && !b)
            {
                leave = fe[i];
            }
        }
        next[static_cast<std::size_t>(enter)] = leave;
    }

    std::array<bool, 12> used{};
    std::array<int, 12> loop{};
    for (int start = 0; start < 12; ++start)
    {
        if (next[static_cast<std::size_t>(start)] < 0 || used[static_cast<std::size_t>(start)])
        {
            continue;
        }
        std::size_t n = 0;
        for (int e = start; !used[static_cast<std::size_t>(e)];
             e = next[static_cast<std::size_t>(e)])
        {
            used[static_cast<std::size_t>(e)] = true;
            loop[n++] = e;
        }
        auto key = [&](int e) {
            const auto ue = static_cast<std::size_t>(e);
            return edge_key(corner_of(cell, t.edge_base[ue]), t.edge_axis[ue]);
        };
        // A chord between two vertices on one face of the cube (crossings of an ambiguous face)
        // could be drawn by the cell across that face too, giving an edge with four triangles.
        // The loop is triangulated by dynamic programming over its chords: none on a face if
        // that is possible; else chords on the cube's lower faces only (−x, −y, −z), which the
        // neighbour across them, whose upper faces they are, never draws; an upper face's chord
        // only where nothing else triangulates the loop (counted by the caller's check).
        auto emit = [&](int a, int b, int c) {
            out.push_back(key(a));
            out.push_back(key(b));
            out.push_back(key(c));
        };
        auto chord_cost = [&](std::size_t i, std::size_t j) {
            if (j == i + 1 || (i == 0 && j == n - 1))
            {
                return 0; // a side of the loop, not a chord
            }
            const auto& fa = t.edge_face[static_cast<std::size_t>(loop[i])];
            const auto& fb = t.edge_face[static_cast<std::size_t>(loop[j])];
            int cost = 0;
            for (const int a : fa)
            {
                for (const int b : fb)
                {
                    if (a == b)
                    {
                        cost = std::max(cost, (a & 1) != 0 ? upper_face_chord : lower_face_chord);
                    }
                }
            }
            return cost;
        };
        // best[i][j]: least cost of triangulating loop[i..j] closed by the chord (i, j);
        // split[i][j]: its apex k (the first of the least).
        std::array<std::array<int, 12>, 12> best{};
        std::array<std::array<std::uint8_t, 12>, 12> split{};
        for (std::size_t length = 2; length < n; ++length)
        {
            for (std::size_t i = 0; i + length < n; ++i)
            {
                const std::size_t j = i + length;
                int least = std::numeric_limits<int>::max();
                for (std::size_t k = i + 1; k < j; ++k)
                {
                    const int cost = best[i][k] + best[k][j] + chord_cost(i, k) + chord_cost(k, j);
                    if (cost < least)
                    {
                        least = cost;
                        split[i][j] = static_cast<std::uint8_t>(k);
                    }
                }
                best[i][j] = least;
            }
        }
        if (n > 3 && best[0][n - 1] >= upper_face_chord)
        {
            // Every triangulation of the loop (a tunnel through an ambiguous upper face) draws a
            // chord the neighbour may draw too: fan it around a vertex of its own inside the
            // cell instead (on a diagonal of the cube, see cell_vertex_key).
            const std::uint64_t centre = cell_vertex_key(cell);
            for (std::size_t i = 0; i < n; ++i)
            {
                out.push_back(key(loop[i]));
                out.push_back(key(loop[(i + 1) % n]));
                out.push_back(centre);
            }
        }
        else if (n >= 3)
        {
            std::array<std::pair<std::uint8_t, std::uint8_t>, 12> pending{};
            std::size_t top = 0;
            pending[top++] = {0, static_cast<std::uint8_t>(n - 1)};
            while (top > 0)
            {
                const auto [i, j] = pending[--top];
                if (j < i + 2)
                {
                    continue;
                }
                const std::uint8_t k = split[i][j];
                emit(loop[i], loop[k], loop[j]);
                pending[top++] = {i, k};
                pending[top++] = {k, j};
            }
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Sparse storage of corner values and visited cells in blocks of 8³ grid points.

constexpr int block_shift = 3;
constexpr int block_side = 1 << block_shift;
constexpr std::size_t block_volume = block_side * block_side * block_side;

enum : std::uint8_t
{
    evaluated = 1,
    defined = 2,
    visited = 4,
    /// Evaluated within a range (Field::evaluate_within) and found beyond it: only the sign
    /// is known until the corner is evaluated exactly.
    bounded = 8,
};

struct Block
{
    std::array<float, block_volume> value{};
    std::array<std::uint8_t, block_volume> state{};
};

class SparseGrid
{
public:
    struct Slot
    {
        float* value = nullptr;
        std::uint8_t* state = nullptr;
    };

    /// The slot of grid point c, creating its block (not thread-safe).
    Slot get_or_create(const Coord& c)
    {
        const std::uint64_t key = block_key(c);
        auto [it, inserted] = index_.try_emplace(key, static_cast<std::uint32_t>(blocks_.size()));
        if (inserted)
        {
            blocks_.push_back(std::make_unique<Block>());
        }
        Block& b = *blocks_[it->second];
        const std::size_t i = local(c);
        return {&b.value[i], &b.state[i]};
    }

    /// The slot of grid point c, or null pointers if its block does not exist (thread-safe
    /// while nobody creates blocks).
    [[nodiscard]] Slot find(const Coord& c) const
    {
        const auto it = index_.find(block_key(c));
        if (it == index_.end())
        {
            return {};
        }
        Block& b = *blocks_[it->second];
        const std::size_t i = local(c);
        return {&b.value[i], &b.state[i]};
    }

    /// The value stored at grid point c, which must have been evaluated (0 if not).
    [[nodiscard]] float value_at(const Coord& c) const
    {
        const Slot s = find(c);
        PF_ASSERT(s.value != nullptr);
        return s.value != nullptr ? *s.value : 0.0F;
    }

private:
    static std::uint64_t block_key(const Coord& c)
    {
        return pack({c[0] >> block_shift, c[1] >> block_shift, c[2] >> block_shift});
    }
    static std::size_t local(const Coord& c)
    {
        constexpr std::int64_t m = block_side - 1;
        return static_cast<std::size_t>((c[0] & m) | (c[1] & m) << block_shift |
                                        (c[2] & m) << (2 * block_shift));
    }

    std::unordered_map<std::uint64_t, std::uint32_t> index_;
    std::vector<std::unique_ptr<Block>> blocks_;
};

Vec3d grid_point(const CellGrid& grid, const Coord& c)
{
    return grid.origin + grid.cell * Vec3d(static_cast<double>(c[0]), static_cast<double>(c[1]),
                                           static_cast<double>(c[2]));
}

bool in_grid(const CellGrid& grid, const Coord& c)
{
    for (std::size_t a = 0; a < 3; ++a)
    {
        if (c[a] < 0 || c[a] >= grid.cells[a])
        {
            return false;
        }
    }
    return true;
}

void sort_unique(std::vector<std::uint64_t>& keys)
{
    // Equal keys are equal values: any sort gives the same sequence.
    parallel_sort(keys);
    keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
}

} // namespace

CellGrid grid_over(const Aabb& box, double cell)
{
    if (box.is_empty() || !box.min.allFinite() || !box.max.allFinite())
    {
        throw InvalidInput("marching cubes: the region to polygonize is empty or not finite");
    }
    if (!(cell > 0.0) || !std::isfinite(cell))
    {
        throw InvalidInput("marching cubes: the cell size must be positive");
    }
    CellGrid grid;
    grid.cell = cell;
    grid.origin = box.min - Vec3d::Constant(cell);
    for (std::size_t a = 0; a < 3; ++a)
    {
        const double extent =
            (box.max[static_cast<Eigen::Index>(a)] - box.min[static_cast<Eigen::Index>(a)]) / cell;
        if (extent > static_cast<double>(max_cells - 2))
        {
            throw InvalidInput("marching cubes: " + std::to_string(std::llround(extent)) +
                               " cells along an axis is more than the grid supports (" +
                               std::to_string(max_cells - 2) + "); use a larger cell size");
        }
        grid.cells[a] = static_cast<std::int64_t>(std::ceil(extent)) + 2;
    }
    return grid;
}

double cell_for_resolution(const Aabb& box, int resolution)
{
    if (resolution < 2)
    {
        throw InvalidInput("marching cubes: the resolution must be at least 2 cells");
    }
    if (box.is_empty() || !(box.size().maxCoeff() > 0.0))
    {
        throw InvalidInput("marching cubes: the region to polygonize is empty");
    }
    return box.size().maxCoeff() / resolution;
}

double default_cell_size(const PointField& field)
{
    return 0.4 * field.median_radius();
}

double estimate_marching_cubes_faces(double surface_area, double cell)
{
    return 3.0 * surface_area / (cell * cell);
}

IntermediateGrid intermediate_grid(const PointField& field, double cell, double max_faces)
{
    if (!(cell > 0.0) || !std::isfinite(cell) || !(max_faces > 0.0) || !std::isfinite(max_faces))
    {
        throw InvalidInput("intermediate grid: the cell and the face limit must be positive");
    }
    IntermediateGrid out;
    out.estimated_faces = estimate_marching_cubes_faces(field.estimated_area(), cell);
    out.cell = cell;
    if (out.estimated_faces > max_faces)
    {
        out.coarsening = std::sqrt(out.estimated_faces / max_faces);
        out.cell = cell * out.coarsening;
        out.min_defined_corners = 1;
    }
    return out;
}

double choose_cell_size(const PointField& field, const Aabb& bounds, int resolution, double cell)
{
    if (resolution > 0)
        return cell_for_resolution(bounds, resolution);
    return cell > 0.0 ? cell : default_cell_size(field);
}

double estimate_marching_cubes_bytes(double surface_area, double cell)
{
    // A surface of area A cuts about 1.5 A / h² cells (the mean of |nx| + |ny| + |nz|); each
    // costs about 400 bytes: its share of the 8³ corner blocks (~120), wave keys (~40), two
    // triangles as edge keys (~50), 1.5 vertices with their refinement state (~190).
    constexpr double bytes_per_cell = 400.0;
    return bytes_per_cell * 1.5 * surface_area / (cell * cell);
}

double estimate_marching_cubes_bytes(const PointField& field, double cell)
{
    return estimate_marching_cubes_bytes(field.estimated_area(), cell);
}

void check_marching_cubes_memory(const PointField& field, double cell)
{
    char what[96];
    std::snprintf(what, sizeof what, "marching cubes at a cell of %g", cell);
    check_memory(estimate_marching_cubes_bytes(field, cell), what,
                 "use a larger cell or a lower resolution");
}

namespace {

/// Stores a corner's sample; `bounded` where its value is beyond ±`range`.
void store_sample(const FieldSample& sample, double range, const SparseGrid::Slot& slot)
{
    *slot.value = static_cast<float>(sample.value);
    *slot.state |= static_cast<std::uint8_t>(evaluated | (sample.defined ? defined : 0) |
                                             (std::abs(sample.value) <= range ? 0 : bounded));
}

/// Field::evaluate_within() with the range ±`range` for every point.
void evaluate_within(const Field& field, double range, std::span<const Vec3d> points,
                     std::span<FieldSample> samples)
{
    const std::vector<double> lo(points.size(), -range);
    const std::vector<double> hi(points.size(), range);
    field.evaluate_within(points, lo, hi, samples);
}

/// `evaluate` (a batch evaluation) at points[at[i]] for each i: the samples, in the order of at.
template <class Evaluate>
std::vector<FieldSample> evaluate_subset(std::span<const Vec3d> points,
                                         std::span<const std::size_t> at, Evaluate&& evaluate)
{
    std::vector<Vec3d> gathered(at.size());
    for (std::size_t i = 0; i < at.size(); ++i)
    {
        gathered[i] = points[at[i]];
    }
    std::vector<FieldSample> samples(at.size());
    std::forward<Evaluate>(evaluate)(std::span<const Vec3d>(gathered), std::span(samples));
    return samples;
}

/// The field's samples at `points`, exact where the value is within ±`range` (asked with
/// Field::evaluate_within) and beyond it (asked again exactly, which a distance-like field
/// near its surface never needs).
void evaluate_near_zero(const Field& field, double range, std::span<const Vec3d> points,
                        std::span<FieldSample> samples)
{
    evaluate_within(field, range, points, samples);
    std::vector<std::size_t> beyond;
    for (std::size_t i = 0; i < samples.size(); ++i)
    {
        if (!(std::abs(samples[i].value) <= range))
        {
            beyond.push_back(i);
        }
    }
    if (beyond.empty())
    {
        return;
    }
    const std::vector<FieldSample> exact = evaluate_subset(
        points, beyond,
        [&](std::span<const Vec3d> at, std::span<FieldSample> out) { field.evaluate(at, out); });
    for (std::size_t j = 0; j < beyond.size(); ++j)
    {
        samples[beyond[j]] = exact[j];
    }
}

/// Twice the area of face f on the stored (float32) positions, in the mesh's units².
double double_area(const TriMesh& mesh, const Triangle& t)
{
    const Vec3d a = mesh.vertices.positions[t[0]].cast<double>();
    const Vec3d b = mesh.vertices.positions[t[1]].cast<double>();
    const Vec3d c = mesh.vertices.positions[t[2]].cast<double>();
    return (b - a).cross(c - a).norm();
}

std::uint64_t edge_key(std::uint32_t from, std::uint32_t to)
{
    return static_cast<std::uint64_t>(from) << 32 | to;
}

/// Makes every triangle whose stored positions have (next to) zero area whole again, keeping the
/// surface closed: its corner w lies on its opposite edge (u, v), so flipping (u, v) in the
/// quad it forms with the neighbour (v, u, d) gives (u, d, w) and (d, v, w), which tile that
/// neighbour exactly (the same surface, no new overlap). A flip that would duplicate an edge
/// or leave a zero-area triangle is not made, and the triangle is kept.
void repair_degenerate_triangles(TriMesh& mesh, double cell, MarchingCubesStats& stats)
{
    const double min_double_area = 1e-12 * cell * cell;
    std::vector<std::uint32_t> degenerate;
    for (std::size_t f = 0; f < mesh.triangles.size(); ++f)
    {
        if (!(double_area(mesh, mesh.triangles[f]) > min_double_area))
        {
            degenerate.push_back(static_cast<std::uint32_t>(f));
        }
    }
    stats.degenerate_triangles = degenerate.size();
    if (degenerate.empty())
    {
        return;
    }
    // Directed edge -> face, for the faces near the degenerate ones.
    std::unordered_map<std::uint64_t, std::uint32_t> face_of;
    face_of.reserve(3 * mesh.triangles.size());
    for (std::size_t f = 0; f < mesh.triangles.size(); ++f)
    {
        const Triangle& t = mesh.triangles[f];
        for (std::size_t j = 0; j < 3; ++j)
        {
            face_of[edge_key(t[j], t[(j + 1) % 3])] = static_cast<std::uint32_t>(f);
        }
    }
    auto position = [&](std::uint32_t v) {
        return mesh.vertices.positions[v].cast<double>();
    };
    for (const std::uint32_t f : degenerate)
    {
        const Triangle t = mesh.triangles[f];
        if (double_area(mesh, t) > min_double_area)
        {
            continue; // an earlier flip already made it whole
        }
        // w: the corner between the other two.
        std::size_t mid = 0;
        double best = std::numeric_limits<double>::infinity();
        for (std::size_t j = 0; j < 3; ++j)
        {
            const Vec3d m = position(t[j]);
            const double d = (position(t[(j + 1) % 3]) - m).dot(position(t[(j + 2) % 3]) - m);
            if (d < best)
            {
                best = d;
                mid = j;
            }
        }
        const std::uint32_t w = t[mid];
        const std::uint32_t u = t[(mid + 1) % 3];
        const std::uint32_t v = t[(mid + 2) % 3];
        const auto across = face_of.find(edge_key(v, u));
        if (across == face_of.end())
        {
            ++stats.degenerate_kept;
            continue;
        }
        const std::uint32_t g = across->second;
        const Triangle& n = mesh.triangles[g];
        std::uint32_t d = n[0];
        for (const std::uint32_t c : n)
        {
            if (c != u && c != v)
            {
                d = c;
            }
        }
        const Triangle first = {u, d, w};
        const Triangle second = {d, v, w};
        if (d == w || face_of.contains(edge_key(w, d)) || face_of.contains(edge_key(d, w)) ||
            !(double_area(mesh, first) > min_double_area) ||
            !(double_area(mesh, second) > min_double_area))
        {
            ++stats.degenerate_kept;
            continue;
        }
        for (const Triangle& old : {t, n})
        {
            for (std::size_t j = 0; j < 3; ++j)
            {
                face_of.erase(edge_key(old[j], old[(j + 1) % 3]));
            }
        }
        mesh.triangles[f] = first;
        mesh.triangles[g] = second;
        for (const std::uint32_t h : {f, g})
        {
            const Triangle& now = mesh.triangles[h];
            for (std::size_t j = 0; j < 3; ++j)
            {
                face_of[edge_key(now[j], now[(j + 1) % 3])] = h;
            }
        }
    }
}

} // namespace

MarchingCubesResult marching_cubes(const Field& field, const CellGrid& grid,
                                   const MarchingCubesOptions& options)
{
    // Corner values within this of zero are asked exactly (Field::evaluate_within): two cell
    // diagonals, beyond which a distance-like field cannot change sign within a cell.
    const double exact_range = 2.0 * std::sqrt(3.0) * grid.cell;
    if (!(grid.cell > 0.0) || grid.cells[0] < 1 || grid.cells[1] < 1 || grid.cells[2] < 1 ||
        grid.cells[0] > max_cells || grid.cells[1] > max_cells || grid.cells[2] > max_cells)
    {
        throw InvalidInput("marching cubes: invalid grid");
    }
    MarchingCubesResult result;
    MarchingCubesStats& stats = result.stats;
    SparseGrid store;

    // Seeds: the cells that contain the field's seeds; or, without seeds, every cell.
    std::vector<std::uint64_t> frontier;
    {
        std::vector<Vec3d> seeds;
        field.append_seeds(seeds);
        if (!seeds.empty())
        {
            frontier.reserve(seeds.size());
            for (const Vec3d& s : seeds)
            {
                const Vec3d g = (s - grid.origin) / grid.cell;
                if (!g.allFinite())
                {
                    continue;
                }
                const Coord c = {static_cast<std::int64_t>(std::floor(g.x())),
                                 static_cast<std::int64_t>(std::floor(g.y())),
                                 static_cast<std::int64_t>(std::floor(g.z()))};
                if (in_grid(grid, c))
                {
                    frontier.push_back(pack(c));
                }
            }
        }
        else
        {
            stats.dense = true;
            const double total = static_cast<double>(grid.cells[0]) *
                                 static_cast<double>(grid.cells[1]) *
                                 static_cast<double>(grid.cells[2]);
            if (total > static_cast<double>(std::int64_t{1} << 27))
            {
                throw InvalidInput(
                    "marching cubes: the field gives no seed points and a dense "
                    "sweep of " +
                    std::to_string(std::llround(total)) +
                    " cells is too large; use a coarser grid");
            }
            for (std::int64_t k = 0; k < grid.cells[2]; ++k)
            {
                for (std::int64_t j = 0; j < grid.cells[1]; ++j)
                {
                    for (std::int64_t i = 0; i < grid.cells[0]; ++i)
                    {
                        frontier.push_back(pack({i, j, k}));
                    }
                }
            }
        }
        sort_unique(frontier);
    }

    if (options.min_defined_corners < 1 || options.min_defined_corners > 8)
    {
        throw InvalidInput("marching cubes: min_defined_corners must be 1 to 8, not " +
                           std::to_string(options.min_defined_corners));
    }
    const int min_defined = options.min_defined_corners;
    ProgressReporter progress(options.progress, "marching cubes");
    std::vector<std::uint64_t> surface_cells;
    std::vector<Vec3d> points;
    std::vector<FieldSample> samples;
    const CubeTables& t = cube();

    for (bool first_wave = true; !frontier.empty(); first_wave = false)
    {
        // Mark the wave visited and collect the corners it still needs.
        std::vector<std::uint64_t> wave;
        wave.reserve(frontier.size());
        std::vector<std::uint64_t> needed;
        for (const std::uint64_t key : frontier)
        {
            const Coord cell = unpack(key);
            const SparseGrid::Slot slot = store.get_or_create(cell);
            if ((*slot.state & visited) != 0)
            {
                continue;
            }
            *slot.state |= visited;
            wave.push_back(key);
            for (int c = 0; c < 8; ++c)
            {
                const Coord corner = corner_of(cell, c);
                const SparseGrid::Slot s = store.find(corner);
                if (s.state == nullptr || (*s.state & evaluated) == 0)
                {
                    needed.push_back(pack(corner));
                }
            }
        }
        sort_unique(needed);
        points.resize(needed.size());
        samples.resize(needed.size());
        for (std::size_t i = 0; i < needed.size(); ++i)
        {
            points[i] = grid_point(grid, unpack(needed[i]));
        }
        // Corners only need their sign unless they are near zero: far from the surface a
        // composite field may answer from bounds (a scan far from where it decides the result).
        // The corners of cells that the surface crosses, and of the first wave's (whose
        // `defined` flags decide where the search starts), are then evaluated exactly, so the
        // mesh is the one that exact values give.
        evaluate_within(field, exact_range, points, samples);
        stats.field_evaluations += needed.size();
        for (std::size_t i = 0; i < needed.size(); ++i)
        {
            const SparseGrid::Slot s = store.get_or_create(unpack(needed[i]));
            store_sample(samples[i], exact_range, s);
        }
        {
            std::vector<std::uint64_t> inexact = parallel_collect<std::uint64_t>(
                wave.size(), 4096,
                [&](std::size_t begin, std::size_t end, std::vector<std::uint64_t>& out) {
                    for (std::size_t w = begin; w < end; ++w)
                    {
                        const Coord cell = unpack(wave[w]);
                        int mask = 0;
                        bool any_bounded = false;
                        std::array<std::uint8_t, 8> state{};
                        for (int c = 0; c < 8; ++c)
                        {
                            const SparseGrid::Slot s = store.find(corner_of(cell, c));
                            if (s.value != nullptr)
                            {
                                mask |= (*s.value < 0.0F ? 1 : 0) << c;
                                state[static_cast<std::size_t>(c)] = *s.state;
                                any_bounded = any_bounded || (*s.state & bounded) != 0;
                            }
                        }
                        if (!any_bounded || (!first_wave && (mask == 0 || mask == 255)))
                        {
                            continue;
                        }
                        for (int c = 0; c < 8; ++c)
                        {
                            if ((state[static_cast<std::size_t>(c)] & bounded) != 0)
                            {
                                out.push_back(pack(corner_of(cell, c)));
                            }
                        }
                    }
                });
            sort_unique(inexact);
            points.resize(inexact.size());
            samples.resize(inexact.size());
            for (std::size_t i = 0; i < inexact.size(); ++i)
            {
                points[i] = grid_point(grid, unpack(inexact[i]));
            }
            field.evaluate(points, samples);
            stats.field_evaluations += inexact.size();
            for (std::size_t i = 0; i < inexact.size(); ++i)
            {
                const SparseGrid::Slot s = store.get_or_create(unpack(inexact[i]));
                *s.state = static_cast<std::uint8_t>(*s.state & visited);
                store_sample(samples[i], std::numeric_limits<double>::infinity(), s);
            }
        }
        stats.cells_visited += wave.size();

        // Classify the wave's cells; a surface cell passes the surface on to the neighbours
        // across each face that the zero set crosses.
        struct Outcome
        {
            std::uint64_t key;
            bool surface;
        };
        std::size_t undefined_here = 0;
        std::vector<std::size_t> undefined_per_block((wave.size() + 4095) / 4096, 0);
        const std::vector<Outcome> outcomes = parallel_collect<Outcome>(
            wave.size(), 4096, [&](std::size_t begin, std::size_t end, std::vector<Outcome>& out) {
                std::size_t undefined_count = 0;
                for (std::size_t w = begin; w < end; ++w)
                {
                    const Coord cell = unpack(wave[w]);
                    int mask = 0;
                    int defined_corners = 0;
                    for (int c = 0; c < 8; ++c)
                    {
                        const SparseGrid::Slot s = store.find(corner_of(cell, c));
                        PF_ASSERT(s.state != nullptr);
                        if (s.state == nullptr)
                            continue;
                        defined_corners += (*s.state & defined) != 0 ? 1 : 0;
                        mask |= (*s.value < 0.0F ? 1 : 0) << c;
                    }
                    const bool all_defined = defined_corners == 8;
                    if (mask == 0 || mask == 255)
                    {
                        // A seed whose cell the surface only touches (e.g. at an extreme
                        // point): try the six neighbours once.
                        if (first_wave && all_defined)
                        {
                            for (std::size_t f = 0; f < 6; ++f)
                            {
                                Coord neighbour = cell;
                                neighbour[static_cast<std::size_t>(t.face_axis[f])] +=
                                    t.face_side[f] == 1 ? 1 : -1;
                                if (in_grid(grid, neighbour))
                                {
                                    out.push_back({pack(neighbour), false});
                                }
                            }
                        }
                        continue;
                    }
                    if (defined_corners < min_defined)
                    {
                        ++undefined_count;
                        continue;
                    }
                    out.push_back({wave[w], true});
                    for (std::size_t f = 0; f < 6; ++f)
                    {
                        int face_inside = 0;
                        for (const int c : t.face_corner[f])
                        {
                            face_inside += mask >> c & 1;
                        }
                        if (face_inside == 0 || face_inside == 4)
                        {
                            continue;
                        }
                        Coord neighbour = cell;
                        const auto axis = static_cast<std::size_t>(t.face_axis[f]);
                        neighbour[axis] += t.face_side[f] == 1 ? 1 : -1;
                        if (in_grid(grid, neighbour))
                        {
                            out.push_back({pack(neighbour), false});
                        }
                    }
                }
                undefined_per_block[begin / 4096] = undefined_count;
            });
        for (const std::size_t u : undefined_per_block)
        {
            undefined_here += u;
        }
        stats.undefined_cells += undefined_here;

        frontier.clear();
        for (const Outcome& o : outcomes)
        {
            if (o.surface)
            {
                surface_cells.push_back(o.key);
            }
            else
            {
                const SparseGrid::Slot s = store.find(unpack(o.key));
                if (s.state == nullptr || (*s.state & visited) == 0)
                {
                    frontier.push_back(o.key);
                }
            }
        }
        sort_unique(frontier);
        progress.update(static_cast<double>(stats.cells_visited),
                        static_cast<double>(stats.cells_visited + frontier.size()));
    }
    sort_unique(surface_cells);
    stats.surface_cells = surface_cells.size();

    // Triangles as global edge keys, cell by cell in key order.
    std::vector<std::uint64_t> corners_of_triangles = parallel_collect<std::uint64_t>(
        surface_cells.size(), 2048,
        [&](std::size_t begin, std::size_t end, std::vector<std::uint64_t>& out) {
            std::array<float, 8> value{};
            for (std::size_t s = begin; s < end; ++s)
            {
                const Coord cell = unpack(surface_cells[s]);
                for (int c = 0; c < 8; ++c)
                {
                    const SparseGrid::Slot slot = store.find(corner_of(cell, c));
                    PF_ASSERT(slot.value != nullptr);
                    value[static_cast<std::size_t>(c)] = slot.value == nullptr ? 0.0F : *slot.value;
                }
                triangulate_cell(cell, value, out);
            }
        });

    // One vertex per crossed edge, in key order.
    std::vector<std::uint64_t> edges = corners_of_triangles;
    sort_unique(edges);
    const std::size_t nv = edges.size();

    // Vertex positions: linear interpolation, then regula falsi (Illinois) along the edge.
    std::vector<Vec3d> a_point(nv);
    std::vector<Vec3d> b_point(nv);
    std::vector<double> lo_t(nv, 0.0);
    std::vector<double> hi_t(nv, 1.0);
    std::vector<double> lo_f(nv);
    std::vector<double> hi_f(nv);
    std::vector<double> vertex_t(nv);
    parallel_blocks(nv, 4096, [&](std::size_t begin, std::size_t end) {
        for (std::size_t v = begin; v < end; ++v)
        {
            const Coord base = unpack(edges[v] >> 2);
            const auto axis = static_cast<std::size_t>(edges[v] & 3);
            Coord tip = base;
            if (axis == 3)
            {
                // A cell's own vertex: on the segment between two of its corners.
                std::array<float, 8> value{};
                for (int c = 0; c < 8; ++c)
                {
                    value[static_cast<std::size_t>(c)] = store.value_at(corner_of(base, c));
                }
                const auto [from, to] = cell_vertex_corners(value);
                const Coord a = corner_of(base, from);
                const Coord b = corner_of(base, to);
                a_point[v] = grid_point(grid, a);
                b_point[v] = grid_point(grid, b);
                lo_f[v] = value[static_cast<std::size_t>(from)];
                hi_f[v] = value[static_cast<std::size_t>(to)];
                continue;
            }
            tip[axis] += 1;
            a_point[v] = grid_point(grid, base);
            b_point[v] = grid_point(grid, tip);
            lo_f[v] = store.value_at(base);
            hi_f[v] = store.value_at(tip);
        }
    });
    stats.cell_vertices += static_cast<std::size_t>(std::count_if(
        edges.begin(), edges.end(), [](std::uint64_t key) { return (key & 3) == 3; }));
    auto interpolate = [&](std::size_t v) {
        const double denominator = lo_f[v] - hi_f[v];
        const double s = denominator != 0.0 ? lo_f[v] / denominator : 0.5;
        return lo_t[v] + std::clamp(s, 0.0, 1.0) * (hi_t[v] - lo_t[v]);
    };
    for (std::size_t v = 0; v < nv; ++v)
    {
        vertex_t[v] = interpolate(v);
    }
    std::vector<int> last_side(nv, 0);
    // A vertex whose value is within `settled_value` of zero (far below the float resolution of
    // its position) stays where it was evaluated, and keeps that sample's gradient as its normal.
    const double settled_value = 1e-7 * grid.cell;
    std::vector<std::uint8_t> settled(nv, 0);
    // Each vertex's normal: a settled vertex's from its last sample, the others' evaluated last.
    std::vector<Vec3d> vertex_gradient(nv, Vec3d::Zero());
    std::vector<std::size_t> active(nv);
    std::iota(active.begin(), active.end(), std::size_t{0});
    for (int step = 0; step < options.refine_steps && !active.empty(); ++step)
    {
        const std::size_t na = active.size();
        points.resize(na);
        samples.resize(na);
        for (std::size_t i = 0; i < na; ++i)
        {
            const std::size_t v = active[i];
            points[i] = a_point[v] + vertex_t[v] * (b_point[v] - a_point[v]);
        }
        evaluate_near_zero(field, exact_range, points, samples);
        stats.field_evaluations += na;
        std::size_t kept = 0;
        for (std::size_t i = 0; i < na; ++i)
        {
            const std::size_t v = active[i];
            const FieldSample& s = samples[i];
            if (!s.defined || !std::isfinite(s.value))
            {
                active[kept++] = v;
                continue;
            }
            if (std::abs(s.value) <= settled_value)
            {
                settled[v] = 1;
                vertex_gradient[v] = s.gradient;
                continue;
            }
            active[kept++] = v;
            const bool lo_inside = lo_f[v] < 0.0;
            const bool here_inside = s.value < 0.0;
            if (here_inside == lo_inside)
            {
                lo_t[v] = vertex_t[v];
                lo_f[v] = s.value;
                if (last_side[v] == -1)
                {
                    hi_f[v] *= 0.5; // Illinois: the same end twice, halve the other
                }
                last_side[v] = -1;
            }
            else
            {
                hi_t[v] = vertex_t[v];
                hi_f[v] = s.value;
                if (last_side[v] == 1)
                {
                    lo_f[v] *= 0.5;
                }
                last_side[v] = 1;
            }
            vertex_t[v] = interpolate(v);
        }
        active.resize(kept);
    }

    // Positions are stored as float32 relative to an origin at the middle of the surface (not
    // of the grid, which may be far larger; rounded as choose_origin() does, so a surface about
    // the world origin keeps origin 0 and float32 files), so their rounding stays small.
    // Vertices are kept off the grid corners by a margin well above that rounding (32 ulps of
    // the largest coordinate, at least 10⁻⁴ of a cell, at most 5%), so that no two vertices
    // coincide and the tiny triangles around a corner keep their shape once rounded.
    TriMesh& mesh = result.mesh;
    Coord low = {max_cells, max_cells, max_cells};
    Coord high = {0, 0, 0};
    for (std::size_t v = 0; v < nv; ++v)
    {
        const Coord base = unpack(edges[v] >> 2);
        for (std::size_t a = 0; a < 3; ++a)
        {
            low[a] = std::min(low[a], base[a]);
            high[a] = std::max(high[a], base[a] + 1);
        }
    }
    double reach = 0.0; // the largest |coordinate| in cells, relative to the origin
    if (nv > 0)
    {
        const Coord middle = {(low[0] + high[0]) / 2, (low[1] + high[1]) / 2,
                              (low[2] + high[2]) / 2};
        mesh.vertices.origin = choose_origin(grid_point(grid, middle));
        const Vec3d lo = grid_point(grid, low) - mesh.vertices.origin;
        const Vec3d hi = grid_point(grid, high) - mesh.vertices.origin;
        reach = std::max(lo.cwiseAbs().maxCoeff(), hi.cwiseAbs().maxCoeff()) / grid.cell;
    }
    const double float_ulp_cells = reach * std::ldexp(1.0, -23);
    const double corner_margin = std::clamp(32.0 * float_ulp_cells, 1e-4, 0.05);
    mesh.vertices.positions.resize(nv);
    points.resize(nv);
    for (std::size_t v = 0; v < nv; ++v)
    {
        const double s = std::clamp(vertex_t[v], corner_margin, 1.0 - corner_margin);
        points[v] = a_point[v] + s * (b_point[v] - a_point[v]);
        mesh.vertices.positions[v] = (points[v] - mesh.vertices.origin).cast<float>();
    }
    // The field at the vertices that no settled sample speaks for (a settled vertex that the
    // corner margin left where it is took its last sample there, defined): evaluated once, for
    // the normals and for the definedness, whichever is asked.
    const bool drop_undefined = options.min_defined_corners < 8 && nv > 0;
    std::vector<std::size_t> unsettled;
    std::vector<FieldSample> at_unsettled;
    if (options.vertex_normals || drop_undefined)
    {
        for (std::size_t v = 0; v < nv; ++v)
        {
            const double s = std::clamp(vertex_t[v], corner_margin, 1.0 - corner_margin);
            if (settled[v] == 0 || s != vertex_t[v])
            {
                unsettled.push_back(v);
            }
        }
        at_unsettled = evaluate_subset(points, unsettled,
                                       [&](std::span<const Vec3d> at, std::span<FieldSample> out) {
                                           evaluate_near_zero(field, exact_range, at, out);
                                       });
        stats.field_evaluations += unsettled.size();
    }
    if (options.vertex_normals)
    {
        // The gradient where each vertex is: a settled vertex's sample, the others'.
        for (std::size_t i = 0; i < unsettled.size(); ++i)
        {
            vertex_gradient[unsettled[i]] = at_unsettled[i].gradient;
        }
        mesh.vertices.normals.resize(nv);
        for (std::size_t v = 0; v < nv; ++v)
        {
            const Vec3d g = vertex_gradient[v];
            const double norm = g.norm();
            mesh.vertices.normals[v] =
                norm > 0.0 && std::isfinite(norm) ? Vec3f((g / norm).cast<float>()) : Vec3f::Zero();
        }
    }

    // Triangles, all of them: dropping one would open a hole.
    mesh.triangles.resize(corners_of_triangles.size() / 3);
    parallel_blocks(mesh.triangles.size(), 4096, [&](std::size_t begin, std::size_t end) {
        for (std::size_t f = begin; f < end; ++f)
        {
            for (std::size_t j = 0; j < 3; ++j)
            {
                const auto it =
                    std::lower_bound(edges.begin(), edges.end(), corners_of_triangles[3 * f + j]);
                mesh.triangles[f][j] = static_cast<std::uint32_t>(it - edges.begin());
            }
        }
    });
    if (drop_undefined)
    {
        // Cells with undefined corners reach past the field's defined region (a hole's rim):
        // there the triangles with a vertex where the field is undefined are dropped, so holes
        // stay as the field has them, and the vertices left unused are removed.
        std::vector<std::uint8_t> defined_at(nv, 1);
        for (std::size_t i = 0; i < unsettled.size(); ++i)
        {
            defined_at[unsettled[i]] = at_unsettled[i].defined ? 1 : 0;
        }
        std::vector<std::uint8_t> keep(mesh.face_count());
        for (std::size_t f = 0; f < mesh.face_count(); ++f)
        {
            const Triangle& tri = mesh.triangles[f];
            keep[f] = defined_at[tri[0]] != 0 && defined_at[tri[1]] != 0 && defined_at[tri[2]] != 0
                          ? 1
                          : 0;
        }
        stats.undefined_triangles = keep_faces(mesh, keep);
    }
    repair_degenerate_triangles(mesh, grid.cell, stats);
    // Where undefined cells meet diagonally, two sheets touch at one vertex; give each its own.
    stats.split_vertices = split_nonmanifold_vertices(mesh);
    progress.finish();
    return result;
}

} // namespace pointform
