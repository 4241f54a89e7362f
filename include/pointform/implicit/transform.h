// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#pragma once

#include "pointform/implicit/field.h"

#include <memory>
#include <utility>

namespace pointform {

/// \brief A field moved by an affine map T(q) = L·q + t (any field: point fields, primitives,
/// operators).
///
/// f_T(p) = σ · f(T⁻¹p) and ∇f_T(p) = σ · L⁻ᵀ ∇f(T⁻¹p), where σ is the smallest singular value
/// of L. For a rigid motion σ = 1 and for a uniform scale by s (times a rotation) σ = s, so an
/// exact signed distance stays exact. Under a non-uniform scale the value is no longer an exact
/// distance, but multiplying by the smallest factor keeps it a bound: |f_T(p)| ≤ the distance
/// from p to the transformed surface (the field stays 1-Lipschitz), and the sign and the zero
/// set are exact. `defined` is the member's. bounds() is the box of the member's transformed
/// box (an infinite side stays infinite), append_seeds() the member's seeds mapped by T.
class TransformedField final : public Field
{
public:
    /// \param linear L, invertible (condition number below 1e12)
    /// \throw InvalidInput if the member is null, or L or t is not finite or L is singular
    TransformedField(std::shared_ptr<const Field> member, const Mat3d& linear,
                     const Vec3d& translation);

    [[nodiscard]] FieldSample evaluate(const Vec3d& p) const override;
    using Field::evaluate;
    [[nodiscard]] FieldSample evaluate_within(const Vec3d& p, double lo, double hi) const override;
    void evaluate_within(std::span<const Vec3d> points, std::span<const double> lo,
                         std::span<const double> hi, std::span<FieldSample> out) const override;
    [[nodiscard]] double cost() const override;
    [[nodiscard]] Aabb bounds() const override;
    void append_seeds(std::vector<Vec3d>& seeds) const override;

    [[nodiscard]] const std::shared_ptr<const Field>& member() const { return member_; }
    [[nodiscard]] const Mat3d& linear() const { return linear_; }
    [[nodiscard]] const Vec3d& translation() const { return translation_; }
    /// \brief σ, the factor on the member's value.
    [[nodiscard]] double value_scale() const { return value_scale_; }

private:
    /// The member's range for a result within [lo, hi].
    [[nodiscard]] std::pair<double, double> member_range(double lo, double hi) const;
    /// The member's sample mapped to this field.
    [[nodiscard]] FieldSample transformed(FieldSample s) const;

    std::shared_ptr<const Field> member_;
    Mat3d linear_;
    Vec3d translation_;
    Mat3d inverse_;
    Mat3d gradient_map_; // σ · L⁻ᵀ
    double value_scale_;
};

/// \name Transform factories; each returns a TransformedField (T applied after the member's own
/// placement: translate(rotate(f, …), …) rotates first).
/// @{
/// \brief p ↦ p + offset.
[[nodiscard]] std::shared_ptr<const Field> translate(std::shared_ptr<const Field> field,
                                                     const Vec3d& offset);
/// \brief Rotation by `angle` radians about `axis` (non-zero, right-handed) through `center`.
[[nodiscard]] std::shared_ptr<const Field> rotate(std::shared_ptr<const Field> field,
                                                  const Vec3d& axis, double angle,
                                                  const Vec3d& center = Vec3d::Zero());
/// \brief Rotation by the matrix R (orthonormal, determinant +1) about `center`.
/// \throw InvalidInput if R is not a rotation (tolerance 1e-6)
[[nodiscard]] std::shared_ptr<const Field> rotate(std::shared_ptr<const Field> field,
                                                  const Mat3d& rotation,
                                                  const Vec3d& center = Vec3d::Zero());
/// \brief Uniform scale by s > 0 about `center`; the value stays an exact distance (× s).
[[nodiscard]] std::shared_ptr<const Field> scale(std::shared_ptr<const Field> field, double factor,
                                                 const Vec3d& center = Vec3d::Zero());
/// \brief Non-uniform scale by (sx, sy, sz), each > 0, about `center`; the value is a distance
/// bound (see TransformedField).
[[nodiscard]] std::shared_ptr<const Field> scale(std::shared_ptr<const Field> field,
                                                 const Vec3d& factors,
                                                 const Vec3d& center = Vec3d::Zero());
/// \brief A general affine map p ↦ L·p + t.
[[nodiscard]] std::shared_ptr<const Field> transform(std::shared_ptr<const Field> field,
                                                     const Mat3d& linear, const Vec3d& translation);
/// @}

} // namespace pointform
