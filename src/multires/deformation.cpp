// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/multires/deformation.h"

#include "pointform/core/disjoint_sets.h"
#include "pointform/core/error.h"
#include "pointform/core/parallel.h"
#include "pointform/multires/level_of_detail.h"

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

namespace pointform {

RegionOfInterest RegionOfInterest::of_vertices(std::vector<std::uint32_t> vertices)
{
    RegionOfInterest region;
    region.kind = Kind::Vertices;
    region.vertices = std::move(vertices);
    return region;
}

RegionOfInterest RegionOfInterest::ball(const Vec3d& center, double radius)
{
    RegionOfInterest region;
    region.kind = Kind::Ball;
    region.center = center;
    region.radius = radius;
    return region;
}

RegionOfInterest RegionOfInterest::box(const Vec3d& min, const Vec3d& max)
{
    RegionOfInterest region;
    region.kind = Kind::Box;
    region.min = min;
    region.max = max;
    return region;
}

DeformHandle DeformHandle::translate(std::vector<std::uint32_t> vertices, const Vec3d& by)
{
    DeformHandle handle;
    handle.vertices = std::move(vertices);
    handle.transform.topRightCorner<3, 1>() = by;
    return handle;
}

DeformHandle DeformHandle::affine(std::vector<std::uint32_t> vertices,
                                  const Eigen::Matrix4d& transform)
{
    DeformHandle handle;
    handle.vertices = std::move(vertices);
    handle.transform = transform;
    return handle;
}

DeformHandle DeformHandle::within(const RegionOfInterest& selection,
                                  const Eigen::Matrix4d& transform)
{
    DeformHandle handle;
    handle.selection = selection;
    handle.transform = transform;
    return handle;
}

namespace {

using SparseMatrix = Eigen::SparseMatrix<double>;
using Triplet = Eigen::Triplet<double>;

enum Role : std::uint8_t
{
    Fixed,  ///< outside the region (or unconstrained): does not move
    Handle, ///< placed by its target
    Free,   ///< placed by the solve
};

constexpr std::uint32_t none = std::numeric_limits<std::uint32_t>::max();

Vec3d transformed(const Eigen::Matrix4d& m, const Vec3d& x)
{
    return m.topLeftCorner<3, 3>() * x + m.topRightCorner<3, 1>();
}

void check_transform(const Eigen::Matrix4d& m, std::size_t handle)
{
    if (!m.allFinite())
        throw InvalidInput("deform: handle " + std::to_string(handle) +
                           " has a transform that is not finite");
    if (m(3, 0) != 0.0 || m(3, 1) != 0.0 || m(3, 2) != 0.0 || m(3, 3) != 1.0)
        throw InvalidInput("deform: handle " + std::to_string(handle) +
                           " has a transform whose last row is not 0 0 0 1 (only affine maps)");
}

/// Which of level j's n vertices the region holds.
std::vector<std::uint8_t> region_members(const MultiresMesh& mesh, std::size_t n,
                                         const RegionOfInterest& region,
                                         const std::string& whose = "the region's")
{
    using Kind = RegionOfInterest::Kind;
    std::vector<std::uint8_t> in(n, region.kind == Kind::Whole ? 1 : 0);
    switch (region.kind)
    {
        case Kind::Whole:
            break;
        case Kind::Vertices:
            for (const std::uint32_t v : region.vertices)
            {
                if (v >= n)
                    throw InvalidInput("deform: region vertex " + std::to_string(v) +
                                       " is not a vertex of the level (it has " +
                                       std::to_string(n) + ")");
                in[v] = 1;
            }
            break;
        case Kind::Ball:
            if (!region.center.allFinite() || !std::isfinite(region.radius) || region.radius <= 0.0)
                throw InvalidInput("deform: " + whose +
                                   " ball needs a finite centre and a finite radius greater "
                                   "than 0");
            for (std::uint32_t v = 0; v < n; ++v)
                in[v] = (mesh.world(v) - region.center).norm() <= region.radius ? 1 : 0;
            break;
        case Kind::Box:
            if (!region.min.allFinite() || !region.max.allFinite() ||
                (region.min.array() > region.max.array()).any())
                throw InvalidInput("deform: " + whose +
                                   " box needs finite corners with min <= max on every axis");
            for (std::uint32_t v = 0; v < n; ++v)
            {
                const Vec3d x = mesh.world(v);
                in[v] = (x.array() >= region.min.array()).all() &&
                                (x.array() <= region.max.array()).all()
                            ? 1
                            : 0;
            }
            break;
    }
    return in;
}

/// Half the cotangent of the angle between u and v, finite for degenerate corners.
double half_cot(const Vec3d& u, const Vec3d& v)
{
    const double cross = u.cross(v).norm();
    const double scale = u.norm() * v.norm();
    return 0.5 * u.dot(v) / std::max(cross, 1e-12 * scale + std::numeric_limits<double>::min());
}

} // namespace

struct MultiresDeformer::Impl
{
    std::size_t level = 0;
    MultiresMesh rest;
    DetailSynthesizer synthesizer;
    MultiresDetails details;
    std::vector<std::uint32_t> handles;     ///< handle vertices, handle by handle
    std::vector<std::size_t> handle_starts; ///< first entry of each handle in `handles`, + end
    /// Each handle's ball or box where it chose its vertices by place (else Kind::Vertices).
    std::vector<RegionOfInterest> selections;
    std::vector<std::uint32_t> free; ///< free vertices (ids of level j)
    SparseMatrix coupling;           ///< free × handles block of the system
    Eigen::SimplicialLDLT<SparseMatrix> solver;
    DeformReport shape; ///< the report's fields fixed at construction

    Impl(const MultiresMesh& mesh, std::size_t j)
        : level(j), rest(mesh), synthesizer(mesh), details(synthesizer.analyze(mesh))
    {}
};

MultiresDeformer::~MultiresDeformer() = default;
MultiresDeformer::MultiresDeformer(MultiresDeformer&&) noexcept = default;
MultiresDeformer& MultiresDeformer::operator=(MultiresDeformer&&) noexcept = default;

MultiresDeformer::MultiresDeformer(const MultiresMesh& rest, const MultiresEdit& edit)
{
    if (rest.level_count() == 0)
        throw InvalidInput("deform: the hierarchy is empty");
    check_level(rest, edit.level);
    const std::size_t j = edit.level;
    const std::size_t n = rest.vertex_count(j);
    const std::vector<std::uint8_t> in_region = region_members(rest, n, edit.region);

    std::vector<std::uint8_t> role(n, Fixed);
    for (std::size_t v = 0; v < n; ++v)
        role[v] = in_region[v] != 0 ? Free : Fixed;
    std::vector<std::uint32_t> handles;
    std::vector<std::size_t> handle_starts{0};
    std::vector<std::uint32_t> handle_index(n, none);
    for (std::size_t h = 0; h < edit.handles.size(); ++h)
    {
        const DeformHandle& handle = edit.handles[h];
        check_transform(handle.transform, h);
        std::vector<std::uint32_t> chosen = handle.vertices;
        if (chosen.empty() && (handle.selection.kind == RegionOfInterest::Kind::Ball ||
                               handle.selection.kind == RegionOfInterest::Kind::Box))
        {
            const std::vector<std::uint8_t> inside =
                region_members(rest, n, handle.selection, "handle " + std::to_string(h) + "'s");
            for (std::uint32_t v = 0; v < n; ++v)
                if (inside[v] != 0)
                    chosen.push_back(v);
            if (chosen.empty())
                throw InvalidInput(
                    "deform: handle " + std::to_string(h) + "'s " +
                    (handle.selection.kind == RegionOfInterest::Kind::Ball ? "ball" : "box") +
                    " holds no vertex of level " + std::to_string(j));
        }
        if (chosen.empty())
            throw InvalidInput("deform: handle " + std::to_string(h) + " has no vertices");
        for (const std::uint32_t v : chosen)
        {
            if (v >= n)
                throw InvalidInput("deform: handle " + std::to_string(h) + ": vertex " +
                                   std::to_string(v) + " is not a vertex of level " +
                                   std::to_string(j) + " (it has " + std::to_string(n) + ")");
            if (handle_index[v] != none)
                throw InvalidInput("deform: vertex " + std::to_string(v) +
                                   " is named twice among the handles");
            if (in_region[v] == 0)
                throw InvalidInput("deform: handle " + std::to_string(h) + ": vertex " +
                                   std::to_string(v) + " lies outside the region of interest");
            handle_index[v] = static_cast<std::uint32_t>(handles.size());
            handles.push_back(v);
            role[v] = Handle;
        }
        handle_starts.push_back(handles.size());
    }

    const std::vector<Triangle> faces = rest.faces(j);
    // Free vertices in parts of the region that touch no constraint stay where they are.
    DisjointSets parts(n);
    std::vector<std::uint8_t> anchored(n, 0);
    for (const Triangle& t : faces)
        for (int k = 0; k < 3; ++k)
        {
            const std::uint32_t a = t[static_cast<std::size_t>(k)];
            const std::uint32_t b = t[static_cast<std::size_t>((k + 1) % 3)];
            if (role[a] == Free && role[b] == Free)
                parts.unite(a, b);
        }
    for (const Triangle& t : faces)
        for (int k = 0; k < 3; ++k)
        {
            const std::uint32_t a = t[static_cast<std::size_t>(k)];
            const std::uint32_t b = t[static_cast<std::size_t>((k + 1) % 3)];
            if (role[a] == Free && role[b] != Free)
                anchored[parts.find(a)] = 1;
            if (role[b] == Free && role[a] != Free)
                anchored[parts.find(b)] = 1;
        }
    std::size_t unconstrained = 0;
    std::size_t region_count = 0;
    for (std::size_t v = 0; v < n; ++v)
    {
        region_count += in_region[v];
        if (role[v] == Free && anchored[parts.find(v)] == 0)
        {
            role[v] = Fixed;
            ++unconstrained;
        }
    }

    impl_ = std::make_unique<Impl>(rest, j);
    Impl& m = *impl_;
    m.handles = std::move(handles);
    m.handle_starts = std::move(handle_starts);
    for (const DeformHandle& handle : edit.handles)
        m.selections.push_back(handle.vertices.empty() ? handle.selection
                                                       : RegionOfInterest::of_vertices({}));
    std::vector<std::uint32_t> free_index(n, none);
    for (std::uint32_t v = 0; v < n; ++v)
        if (role[v] == Free)
        {
            free_index[v] = static_cast<std::uint32_t>(m.free.size());
            m.free.push_back(v);
        }
    m.shape.level = j;
    m.shape.region_vertices = region_count;
    m.shape.handle_vertices = m.handles.size();
    m.shape.free_vertices = m.free.size();
    m.shape.unconstrained_vertices = unconstrained;
    if (m.free.empty())
        return;

    // Rows of L that the free block reads: the free vertices and their neighbours; their rows
    // are complete once every face touching one of them is assembled.
    std::vector<std::uint8_t> row(n, 0);
    for (const Triangle& t : faces)
        if (role[t[0]] == Free || role[t[1]] == Free || role[t[2]] == Free)
            for (const std::uint32_t v : t)
                row[v] = 1;
    std::vector<Triplet> laplacian;
    std::vector<double> mass(n, 0.0);
    const auto position = [&](std::uint32_t v) {
        return rest.positions()[v];
    };
    for (const Triangle& t : faces)
    {
        if (row[t[0]] == 0 && row[t[1]] == 0 && row[t[2]] == 0)
            continue;
        const Vec3d& a = position(t[0]);
        const Vec3d& b = position(t[1]);
        const Vec3d& c = position(t[2]);
        const double third = (b - a).cross(c - a).norm() / 6.0;
        for (const std::uint32_t v : t)
            mass[v] += third;
        // The angle at each corner weighs the opposite edge.
        const std::array<double, 3> w = {half_cot(b - a, c - a), half_cot(c - b, a - b),
                                         half_cot(a - c, b - c)};
        for (int k = 0; k < 3; ++k)
        {
            const std::uint32_t p = t[static_cast<std::size_t>((k + 1) % 3)];
            const std::uint32_t q = t[static_cast<std::size_t>((k + 2) % 3)];
            const double weight = w[static_cast<std::size_t>(k)];
            laplacian.emplace_back(p, q, weight);
            laplacian.emplace_back(q, p, weight);
            laplacian.emplace_back(p, p, -weight);
            laplacian.emplace_back(q, q, -weight);
        }
    }
    SparseMatrix L(static_cast<Eigen::Index>(n), static_cast<Eigen::Index>(n));
    L.setFromTriplets(laplacian.begin(), laplacian.end());
    laplacian = {};
    double mass_sum = 0.0;
    std::size_t mass_count = 0;
    for (std::size_t v = 0; v < n; ++v)
        if (row[v] != 0 && mass[v] > 0.0 && std::isfinite(mass[v]))
        {
            mass_sum += mass[v];
            ++mass_count;
        }
    const double mean_mass = mass_count > 0 ? mass_sum / static_cast<double>(mass_count) : 1.0;

    // A = Lᵀ M⁻¹ L = Σ_k L_k· ᵀ L_k· / m_k over rows k; keep the free × free block and the free ×
    // handle coupling (the other constraints do not move).
    std::vector<Triplet> block;
    std::vector<Triplet> couple;
    std::vector<std::pair<std::uint32_t, double>> entries;
    for (std::uint32_t k = 0; k < n; ++k)
    {
        if (row[k] == 0)
            continue;
        entries.clear();
        for (SparseMatrix::InnerIterator it(L, k); it; ++it)
            entries.emplace_back(static_cast<std::uint32_t>(it.row()), it.value());
        const double m_k = mass[k] > 1e-12 * mean_mass ? mass[k] : mean_mass;
        for (const auto& [i, li] : entries)
        {
            if (role[i] != Free)
                continue;
            for (const auto& [jj, lj] : entries)
            {
                const double value = li * lj / m_k;
                if (role[jj] == Free)
                    block.emplace_back(free_index[i], free_index[jj], value);
                else if (role[jj] == Handle)
                    couple.emplace_back(free_index[i], handle_index[jj], value);
            }
        }
    }
    const auto free_count = static_cast<Eigen::Index>(m.free.size());
    SparseMatrix A(free_count, free_count);
    A.setFromTriplets(block.begin(), block.end());
    m.coupling.resize(free_count, static_cast<Eigen::Index>(m.handles.size()));
    m.coupling.setFromTriplets(couple.begin(), couple.end());
    m.solver.compute(A);
    if (m.solver.info() != Eigen::Success)
        throw InvalidInput("deform: the bi-Laplacian system of level " + std::to_string(j) +
                           " could not be factored (degenerate faces in the region?)");
}

std::span<const std::uint32_t> MultiresDeformer::handle_vertices() const
{
    return impl_->handles;
}

std::size_t MultiresDeformer::level() const
{
    return impl_->level;
}

DeformReport MultiresDeformer::apply(MultiresMesh& mesh, std::span<const Vec3d> targets) const
{
    const Impl& m = *impl_;
    if (targets.size() != m.handles.size())
        throw InvalidInput("deform: " + std::to_string(targets.size()) + " targets for " +
                           std::to_string(m.handles.size()) + " handle vertices");
    if (!std::equal(mesh.level_offsets().begin(), mesh.level_offsets().end(),
                    m.rest.level_offsets().begin(), m.rest.level_offsets().end()) ||
        mesh.base_faces().size() != m.rest.base_faces().size() || mesh.origin() != m.rest.origin())
        throw InvalidInput(
            "deform: the hierarchy does not match the one the deformer was made "
            "for");
    for (const Vec3d& t : targets)
        if (!t.allFinite())
            throw InvalidInput("deform: a handle target is not finite");

    const std::span<const Vec3d> x0 = m.rest.positions();
    const std::span<Vec3d> x = mesh.mutable_positions();
    std::copy(x0.begin(), x0.end(), x.begin());
    std::vector<std::uint8_t> moved(x.size(), 0);
    const auto place = [&](std::uint32_t v, const Vec3d& p) {
        x[v] = p;
        moved[v] = p != x0[v] ? 1 : 0;
    };
    const Vec3d& origin = m.rest.origin();
    Eigen::MatrixX3d handle_shift(static_cast<Eigen::Index>(m.handles.size()), 3);
    for (std::size_t h = 0; h < m.handles.size(); ++h)
    {
        const Vec3d local = targets[h] - origin;
        handle_shift.row(static_cast<Eigen::Index>(h)) = (local - x0[m.handles[h]]).transpose();
        place(m.handles[h], local);
    }
    if (!m.free.empty())
    {
        const Eigen::MatrixX3d rhs = -(m.coupling * handle_shift);
        const Eigen::MatrixX3d shift = m.solver.solve(rhs);
        for (std::size_t f = 0; f < m.free.size(); ++f)
        {
            const Vec3d d = shift.row(static_cast<Eigen::Index>(f)).transpose();
            if (!d.allFinite())
                throw InvalidInput("deform: the solve gave a non-finite displacement");
            place(m.free[f], x0[m.free[f]] + d);
        }
    }
    m.synthesizer.synthesize(mesh, m.details, m.level, &moved);

    DeformReport report = m.shape;
    report.levels = level_motion(m.rest, mesh);
    for (const LevelMotion& motion : report.levels)
        report.largest_displacement = std::max(report.largest_displacement, motion.largest);
    return report;
}

DeformReport MultiresDeformer::apply(MultiresMesh& mesh,
                                     std::span<const DeformHandle> handles) const
{
    const Impl& m = *impl_;
    if (handles.size() + 1 != m.handle_starts.size())
        throw InvalidInput("deform: " + std::to_string(handles.size()) +
                           " handles for a deformer "
                           "made with " +
                           std::to_string(m.handle_starts.size() - 1));
    std::vector<Vec3d> targets;
    targets.reserve(m.handles.size());
    for (std::size_t h = 0; h < handles.size(); ++h)
    {
        check_transform(handles[h].transform, h);
        const std::span<const std::uint32_t> expected(m.handles.data() + m.handle_starts[h],
                                                      m.handle_starts[h + 1] - m.handle_starts[h]);
        const RegionOfInterest& made = m.selections[h];
        const RegionOfInterest& given = handles[h].selection;
        const bool same_place = handles[h].vertices.empty() && made.kind == given.kind &&
                                made.kind != RegionOfInterest::Kind::Vertices &&
                                made.center == given.center && made.radius == given.radius &&
                                made.min == given.min && made.max == given.max;
        if (!same_place && !std::equal(expected.begin(), expected.end(),
                                       handles[h].vertices.begin(), handles[h].vertices.end()))
            throw InvalidInput("deform: handle " + std::to_string(h) +
                               " names other vertices than the deformer was made with");
        for (const std::uint32_t v : expected)
            targets.push_back(transformed(handles[h].transform, m.rest.world(v)));
    }
    return apply(mesh, targets);
}

DeformReport deform(MultiresMesh& mesh, const MultiresEdit& edit)
{
    const MultiresDeformer deformer(mesh, edit);
    return deformer.apply(mesh, edit.handles);
}

std::vector<LevelMotion> level_motion(const MultiresMesh& before, const MultiresMesh& after)
{
    if (!std::equal(before.level_offsets().begin(), before.level_offsets().end(),
                    after.level_offsets().begin(), after.level_offsets().end()))
        throw InvalidInput("level_motion: the hierarchies have different levels");
    std::vector<LevelMotion> out;
    for (std::size_t level = 0; level < before.level_count(); ++level)
    {
        LevelMotion motion;
        motion.level = level;
        const std::size_t first = before.level_offsets()[level];
        const std::size_t last = before.level_offsets()[level + 1];
        motion.vertices = last - first;
        // Per block: how many moved and the largest move; combined in block order (a sum and a
        // maximum: the same whatever the thread count).
        constexpr std::size_t block = 16384;
        const std::size_t blocks = (motion.vertices + block - 1) / block;
        std::vector<std::pair<std::size_t, double>> partial(blocks, {0, 0.0});
        parallel_blocks(blocks, 1, [&](std::size_t begin, std::size_t end) {
            for (std::size_t b = begin; b < end; ++b)
                for (std::size_t v = first + b * block; v < std::min(last, first + (b + 1) * block);
                     ++v)
                {
                    const auto id = static_cast<std::uint32_t>(v);
                    if (before.positions()[v] == after.positions()[v] &&
                        before.origin() == after.origin())
                        continue;
                    ++partial[b].first;
                    partial[b].second =
                        std::max(partial[b].second, (after.world(id) - before.world(id)).norm());
                }
        });
        for (const auto& [moved, largest] : partial)
        {
            motion.moved += moved;
            motion.largest = std::max(motion.largest, largest);
        }
        out.push_back(motion);
    }
    return out;
}

} // namespace pointform
