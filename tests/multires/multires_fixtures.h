// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

// Hierarchies with known relief for the Level 3 tests: every vertex of every level lies on an
// analytic surface with bumps, so details are real and their normal parts known in sign.

#pragma once

#include "pointform/geometry/multires_mesh.h"

#include "support/test_meshes.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <span>
#include <vector>

namespace pointform::test {

/// Radius of the bumpy sphere in direction `dir` (unit).
inline double relief_radius(const Vec3d& dir)
{
    return 1.0 + 0.04 * std::sin(6.0 * dir.x()) * std::sin(6.0 * dir.y()) * std::sin(6.0 * dir.z());
}

/// Height of the bumpy plate over (x, y).
inline double relief_height(double x, double y)
{
    return 0.05 * std::sin(3.0 * x) * std::cos(2.0 * y) + 0.01 * std::sin(11.0 * x + 7.0 * y);
}

/// A bumpy sphere: the icosphere(1) base (80 faces) and `levels` levels, each new vertex put on
/// the bumpy surface radially from its edge's midpoint.
inline MultiresMesh relief_sphere(std::size_t levels, Predictor predictor = Predictor::Midpoint)
{
    MultiresMesh mesh(icosphere(1));
    for (Vec3d& x : mesh.mutable_positions())
        x = relief_radius(x.normalized()) * x.normalized();
    mesh.set_predictor(predictor);
    for (std::size_t l = 0; l < levels; ++l)
    {
        (void)mesh.split();
        for (Vec3d& x : mesh.finest_new_positions())
            x = relief_radius(x.normalized()) * x.normalized();
    }
    return mesh;
}

/// The bumpy sphere of relief_sphere(), but each new vertex put on the surface along the normal
/// of its parent edge (the sum of the area normals of the edge's faces), from the edge's
/// midpoint, as the refinement projects (§5.2): a normal mesh, every detail a normal offset.
inline MultiresMesh relief_sphere_along_normals(std::size_t levels)
{
    MultiresMesh mesh(icosphere(1));
    for (Vec3d& x : mesh.mutable_positions())
        x = relief_radius(x.normalized()) * x.normalized();
    for (std::size_t l = 0; l < levels; ++l)
    {
        const MultiresMesh::SplitResult split = mesh.split();
        const std::size_t first = mesh.vertex_count(l);
        std::vector<Vec3d> normal(mesh.vertex_count() - first, Vec3d::Zero());
        for (std::size_t f = 0; f < split.faces.size(); ++f)
        {
            const auto [a, b, c] = split.faces[f];
            const Vec3d& pa = mesh.positions()[a];
            const Vec3d n = (mesh.positions()[b] - pa).cross(mesh.positions()[c] - pa);
            for (int k = 0; k < 3; ++k)
                normal[split.edge_vertices[3 * f + static_cast<std::size_t>(k)] - first] += n;
        }
        const std::span<Vec3d> added = mesh.finest_new_positions();
        for (std::size_t j = 0; j < added.size(); ++j)
        {
            // Bisection on the line midpoint + s n for |p| = relief_radius(p / |p|).
            const Vec3d origin = added[j];
            const Vec3d n = normal[j].normalized();
            const auto outside = [&](double s) {
                const Vec3d p = origin + s * n;
                return p.norm() > relief_radius(p.normalized());
            };
            double lo = -0.2;
            double hi = 0.2;
            for (int step = 0; step < 80; ++step)
            {
                const double mid = 0.5 * (lo + hi);
                (outside(mid) ? hi : lo) = mid;
            }
            added[j] = origin + 0.5 * (lo + hi) * n;
        }
    }
    return mesh;
}

/// A bumpy open plate over [-1, 1]²: a 4 × 4 grid base and `levels` levels on the height field.
inline MultiresMesh relief_plate(std::size_t levels, Predictor predictor = Predictor::Midpoint)
{
    MultiresMesh mesh(square_grid(4));
    for (Vec3d& x : mesh.mutable_positions())
        x.z() = relief_height(x.x(), x.y());
    mesh.set_predictor(predictor);
    for (std::size_t l = 0; l < levels; ++l)
    {
        (void)mesh.split();
        for (Vec3d& x : mesh.finest_new_positions())
            x.z() = relief_height(x.x(), x.y());
    }
    return mesh;
}

/// Length of the diagonal of the bounding box of every vertex.
inline double diagonal(const MultiresMesh& mesh)
{
    Vec3d lo = Vec3d::Constant(1e300);
    Vec3d hi = Vec3d::Constant(-1e300);
    for (std::uint32_t v = 0; v < mesh.vertex_count(); ++v)
    {
        lo = lo.cwiseMin(mesh.world(v));
        hi = hi.cwiseMax(mesh.world(v));
    }
    return (hi - lo).norm();
}

/// Largest distance between the world positions of two hierarchies of the same shape.
inline double largest_difference(const MultiresMesh& a, const MultiresMesh& b)
{
    double worst = 0.0;
    for (std::uint32_t v = 0; v < a.vertex_count(); ++v)
        worst = std::max(worst, (a.world(v) - b.world(v)).norm());
    return worst;
}

/// A proper rigid motion (a rotation about a slanted axis and a translation) as a 4 × 4 matrix.
inline Eigen::Matrix4d rigid_motion()
{
    Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
    m.topLeftCorner<3, 3>() =
        Eigen::AngleAxisd(0.7, Vec3d(1.0, 2.0, -0.5).normalized()).toRotationMatrix();
    m.topRightCorner<3, 1>() = Vec3d(0.3, -1.2, 2.5);
    return m;
}

} // namespace pointform::test
