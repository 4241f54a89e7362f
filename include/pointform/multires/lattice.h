// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include "pointform/core/types.h"
#include "pointform/geometry/multires_mesh.h"
#include "pointform/multires/deformation.h"

#include <array>
#include <cstddef>
#include <vector>

namespace pointform {

/// \file
/// \brief Global free-form deformation (Sederberg and Parry 1986): a trivariate Bernstein
/// lattice over a box. A point x in the box, with local coordinates u = (x − min) / (max − min),
/// goes to Σ_ijk B_i^l(u_x) B_j^m(u_y) B_k^n(u_z) P_ijk. Points outside the box do not move.

/// \brief The most control points along one axis minus one (the degree), and in all.
inline constexpr std::size_t max_lattice_degree = 24;
inline constexpr std::size_t max_lattice_points = 4096;

/// \brief A Bernstein lattice of degree l × m × n over the box [min, max]: (l + 1)(m + 1)(n + 1)
/// control points in world coordinates, x fastest, then y, then z.
struct Lattice
{
    Vec3d min = Vec3d::Zero();
    Vec3d max = Vec3d::Ones();
    std::array<std::size_t, 3> degree = {1, 1, 1};
    std::vector<Vec3d> control_points;

    /// \brief Index of control point (i, j, k).
    [[nodiscard]] std::size_t index(std::size_t i, std::size_t j, std::size_t k) const
    {
        return i + (degree[0] + 1) * (j + (degree[1] + 1) * k);
    }
};

/// \brief The lattice at rest: control point (i, j, k) at min + (i / l, j / m, k / n) ∘ (max −
/// min), the identity map.
/// \throw InvalidInput as validate_lattice()
[[nodiscard]] Lattice rest_lattice(const Vec3d& min, const Vec3d& max,
                                   const std::array<std::size_t, 3>& degree);

/// \brief Checks a lattice: finite box with min < max on every axis, degrees in [1,
/// max_lattice_degree], at most max_lattice_points control points, exactly (l + 1)(m + 1)(n + 1)
/// of them, all finite. \throw InvalidInput saying what is wrong
void validate_lattice(const Lattice& lattice);

/// \brief The deformed position of world point x (x itself outside the box). \pre a valid lattice
[[nodiscard]] Vec3d evaluate_lattice(const Lattice& lattice, const Vec3d& x);

/// \brief How a lattice deforms a hierarchy.
enum class LatticeMode
{
    /// Level j's vertices (those of every coarser level included) go through the lattice; the
    /// finer levels follow by their details, which ride along in their local frames: the relief
    /// is bent, not sheared.
    Details,
    /// Every vertex of every level goes through the lattice (plain FFD).
    Plain,
};

/// \brief Deforms `mesh` by `lattice` (LatticeMode; `level` is j, unused in Plain mode).
/// \throw InvalidInput for an invalid lattice or a level that does not exist
DeformReport apply_lattice(MultiresMesh& mesh, const Lattice& lattice, std::size_t level,
                           LatticeMode mode = LatticeMode::Details);

} // namespace pointform
