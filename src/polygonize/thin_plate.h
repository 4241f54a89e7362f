// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include "pointform/core/types.h"

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>

#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <vector>

namespace pointform::detail {

/// \brief Thin-plate fairing of the `free` vertices of a mesh of `vertex_count` vertices: their
/// positions minimising Σ ‖L x_i‖² over the free vertices and their neighbours i, with L the
/// uniform Laplacian (the mean of the neighbours minus the vertex) and every other vertex held,
/// so that the free part meets the rest with the slope of the ring around it (the smoothest
/// surface that continues the mesh). `for_each_neighbour(v, f)` calls f(w) for each neighbour w
/// of vertex v; `position(v)` is v's position. Returns the free vertices' new positions, in the
/// order of `free`, or nothing where the system is singular (a free part that no held vertex
/// pins) or its solution is not finite. Used by the base mesh's hole patches and the finest
/// level's unsupported regions alike.
template <class ForEachNeighbour, class Position>
[[nodiscard]] std::optional<std::vector<Vec3d>> thin_plate_fairing(
    std::size_t vertex_count, std::span<const std::uint32_t> free,
    ForEachNeighbour&& for_each_neighbour, Position&& position)
{
    if (free.empty())
        return std::nullopt;
    constexpr std::uint32_t held = std::numeric_limits<std::uint32_t>::max();
    std::vector<std::uint32_t> column(vertex_count, held);
    for (std::size_t i = 0; i < free.size(); ++i)
        column[free[i]] = static_cast<std::uint32_t>(i);
    // One row per free vertex and per neighbour of one: its uniform Laplacian.
    std::vector<std::uint32_t> rows(free.begin(), free.end());
    std::vector<char> in_rows(vertex_count, 0);
    for (const std::uint32_t v : free)
        in_rows[v] = 1;
    for (const std::uint32_t v : free)
        for_each_neighbour(v, [&](std::uint32_t w) {
            if (in_rows[w] == 0)
            {
                in_rows[w] = 1;
                rows.push_back(w);
            }
        });
    using Sparse = Eigen::SparseMatrix<double>;
    std::vector<Eigen::Triplet<double>> entries;
    Eigen::MatrixXd fixed = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(rows.size()), 3);
    for (std::size_t r = 0; r < rows.size(); ++r)
    {
        const std::uint32_t v = rows[r];
        std::size_t degree = 0;
        for_each_neighbour(v, [&](std::uint32_t) { ++degree; });
        if (degree == 0)
            continue;
        const auto add = [&](std::uint32_t w, double coefficient) {
            if (column[w] != held)
                entries.emplace_back(static_cast<int>(r), static_cast<int>(column[w]), coefficient);
            else
                fixed.row(static_cast<Eigen::Index>(r)) += coefficient * position(w).transpose();
        };
        const double weight = 1.0 / static_cast<double>(degree);
        for_each_neighbour(v, [&](std::uint32_t w) { add(w, weight); });
        add(v, -1.0);
    }
    Sparse a(static_cast<Eigen::Index>(rows.size()), static_cast<Eigen::Index>(free.size()));
    a.setFromTriplets(entries.begin(), entries.end());
    const Sparse normal = a.transpose() * a;
    const Eigen::SimplicialLDLT<Sparse> solver(normal);
    if (solver.info() != Eigen::Success)
        return std::nullopt;
    const Eigen::MatrixXd x = solver.solve(-(a.transpose() * fixed));
    if (solver.info() != Eigen::Success || !x.allFinite())
        return std::nullopt;
    std::vector<Vec3d> out(free.size());
    for (std::size_t i = 0; i < free.size(); ++i)
        out[i] = x.row(static_cast<Eigen::Index>(i)).transpose();
    return out;
}

} // namespace pointform::detail
