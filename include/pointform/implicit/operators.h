// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include "pointform/implicit/field.h"

#include <cstdint>
#include <memory>
#include <mutex>
#include <span>
#include <utility>
#include <vector>

namespace pointform {

/// \file
/// \brief Volumetric operators on fields (§4.2, Tables 2 and 3): Boolean, blends, offset, shell
/// and metamorphosis.
///
/// Conventions kept by every operator:
/// - Members are shared, immutable fields; an operator is itself a Field, so they nest freely.
///   Constructors throw InvalidInput for a null member or a parameter outside its range.
/// - Values stay negative inside, positive outside; gradients point outwards and are the exact
///   gradients of the value (one-sided where the value has a crease, e.g. where min switches).
/// - Undefined samples (a point field beyond its influence radii, the paper's f = ∞) keep their
///   sign: every operator combines the members' values as they are (a point field's fallback is
///   ± the distance to its nearest sample), so "deep inside" and "far outside" survive, and only
///   the `defined` flag says whether polygonization may put a surface there. Booleans take
///   `defined` from the member whose value was chosen, so the union of two overlapping scans has
///   no inner surface (inside B, A's undefined negative value wins the min) and a difference cuts
///   cleanly. The other operators take the AND over the members that shape the value at p, as
///   filtered by their UndefinedPolicy.
/// - Seeds come from the operator's result, not passed through from its members: each distinct
///   member's seeds, moved onto the operator's surface by Newton steps where that surface is
///   displaced (offset, shell, hyperbolic blend, morph), kept where the result is as near zero
///   as the member is there (so A's seeds inside B are no seeds of A ∪ B); when none is kept,
///   the members' seeds moved by Newton steps onto the result, and if that finds none either, a
///   coarse sweep of bounds() (32 cells along its longest side) for sign changes. So every piece
///   of the result that holds a member's seed, or is larger than the sweep's cells when none
///   does, is found (e.g. A ∩ B where no seed of A lies inside B and none of B inside A). An
///   operator with a member that knows no seeds knows none either (dense polygonization).
/// - cost() is computed once, when the operator is made (a member that appears twice counts
///   once); members shared through SharedField are evaluated once per batch of points.
/// - Bounded evaluation (Field::evaluate_within): Booleans, smooth Booleans, offsets and shells
///   ask each member only for the range of values that can still decide their own result, the
///   cheaper members first (Field::cost), and give evaluate()'s result wherever it lies in the
///   range asked of them; the other operators ask their members exactly.
/// - Bounds: union → union of the boxes, intersection → their intersection (possibly empty),
///   difference → the first member's box, offset → grown by d (d > 0), blends → the union grown
///   by the blend range.

/// \brief How an operator other than a Boolean treats its members' undefined samples.
enum class UndefinedPolicy
{
    /// Undefined wherever a member that shapes the value is undefined.
    Propagate,
    /// Undefined where a member that shapes the value is undefined and not outside (value ≤ 0).
    /// Outside a point field, beyond its influence radii, its fallback value (the distance to
    /// the nearest sample) is a fair distance and is trusted, so blends and offsets can reach
    /// farther than the influence radius, while the corners inside a hole of a scan stay
    /// undefined and the hole stays open.
    TrustOutside,
    /// Never undefined: fallback values count as distances inside too (closes holes with the
    /// planes of their rims); what a morph between two scans needs, where the in-between surface
    /// lies deep inside one of them.
    Ignore,
};

/// \brief Which Boolean (Table 2).
enum class BooleanOp
{
    Union,        ///< A ∪ B: min(f_A, f_B, …)  ("paste")
    Intersection, ///< A ∩ B: max(f_A, f_B, …)  ("copy")
    Difference,   ///< A \ B: max(f_A, −f_B, −f_C, …) ("cut"): the first member minus the rest
};

/// \brief The Booleans of Table 2 over any number of members. The value is the chosen member's
/// value (negated for the subtracted ones), so exact distances stay exact outside the union and
/// inside the intersection and bounds elsewhere; the gradient and `defined` are the chosen
/// member's. Ties go to the earlier member.
class BooleanField final : public Field
{
public:
    /// \param members ≥ 1 for union and intersection, ≥ 2 for difference
    BooleanField(BooleanOp op, std::vector<std::shared_ptr<const Field>> members);

    [[nodiscard]] FieldSample evaluate(const Vec3d& p) const override;
    using Field::evaluate;
    [[nodiscard]] FieldSample evaluate_within(const Vec3d& p, double lo, double hi) const override;
    void evaluate_within(std::span<const Vec3d> points, std::span<const double> lo,
                         std::span<const double> hi, std::span<FieldSample> out) const override;
    [[nodiscard]] double cost() const override;
    [[nodiscard]] Aabb bounds() const override;
    void append_seeds(std::vector<Vec3d>& seeds) const override;

    [[nodiscard]] BooleanOp op() const { return op_; }
    [[nodiscard]] std::span<const std::shared_ptr<const Field>> members() const { return members_; }

private:
    class Minimum;

    BooleanOp op_;
    std::vector<std::shared_ptr<const Field>> members_;
    std::vector<std::size_t> order_; ///< members by cost, then by position
    double cost_ = 1.0;
};

/// \brief Smooth union, intersection or difference of two fields with blend radius k, by the
/// quadratic polynomial smooth minimum: with h = max(k − |a − b|, 0) / k,
/// smin(a, b) = min(a, b) − k·h²/4, smax(a, b) = −smin(−a, −b); difference = smax(f_A, −f_B).
///
/// Equal to the Boolean where |f_A − f_B| ≥ k; within that band the surface gets a fillet (or
/// a round for intersection and difference) at most k/4 from the Boolean's. The gradient is a
/// convex combination of the members' (weights 1 − h/2 and h/2), continuous, of norm ≤ 1, so a
/// distance field stays distance-like (1-Lipschitz). `defined`: the chosen member's where
/// |f_A − f_B| ≥ k, else the AND of both under `policy`.
class SmoothBooleanField final : public Field
{
public:
    /// \param radius k > 0, in input units
    SmoothBooleanField(BooleanOp op, std::shared_ptr<const Field> a, std::shared_ptr<const Field> b,
                       double radius, UndefinedPolicy policy = UndefinedPolicy::TrustOutside);

    [[nodiscard]] FieldSample evaluate(const Vec3d& p) const override;
    using Field::evaluate;
    [[nodiscard]] FieldSample evaluate_within(const Vec3d& p, double lo, double hi) const override;
    void evaluate_within(std::span<const Vec3d> points, std::span<const double> lo,
                         std::span<const double> hi, std::span<FieldSample> out) const override;
    [[nodiscard]] double cost() const override;
    [[nodiscard]] Aabb bounds() const override;
    void append_seeds(std::vector<Vec3d>& seeds) const override;

    [[nodiscard]] BooleanOp op() const { return op_; }
    [[nodiscard]] double radius() const { return radius_; }

private:
    /// s with g = s · f for member b (or a): the smooth minimum's orientation of its values.
    [[nodiscard]] double sign_of(bool b) const;
    /// The range to ask of member b (or a) for a result within [lo, hi], given the other's
    /// sample if that was asked first.
    [[nodiscard]] std::pair<double, double> range_of(bool b, double lo, double hi,
                                                     const FieldSample* first) const;
    [[nodiscard]] FieldSample combine(const FieldSample& sa, FieldSample sb) const;

    BooleanOp op_;
    std::shared_ptr<const Field> a_;
    std::shared_ptr<const Field> b_;
    double radius_;
    UndefinedPolicy policy_;
    bool b_first_ = false; ///< b is cheaper: asked first
    double cost_ = 1.0;
};

/// \brief Which blend of Table 3 (see BlendField).
enum class BlendKind
{
    Linear,
    Hyperbolic,
    SuperElliptic,
};

/// \brief The implicit blends of Table 3, each a blended union of k ≥ 1 members.
///
/// Each formula expects potentials rather than signed distances; with f_i the member's signed
/// distance (negative inside) and α_i > 0 its parameter (1/α_i is the member's blend range, in
/// input units: how far outside it the blend reaches):
/// - Linear, B = Σ p_i − 1 ≥ 0 inside, with p_i = [1 − α_i f_i]₊ (1 on the member's surface,
///   growing inwards, 0 at distance 1/α_i outside). Our value is −B = 1 − Σ p_i.
/// - Super-elliptic, B = 1 − (Σ [1 − α_i f_i]₊^β)^{1/β} ≤ 0 inside, i.e. the same potentials in
///   a β-norm; our value is B. β = 1 is the linear blend, β → ∞ the union; β = 2 gives round
///   fillets. β ≥ 1.
/// - Hyperbolic, B = Π p_i − 1 ≥ 0 inside, with the inverse-distance potentials
///   p_i = 1/(α_i f_i) (∞ on the member's surface). Our value is the reciprocal form
///   Π q_i − 1 with q_i = α_i f_i, negative inside, with the same zero set outside every member
///   and finite on the members' surfaces; where some q_i ≤ 0 (inside a member) it is
///   min_i q_i − 1, continuous, so the inside keeps its sign. The hyperbolic blend has no
///   bounded range: the surface lies off every member (at q_i = 1/Π_{j≠i} q_j), approaching it
///   away from the others; with one member it is the offset f = 1/α.
///
/// Far from the junction (beyond the other members' ranges) the linear and super-elliptic blends
/// equal the member: the value there is α_i f_i. Beyond every range the formulas are flat
/// (B = 1); the value continues as min_i α_i f_i so that it keeps growing with the distance
/// (continuous, same zero set). All values are finally divided by max_i α_i, so they are in
/// input units and, near an isolated member, |value| ≤ |f_i|. The hyperbolic value is not
/// distance-like (its gradient grows with the other members' distances); only its sign and zero
/// set matter. `defined` is the AND, under `policy`, of the members that contribute at p (for the
/// linear and super-elliptic blends those within their range, p_i > 0; for the hyperbolic blend
/// all).
class BlendField final : public Field
{
public:
    /// \param alphas one α_i > 0 per member, or a single α for all
    /// \param beta the super-elliptic exponent, ≥ 1 and finite (ignored by the other kinds)
    BlendField(BlendKind kind, std::vector<std::shared_ptr<const Field>> members,
               std::vector<double> alphas, double beta = 2.0,
               UndefinedPolicy policy = UndefinedPolicy::TrustOutside);

    [[nodiscard]] FieldSample evaluate(const Vec3d& p) const override;
    using Field::evaluate;
    [[nodiscard]] double cost() const override;
    [[nodiscard]] Aabb bounds() const override;
    void append_seeds(std::vector<Vec3d>& seeds) const override;

    [[nodiscard]] BlendKind kind() const { return kind_; }
    [[nodiscard]] std::span<const double> alphas() const { return alphas_; }
    [[nodiscard]] double beta() const { return beta_; }

private:
    BlendKind kind_;
    std::vector<std::shared_ptr<const Field>> members_;
    std::vector<double> alphas_;
    double beta_;
    UndefinedPolicy policy_;
    double alpha_max_;
    double cost_ = 1.0;
};

/// \brief Offset (§4.2, Fig. 3): f − d, the surface moved outwards by d (inwards for d < 0).
/// Exact for an exact distance field where the offset does not self-intersect. Note that a point
/// field is defined only within its influence radii: with the default policy an outward offset
/// uses the point field's fallback distance beyond them, an inward one farther than them is
/// undefined.
class OffsetField final : public Field
{
public:
    /// \param distance d, finite, in input units
    OffsetField(std::shared_ptr<const Field> member, double distance,
                UndefinedPolicy policy = UndefinedPolicy::TrustOutside);

    [[nodiscard]] FieldSample evaluate(const Vec3d& p) const override;
    using Field::evaluate;
    [[nodiscard]] FieldSample evaluate_within(const Vec3d& p, double lo, double hi) const override;
    void evaluate_within(std::span<const Vec3d> points, std::span<const double> lo,
                         std::span<const double> hi, std::span<FieldSample> out) const override;
    [[nodiscard]] double cost() const override;
    [[nodiscard]] Aabb bounds() const override;
    void append_seeds(std::vector<Vec3d>& seeds) const override;

    [[nodiscard]] double distance() const { return distance_; }

private:
    std::shared_ptr<const Field> member_;
    double distance_;
    UndefinedPolicy policy_;
    double cost_ = 1.0;
};

/// \brief Hollow shell of thickness t around the surface: |f| − t/2 (two surfaces, at f = ±t/2;
/// gradient sign(f)·∇f).
class ShellField final : public Field
{
public:
    /// \param thickness t > 0, in input units
    ShellField(std::shared_ptr<const Field> member, double thickness,
               UndefinedPolicy policy = UndefinedPolicy::TrustOutside);

    [[nodiscard]] FieldSample evaluate(const Vec3d& p) const override;
    using Field::evaluate;
    [[nodiscard]] FieldSample evaluate_within(const Vec3d& p, double lo, double hi) const override;
    void evaluate_within(std::span<const Vec3d> points, std::span<const double> lo,
                         std::span<const double> hi, std::span<FieldSample> out) const override;
    [[nodiscard]] double cost() const override;
    [[nodiscard]] Aabb bounds() const override;
    void append_seeds(std::vector<Vec3d>& seeds) const override;

    [[nodiscard]] double thickness() const { return thickness_; }

private:
    std::shared_ptr<const Field> member_;
    double thickness_;
    UndefinedPolicy policy_;
    double cost_ = 1.0;
};

/// \brief Metamorphosis (§4.2): f_t = (1 − t)·f₁ + t·f₂ for t in [0, 1]; f₁'s surface at t = 0,
/// f₂'s at t = 1. For t < 1 its zero set is that of the paper's f₁ + t'·f₂ with t' = t/(1 − t);
/// the convex weights keep the value a distance bound between the two. `defined` is the AND
/// (under `policy`) of the members with a non-zero weight; the default Ignore is what morphs
/// between scans need (the in-between surfaces lie beyond the influence radii of both).
class MorphField final : public Field
{
public:
    /// \param t in [0, 1]
    /// \throw InvalidInput also if the members' bounds do not overlap (the in-between shapes
    ///        would be empty)
    MorphField(std::shared_ptr<const Field> from, std::shared_ptr<const Field> to, double t,
               UndefinedPolicy policy = UndefinedPolicy::Ignore);

    [[nodiscard]] FieldSample evaluate(const Vec3d& p) const override;
    using Field::evaluate;
    [[nodiscard]] double cost() const override;
    [[nodiscard]] Aabb bounds() const override;
    void append_seeds(std::vector<Vec3d>& seeds) const override;

    [[nodiscard]] double t() const { return t_; }

private:
    std::shared_ptr<const Field> from_;
    std::shared_ptr<const Field> to_;
    double t_;
    UndefinedPolicy policy_;
    double cost_ = 1.0;
};

/// \brief A field that several operators share (a scene's `let` binding used more than once):
/// its member is evaluated once per batch of points however many operators ask it, and its seeds
/// are computed once, so the work of a scene grows with its distinct nodes, not with its paths
/// (`let a1 = union(a0, a0)`, `let a2 = union(a1, a1)`, …).
///
/// Each thread remembers, per shared field, the last batch of up to 1024 points asked of it
/// (operators ask their members in such blocks; what it remembers of a field goes when the field
/// does), with the range each point was asked within; a
/// request for the same points within ranges that those contain is answered from it, the rest
/// from the member. Every answer is one the member gave for a range that contains the one asked,
/// so it keeps Field::evaluate_within's contract, and exact values are the member's exactly.
class SharedField final : public Field
{
public:
    explicit SharedField(std::shared_ptr<const Field> member);
    ~SharedField() override;

    [[nodiscard]] FieldSample evaluate(const Vec3d& p) const override;
    using Field::evaluate;
    [[nodiscard]] FieldSample evaluate_within(const Vec3d& p, double lo, double hi) const override;
    void evaluate_within(std::span<const Vec3d> points, std::span<const double> lo,
                         std::span<const double> hi, std::span<FieldSample> out) const override;
    [[nodiscard]] double cost() const override;
    [[nodiscard]] Aabb bounds() const override;
    void append_seeds(std::vector<Vec3d>& seeds) const override;

    [[nodiscard]] const std::shared_ptr<const Field>& member() const { return member_; }

private:
    std::shared_ptr<const Field> member_;
    std::uint64_t id_; ///< unique over the process: the key of the threads' remembered batches
    double cost_;
    Aabb bounds_;
    mutable std::once_flag seeds_once_;
    mutable std::vector<Vec3d> seeds_;
};

/// \name Factories (the same validation as the constructors)
/// @{
[[nodiscard]] std::shared_ptr<const Field> make_union(
    std::vector<std::shared_ptr<const Field>> members);
[[nodiscard]] std::shared_ptr<const Field> make_intersection(
    std::vector<std::shared_ptr<const Field>> members);
/// \brief a \ b.
[[nodiscard]] std::shared_ptr<const Field> make_difference(std::shared_ptr<const Field> a,
                                                           std::shared_ptr<const Field> b);
[[nodiscard]] std::shared_ptr<const Field> make_smooth_union(std::shared_ptr<const Field> a,
                                                             std::shared_ptr<const Field> b,
                                                             double radius);
[[nodiscard]] std::shared_ptr<const Field> make_smooth_intersection(std::shared_ptr<const Field> a,
                                                                    std::shared_ptr<const Field> b,
                                                                    double radius);
[[nodiscard]] std::shared_ptr<const Field> make_smooth_difference(std::shared_ptr<const Field> a,
                                                                  std::shared_ptr<const Field> b,
                                                                  double radius);
/// \brief A Table-3 blend with the same blend range (α = 1/range) for every member.
/// \param range > 0, in input units
[[nodiscard]] std::shared_ptr<const Field> make_blend(
    BlendKind kind, std::vector<std::shared_ptr<const Field>> members, double range,
    double beta = 2.0);
[[nodiscard]] std::shared_ptr<const Field> make_offset(std::shared_ptr<const Field> member,
                                                       double distance);
[[nodiscard]] std::shared_ptr<const Field> make_shell(std::shared_ptr<const Field> member,
                                                      double thickness);
[[nodiscard]] std::shared_ptr<const Field> make_morph(std::shared_ptr<const Field> from,
                                                      std::shared_ptr<const Field> to, double t);
/// \brief `member` as a SharedField (itself if it is one already).
[[nodiscard]] std::shared_ptr<const Field> make_shared_node(std::shared_ptr<const Field> member);
/// @}

} // namespace pointform
