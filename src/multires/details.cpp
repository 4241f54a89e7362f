// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/multires/details.h"

#include "pointform/core/error.h"
#include "pointform/core/parallel.h"
#include "pointform/geometry/level_topology.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace pointform {

namespace {

constexpr std::uint32_t none = LevelTopology::none;
constexpr std::size_t vertex_block = 4096;

/// A unit vector perpendicular to unit `t`: t × (the axis least aligned with t).
Vec3d any_perpendicular(const Vec3d& t)
{
    const Vec3d abs = t.cwiseAbs();
    const Vec3d axis = abs.x() <= abs.y() && abs.x() <= abs.z() ? Vec3d::UnitX()
                       : abs.y() <= abs.z()                     ? Vec3d::UnitY()
                                                                : Vec3d::UnitZ();
    return t.cross(axis).normalized();
}

} // namespace

LocalFrame local_frame(const Vec3d& a, const Vec3d& b, const Vec3d& c, const Vec3d* d)
{
    LocalFrame frame;
    const Vec3d edge = b - a;
    const double length = edge.norm();
    frame.t = length > 0.0 ? Vec3d(edge / length) : Vec3d::UnitX();
    Vec3d n = edge.cross(c - b);
    if (d != nullptr)
        n += (a - b).cross(*d - a);
    n -= n.dot(frame.t) * frame.t;
    const double n_length = n.norm();
    frame.n = n_length > 0.0 && std::isfinite(n_length) ? Vec3d(n / n_length)
                                                        : any_perpendicular(frame.t);
    frame.b = frame.n.cross(frame.t);
    return frame;
}

DetailSynthesizer::DetailSynthesizer(const MultiresMesh& mesh)
    : predictor_(mesh.predictor()),
      level_offsets_(mesh.level_offsets().begin(), mesh.level_offsets().end())
{
    if (mesh.level_count() == 0)
        throw InvalidInput("details: the hierarchy is empty");
    const std::size_t base = mesh.vertex_count(0);
    frame_vertices_.resize(mesh.vertex_count() - base);
    if (predictor_ == Predictor::Butterfly)
        stencil_offsets_.assign(frame_vertices_.size() + 1, 0);
    for (std::size_t i = 0; i < mesh.finest_level(); ++i)
    {
        const LevelTopology level = level_topology(mesh, i);
        const std::size_t first = level.first_new - base;
        const std::size_t added = level.halfedges.size();
        parallel_blocks(added, vertex_block, [&](std::size_t begin, std::size_t end) {
            for (std::size_t j = begin; j < end; ++j)
            {
                const auto [h1, h2] = level.halfedges[j];
                frame_vertices_[first + j] = {level.from(h1), level.to(h1), level.opposite(h1),
                                              h2 == none ? none : level.opposite(h2)};
            }
        });
        if (predictor_ != Predictor::Butterfly)
            continue;
        // Stencils in order (serially appended: their lengths vary).
        std::vector<StencilTerm> stencil;
        std::vector<std::uint32_t> ring;
        for (std::size_t j = 0; j < added; ++j)
        {
            prediction_stencil(level, j, predictor_, stencil, ring);
            for (const StencilTerm& term : stencil)
            {
                stencil_vertices_.push_back(term.vertex);
                stencil_weights_.push_back(term.weight);
            }
            stencil_offsets_[first + j + 1] = static_cast<std::uint32_t>(stencil_vertices_.size());
        }
    }
}

Vec3d DetailSynthesizer::predict(std::size_t k, std::span<const Vec3d> x) const
{
    if (predictor_ != Predictor::Butterfly)
    {
        const auto& f = frame_vertices_[k];
        return 0.5 * (x[f[0]] + x[f[1]]);
    }
    Vec3d p = Vec3d::Zero();
    for (std::uint32_t s = stencil_offsets_[k]; s < stencil_offsets_[k + 1]; ++s)
        p += stencil_weights_[s] * x[stencil_vertices_[s]];
    return p;
}

LocalFrame DetailSynthesizer::frame(std::size_t k, std::span<const Vec3d> x) const
{
    const auto& f = frame_vertices_[k];
    return local_frame(x[f[0]], x[f[1]], x[f[2]], f[3] == none ? nullptr : &x[f[3]]);
}

void DetailSynthesizer::check_shape(const MultiresMesh& mesh, const char* what) const
{
    if (!std::equal(level_offsets_.begin(), level_offsets_.end(), mesh.level_offsets().begin(),
                    mesh.level_offsets().end()))
        throw InvalidInput(
            std::string(what) + ": the hierarchy's levels do not match the details' (" +
            std::to_string(mesh.level_count()) + " levels, " + std::to_string(mesh.vertex_count()) +
            " vertices, against " + std::to_string(level_offsets_.size() - 1) + " levels, " +
            std::to_string(level_offsets_.back()) + " vertices)");
}

MultiresDetails DetailSynthesizer::analyze(const MultiresMesh& mesh) const
{
    check_shape(mesh, "analyze_details");
    MultiresDetails details;
    details.predictor = predictor_;
    details.level_offsets = level_offsets_;
    details.coefficients.resize(frame_vertices_.size());
    const std::span<const Vec3d> x = mesh.positions();
    const std::size_t base = level_offsets_[1];
    parallel_blocks(frame_vertices_.size(), vertex_block, [&](std::size_t begin, std::size_t end) {
        for (std::size_t k = begin; k < end; ++k)
        {
            const Vec3d offset = x[base + k] - predict(k, x);
            const LocalFrame f = frame(k, x);
            details.coefficients[k] = {offset.dot(f.t), offset.dot(f.n), offset.dot(f.b)};
        }
    });
    return details;
}

void DetailSynthesizer::synthesize(MultiresMesh& mesh, const MultiresDetails& details,
                                   std::size_t from_level, std::vector<std::uint8_t>* moved) const
{
    check_shape(mesh, "synthesize_details");
    if (details.level_offsets != level_offsets_ ||
        details.coefficients.size() != frame_vertices_.size())
        throw InvalidInput("synthesize_details: the details belong to another hierarchy");
    if (from_level >= mesh.level_count())
        throw InvalidInput("synthesize_details: level " + std::to_string(from_level) +
                           " does not exist (the hierarchy has " +
                           std::to_string(mesh.level_count()) + " levels)");
    if (moved != nullptr && moved->size() != mesh.vertex_count())
        throw InvalidInput("synthesize_details: one moved flag per vertex is needed");
    const std::span<Vec3d> x = mesh.mutable_positions();
    const std::size_t base = level_offsets_[1];
    for (std::size_t level = from_level + 1; level < level_offsets_.size() - 1; ++level)
    {
        const std::size_t first = level_offsets_[level] - base;
        const std::size_t count = level_offsets_[level + 1] - level_offsets_[level];
        parallel_blocks(count, vertex_block, [&](std::size_t begin, std::size_t end) {
            for (std::size_t k = first + begin; k < first + end; ++k)
            {
                if (moved != nullptr)
                {
                    bool touched = false;
                    for (const std::uint32_t v : frame_vertices_[k])
                        touched = touched || (v != none && (*moved)[v] != 0);
                    if (predictor_ == Predictor::Butterfly)
                        for (std::uint32_t s = stencil_offsets_[k];
                             !touched && s < stencil_offsets_[k + 1]; ++s)
                            touched = (*moved)[stencil_vertices_[s]] != 0;
                    if (!touched)
                        continue;
                }
                const LocalFrame f = frame(k, x);
                const Vec3d& d = details.coefficients[k];
                const Vec3d p = predict(k, x) + d.x() * f.t + d.y() * f.n + d.z() * f.b;
                if (moved != nullptr && p != x[base + k])
                    (*moved)[base + k] = 1;
                x[base + k] = p;
            }
        });
    }
}

MultiresDetails analyze_details(const MultiresMesh& mesh)
{
    return DetailSynthesizer(mesh).analyze(mesh);
}

void synthesize_details(MultiresMesh& mesh, const MultiresDetails& details, std::size_t from_level)
{
    if (details.predictor != mesh.predictor())
        throw InvalidInput(std::string("synthesize_details: the details were measured from the ") +
                           std::string(to_string(details.predictor)) +
                           " predictor, the hierarchy's is " +
                           std::string(to_string(mesh.predictor())));
    DetailSynthesizer(mesh).synthesize(mesh, details, from_level);
}

std::vector<DetailLevelStats> detail_statistics(const MultiresDetails& details,
                                                double normal_tolerance)
{
    if (!(normal_tolerance >= 0.0 && normal_tolerance <= 1.0))
        throw InvalidInput("detail_statistics: normal_tolerance must lie in [0, 1]");
    std::vector<DetailLevelStats> out;
    if (details.level_offsets.size() < 2)
        return out;
    const std::size_t base = details.level_offsets[1];
    for (std::size_t level = 1; level + 1 < details.level_offsets.size(); ++level)
    {
        DetailLevelStats stats;
        stats.level = level;
        const std::size_t first = details.level_offsets[level] - base;
        const std::size_t last = details.level_offsets[level + 1] - base;
        stats.details = last - first;
        std::size_t normal = 0;
        for (std::size_t k = first; k < last; ++k)
        {
            const Vec3d& d = details.coefficients[k];
            const double length = d.norm();
            const double tangent = std::hypot(d.x(), d.z());
            stats.mean_length += length;
            stats.max_length = std::max(stats.max_length, length);
            stats.mean_normal += std::abs(d.y());
            stats.mean_tangent += tangent;
            normal += tangent <= normal_tolerance * length ? 1 : 0;
        }
        if (stats.details > 0)
        {
            const auto n = static_cast<double>(stats.details);
            stats.mean_length /= n;
            stats.mean_normal /= n;
            stats.mean_tangent /= n;
            stats.normal_share = static_cast<double>(normal) / n;
        }
        out.push_back(stats);
    }
    return out;
}

} // namespace pointform
