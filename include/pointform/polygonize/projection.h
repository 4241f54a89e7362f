// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include "pointform/core/types.h"
#include "pointform/implicit/field.h"

#include <optional>

namespace pointform {

/// \brief Options of project_to_zero().
struct ProjectionOptions
{
    /// Samples per side of the segment used to bracket crossings: the march steps by
    /// max_distance / steps outwards from p in both directions (a crossing pair closer than one
    /// step can be missed). At least 1.
    int steps = 16;
    /// The crossing is located to within this fraction of max_distance. The meshes that take
    /// the points store float coordinates, one unit in the last place of which is about 6e-8
    /// of the object's size: 1e-6 of a vertex's search reach (about an edge) is below that on
    /// the levels a reconstruction outputs, and half the regula falsi evaluations of 1e-7 (on
    /// a simulated fandisk scan and PCL's table_scene_mug, where creases and noise make the
    /// field converge slowly).
    double relative_tolerance = 1e-6;
    /// Most field evaluations spent refining one bracket (Illinois regula falsi).
    int max_iterations = 64;
};

/// \brief Zero crossing of the field on the segment p + t·direction, |t| <= max_distance, nearest
/// to p, at which direction·∇f > 0 (f goes from inside to outside); nullopt if none is found or
/// the field is undefined there.
///
/// The segment is sampled outwards from p, alternately on both sides, in steps of
/// max_distance / options.steps; where the field is defined at p and grows along the direction,
/// the first sample on the side its sign points to is taken at twice the Newton step from p
/// (-2 f / (direction·∇f)) if that is within the first step, so that a point near the surface
/// brackets its crossing tightly. p itself is the answer if it is defined with |f| within the
/// tolerance and the field grows along the direction. A crossing is an interval between two
/// consecutive samples where f goes from negative to non-negative in the direction of
/// increasing t (the discrete form of direction·∇f > 0). Undefined samples take part in the
/// bracketing by their sign (FieldSample keeps it), so a band of definition thinner than a step
/// around the surface is still found. The nearest bracket (ties: the positive side) is refined by
/// Illinois regula falsi to options.relative_tolerance · max_distance; the located point must be a
/// defined sample, and a sign change at the border between defined and undefined space (the rim of
/// a hole in a point field, where the surface ends) is no crossing. A rejected bracket lets the
/// march go on. Deterministic: the same input gives the same point.
///
/// \param direction  need not be unit length; a zero or non-finite direction, a non-positive or
///                   non-finite max_distance or a non-finite p give nullopt
[[nodiscard]] std::optional<Vec3d> project_to_zero(const Field& field, const Vec3d& p,
                                                   const Vec3d& direction, double max_distance);

/// \brief project_to_zero() with explicit options.
/// \throw InvalidInput if options.steps < 1, options.max_iterations < 1 or the tolerance is not
///        positive and finite
[[nodiscard]] std::optional<Vec3d> project_to_zero(const Field& field, const Vec3d& p,
                                                   const Vec3d& direction, double max_distance,
                                                   const ProjectionOptions& options);

/// \brief project_to_zero() given `at_p`, the field's sample at p (field.evaluate(p)), which it
/// would otherwise evaluate first: the same point, one evaluation fewer.
[[nodiscard]] std::optional<Vec3d> project_to_zero(const Field& field, const FieldSample& at_p,
                                                   const Vec3d& p, const Vec3d& direction,
                                                   double max_distance);

/// \brief A point of f = 0 near p by Newton steps along the gradient, q ← q − f(q) ∇f / |∇f|²
/// (where the field is undefined its value and gradient still say which way the surface is,
/// see FieldSample): for a point whose projection along a direction fails or folds, e.g. a
/// midpoint that cuts a crease's corner. nullopt unless, within 16 steps, a defined sample with
/// |f| ≤ 1e-7 · max_distance is reached no farther than max_distance from p.
[[nodiscard]] std::optional<Vec3d> newton_to_zero(const Field& field, const Vec3d& p,
                                                  double max_distance);

} // namespace pointform
