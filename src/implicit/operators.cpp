// SPDX-License-Identifier: MIT
// Copyright (c) 2026 the pointform authors

#include "pointform/implicit/operators.h"

#include "pointform/core/error.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

namespace pointform {
namespace {

using FieldPtr = std::shared_ptr<const Field>;

void require_member(const FieldPtr& member, const char* what)
{
    if (member == nullptr)
    {
        throw InvalidInput(std::string(what) + ": missing field");
    }
}

void require_members(const std::vector<FieldPtr>& members, std::size_t minimum, const char* what)
{
    if (members.size() < minimum)
    {
        throw InvalidInput(std::string(what) + " needs at least " + std::to_string(minimum) +
                           " fields, got " + std::to_string(members.size()));
    }
    for (const FieldPtr& m : members)
    {
        require_member(m, what);
    }
}

/// Whether a member's sample lets the result be defined, under the policy.
bool usable(const FieldSample& s, UndefinedPolicy policy)
{
    switch (policy)
    {
        case UndefinedPolicy::Propagate:
            return s.defined;
        case UndefinedPolicy::TrustOutside:
            return s.defined || s.value > 0.0;
        case UndefinedPolicy::Ignore:
            return true;
    }
    return s.defined;
}

Aabb union_of(const Aabb& a, const Aabb& b)
{
    if (a.is_empty())
    {
        return b;
    }
    if (b.is_empty())
    {
        return a;
    }
    return {.min = a.min.cwiseMin(b.min), .max = a.max.cwiseMax(b.max)};
}

Aabb intersection_of(const Aabb& a, const Aabb& b)
{
    return {.min = a.min.cwiseMax(b.min), .max = a.max.cwiseMin(b.max)};
}

Aabb grown(Aabb box, double margin)
{
    if (!box.is_empty() && margin > 0.0)
    {
        box.min -= Vec3d::Constant(margin);
        box.max += Vec3d::Constant(margin);
    }
    return box;
}

/// Newton steps p ← p − f(p)·∇f/‖∇f‖² on seeds[first..], each step at most `max_step` long,
/// so that seeds of the members land on the operator's displaced surface.
void project_seeds(const Field& field, std::vector<Vec3d>& seeds, std::size_t first, int iterations)
{
    if (first >= seeds.size())
    {
        return;
    }
    const Aabb box = field.bounds();
    const double diagonal = box.diagonal();
    const double max_step =
        std::isfinite(diagonal) && diagonal > 0.0 ? diagonal : std::numeric_limits<double>::max();
    const std::span<Vec3d> points(seeds.data() + first, seeds.size() - first);
    std::vector<FieldSample> samples(points.size());
    for (int it = 0; it < iterations; ++it)
    {
        field.evaluate(points, samples);
        for (std::size_t i = 0; i < points.size(); ++i)
        {
            const FieldSample& s = samples[i];
            const double g2 = s.gradient.squaredNorm();
            if (!(g2 > 1e-24) || !std::isfinite(s.value))
            {
                continue;
            }
            Vec3d step = -s.value / g2 * s.gradient;
            const double length = step.norm();
            if (length > max_step)
            {
                step *= max_step / length;
            }
            if (step.allFinite())
            {
                points[i] += step;
            }
        }
    }
}

/// Members' samples at one point, on the stack for the usual few members.
class SampleBuffer
{
public:
    explicit SampleBuffer(std::size_t n)
    {
        if (n > stack_.size())
        {
            heap_.resize(n);
            view_ = heap_;
        }
        else
        {
            view_ = std::span<FieldSample>(stack_.data(), n);
        }
    }
    [[nodiscard]] std::span<FieldSample> view() const { return view_; }

private:
    std::array<FieldSample, 8> stack_{};
    std::vector<FieldSample> heap_;
    std::span<FieldSample> view_;
};

} // namespace

// ---------------------------------------------------------------------------------------------

BooleanField::BooleanField(BooleanOp op, std::vector<FieldPtr> members)
    : op_(op), members_(std::move(members))
{
    const char* name = op == BooleanOp::Union          ? "union"
                       : op == BooleanOp::Intersection ? "intersection"
                                                       : "difference";
    require_members(members_, op == BooleanOp::Difference ? 2 : 1, name);
}

FieldSample BooleanField::evaluate(const Vec3d& p) const
{
    FieldSample best = members_.front()->evaluate(p);
    for (std::size_t i = 1; i < members_.size(); ++i)
    {
        FieldSample s = members_[i]->evaluate(p);
        switch (op_)
        {
            case BooleanOp::Union:
                if (s.value < best.value)
                {
                    best = s;
                }
                break;
            case BooleanOp::Intersection:
                if (s.value > best.value)
                {
                    best = s;
                }
                break;
            case BooleanOp::Difference:
                s.value = -s.value;
                s.gradient = -s.gradient;
                if (s.value > best.value)
                {
                    best = s;
                }
                break;
        }
    }
    return best;
}

Aabb BooleanField::bounds() const
{
    Aabb box = members_.front()->bounds();
    if (op_ == BooleanOp::Difference)
    {
        return box;
    }
    for (std::size_t i = 1; i < members_.size(); ++i)
    {
        box = op_ == BooleanOp::Union ? union_of(box, members_[i]->bounds())
                                      : intersection_of(box, members_[i]->bounds());
    }
    return box;
}

void BooleanField::append_seeds(std::vector<Vec3d>& seeds) const
{
    for (const FieldPtr& m : members_)
    {
        m->append_seeds(seeds);
    }
}

// ---------------------------------------------------------------------------------------------

SmoothBooleanField::SmoothBooleanField(BooleanOp op, FieldPtr a, FieldPtr b, double radius,
                                       UndefinedPolicy policy)
    : op_(op), a_(std::move(a)), b_(std::move(b)), radius_(radius), policy_(policy)
{
    require_member(a_, "smooth Boolean");
    require_member(b_, "smooth Boolean");
    if (!(radius > 0.0) || !std::isfinite(radius))
    {
        throw InvalidInput("smooth Boolean: the blend radius must be positive and finite, got " +
                           std::to_string(radius));
    }
}

FieldSample SmoothBooleanField::evaluate(const Vec3d& p) const
{
    FieldSample sa = a_->evaluate(p);
    FieldSample sb = b_->evaluate(p);
    if (op_ == BooleanOp::Difference)
    {
        sb.value = -sb.value;
        sb.gradient = -sb.gradient;
    }
    // Work on the minimum: the intersection is −smin(−a, −b).
    const double sign = op_ == BooleanOp::Union ? 1.0 : -1.0;
    const double a = sign * sa.value;
    const double b = sign * sb.value;
    const bool a_smaller = a <= b;
    const FieldSample& lo = a_smaller ? sa : sb;
    const FieldSample& hi = a_smaller ? sb : sa;
    const double h = std::max(radius_ - std::abs(a - b), 0.0) / radius_;
    if (h <= 0.0)
    {
        return lo;
    }
    FieldSample out;
    out.value = lo.value - sign * 0.25 * radius_ * h * h;
    out.gradient = (1.0 - 0.5 * h) * lo.gradient + 0.5 * h * hi.gradient;
    out.defined = usable(sa, policy_) && usable(sb, policy_);
    return out;
}

Aabb SmoothBooleanField::bounds() const
{
    switch (op_)
    {
        case BooleanOp::Union:
            return grown(union_of(a_->bounds(), b_->bounds()), 0.25 * radius_);
        case BooleanOp::Intersection:
            return intersection_of(a_->bounds(), b_->bounds());
        case BooleanOp::Difference:
            break;
    }
    return a_->bounds();
}

void SmoothBooleanField::append_seeds(std::vector<Vec3d>& seeds) const
{
    a_->append_seeds(seeds);
    b_->append_seeds(seeds);
}

// ---------------------------------------------------------------------------------------------

BlendField::BlendField(BlendKind kind, std::vector<FieldPtr> members, std::vector<double> alphas,
                       double beta, UndefinedPolicy policy)
    : kind_(kind),
      members_(std::move(members)),
      alphas_(std::move(alphas)),
      beta_(kind == BlendKind::SuperElliptic ? beta : 1.0),
      policy_(policy)
{
    require_members(members_, 1, "blend");
    if (alphas_.size() == 1 && members_.size() > 1)
    {
        alphas_.assign(members_.size(), alphas_.front());
    }
    if (alphas_.size() != members_.size())
    {
        throw InvalidInput("blend: " + std::to_string(alphas_.size()) + " α parameters for " +
                           std::to_string(members_.size()) + " fields");
    }
    for (const double alpha : alphas_)
    {
        if (!(alpha > 0.0) || !std::isfinite(alpha))
        {
            throw InvalidInput("blend: α must be positive and finite, got " +
                               std::to_string(alpha));
        }
    }
    if (kind == BlendKind::SuperElliptic && (!(beta >= 1.0) || !std::isfinite(beta)))
    {
        throw InvalidInput("blend: the super-elliptic exponent β must be ≥ 1 and finite, got " +
                           std::to_string(beta));
    }
    alpha_max_ = *std::max_element(alphas_.begin(), alphas_.end());
}

FieldSample BlendField::evaluate(const Vec3d& p) const
{
    const std::size_t n = members_.size();
    SampleBuffer buffer(n);
    const std::span<FieldSample> s = buffer.view();
    for (std::size_t i = 0; i < n; ++i)
    {
        s[i] = members_[i]->evaluate(p);
    }
    FieldSample out;
    out.defined = true;
    const double inv = 1.0 / alpha_max_;

    if (kind_ == BlendKind::Hyperbolic)
    {
        double product = 1.0;
        std::size_t lowest = 0;
        for (std::size_t i = 0; i < n; ++i)
        {
            const double q = alphas_[i] * s[i].value;
            product *= q;
            if (q < alphas_[lowest] * s[lowest].value)
            {
                lowest = i;
            }
            out.defined = out.defined && usable(s[i], policy_);
        }
        const double q_min = alphas_[lowest] * s[lowest].value;
        if (q_min <= 0.0)
        {
            // Inside a member: continue as min q − 1, continuous with Π q − 1 at q_min = 0.
            out.value = (q_min - 1.0) * inv;
            out.gradient = alphas_[lowest] * inv * s[lowest].gradient;
            return out;
        }
        out.value = (product - 1.0) * inv;
        for (std::size_t i = 0; i < n; ++i)
        {
            const double q = alphas_[i] * s[i].value;
            out.gradient += (product / q) * alphas_[i] * inv * s[i].gradient;
        }
        return out;
    }

    // Linear (β = 1) and super-elliptic: potentials p_i = 1 − α_i f_i, clamped at 0.
    double p_max = -std::numeric_limits<double>::infinity();
    std::size_t arg_max = 0;
    for (std::size_t i = 0; i < n; ++i)
    {
        const double potential = 1.0 - alphas_[i] * s[i].value;
        if (potential > p_max)
        {
            p_max = potential;
            arg_max = i;
        }
    }
    if (!(p_max > 0.0))
    {
        // Beyond every range: B = 1 is flat there; continue as min α_i f_i = 1 − max p_i.
        out.value = (1.0 - p_max) * inv;
        out.gradient = alphas_[arg_max] * inv * s[arg_max].gradient;
        out.defined = usable(s[arg_max], policy_);
        return out;
    }
    // S = (Σ p_i^β)^{1/β}, computed as p_max·(Σ (p_i/p_max)^β)^{1/β} so that it cannot overflow.
    double sum = 0.0;
    for (std::size_t i = 0; i < n; ++i)
    {
        const double potential = 1.0 - alphas_[i] * s[i].value;
        if (potential > 0.0)
        {
            sum += beta_ == 1.0 ? potential / p_max : std::pow(potential / p_max, beta_);
            out.defined = out.defined && usable(s[i], policy_);
        }
    }
    const double norm = beta_ == 1.0 ? sum : std::pow(sum, 1.0 / beta_);
    const double big_s = p_max * norm;
    out.value = (1.0 - big_s) * inv;
    for (std::size_t i = 0; i < n; ++i)
    {
        const double potential = 1.0 - alphas_[i] * s[i].value;
        if (potential > 0.0)
        {
            // ∂S/∂p_i = (p_i/S)^{β−1}; ∂p_i/∂x = −α_i ∇f_i; value = (1 − S)/α_max.
            const double weight = beta_ == 1.0 ? 1.0 : std::pow(potential / big_s, beta_ - 1.0);
            out.gradient += weight * alphas_[i] * inv * s[i].gradient;
        }
    }
    return out;
}

Aabb BlendField::bounds() const
{
    Aabb box;
    for (const FieldPtr& m : members_)
    {
        box = union_of(box, m->bounds());
    }
    const double range = 1.0 / *std::min_element(alphas_.begin(), alphas_.end());
    return grown(box, range);
}

void BlendField::append_seeds(std::vector<Vec3d>& seeds) const
{
    const std::size_t first = seeds.size();
    for (const FieldPtr& m : members_)
    {
        m->append_seeds(seeds);
    }
    if (kind_ == BlendKind::Hyperbolic)
    {
        project_seeds(*this, seeds, first, 4);
    }
}

// ---------------------------------------------------------------------------------------------

OffsetField::OffsetField(FieldPtr member, double distance, UndefinedPolicy policy)
    : member_(std::move(member)), distance_(distance), policy_(policy)
{
    require_member(member_, "offset");
    if (!std::isfinite(distance))
    {
        throw InvalidInput("offset: the distance must be finite");
    }
}

FieldSample OffsetField::evaluate(const Vec3d& p) const
{
    FieldSample s = member_->evaluate(p);
    s.defined = usable(s, policy_);
    s.value -= distance_;
    return s;
}

Aabb OffsetField::bounds() const
{
    return grown(member_->bounds(), distance_);
}

void OffsetField::append_seeds(std::vector<Vec3d>& seeds) const
{
    const std::size_t first = seeds.size();
    member_->append_seeds(seeds);
    if (distance_ != 0.0)
    {
        project_seeds(*this, seeds, first, 3);
    }
}

// ---------------------------------------------------------------------------------------------

ShellField::ShellField(FieldPtr member, double thickness, UndefinedPolicy policy)
    : member_(std::move(member)), thickness_(thickness), policy_(policy)
{
    require_member(member_, "shell");
    if (!(thickness > 0.0) || !std::isfinite(thickness))
    {
        throw InvalidInput("shell: the thickness must be positive and finite, got " +
                           std::to_string(thickness));
    }
}

FieldSample ShellField::evaluate(const Vec3d& p) const
{
    FieldSample s = member_->evaluate(p);
    s.defined = usable(s, policy_);
    if (s.value < 0.0)
    {
        s.value = -s.value;
        s.gradient = -s.gradient;
    }
    s.value -= 0.5 * thickness_;
    return s;
}

Aabb ShellField::bounds() const
{
    return grown(member_->bounds(), 0.5 * thickness_);
}

void ShellField::append_seeds(std::vector<Vec3d>& seeds) const
{
    // The two surfaces are separate pieces: push every member seed to both sides.
    std::vector<Vec3d> base;
    member_->append_seeds(base);
    std::vector<FieldSample> samples(base.size());
    member_->evaluate(base, samples);
    const std::size_t first = seeds.size();
    seeds.reserve(first + 2 * base.size());
    for (std::size_t i = 0; i < base.size(); ++i)
    {
        const double g = samples[i].gradient.norm();
        if (!(g > 0.0) || !samples[i].gradient.allFinite())
        {
            seeds.push_back(base[i]);
            continue;
        }
        const Vec3d step = (0.5 * thickness_ / g) * samples[i].gradient;
        seeds.push_back(base[i] + step);
        seeds.push_back(base[i] - step);
    }
    project_seeds(*this, seeds, first, 2);
}

// ---------------------------------------------------------------------------------------------

MorphField::MorphField(FieldPtr from, FieldPtr to, double t, UndefinedPolicy policy)
    : from_(std::move(from)), to_(std::move(to)), t_(t), policy_(policy)
{
    require_member(from_, "morph");
    require_member(to_, "morph");
    if (!(t >= 0.0 && t <= 1.0))
    {
        throw InvalidInput("morph: t must be in [0, 1], got " + std::to_string(t));
    }
    if (intersection_of(from_->bounds(), to_->bounds()).is_empty())
    {
        throw InvalidInput(
            "morph: the bounds of the two fields do not overlap, so the in-between shapes "
            "would be empty");
    }
}

FieldSample MorphField::evaluate(const Vec3d& p) const
{
    if (t_ == 0.0)
    {
        FieldSample s = from_->evaluate(p);
        s.defined = usable(s, policy_);
        return s;
    }
    if (t_ == 1.0)
    {
        FieldSample s = to_->evaluate(p);
        s.defined = usable(s, policy_);
        return s;
    }
    const FieldSample a = from_->evaluate(p);
    const FieldSample b = to_->evaluate(p);
    return {.value = (1.0 - t_) * a.value + t_ * b.value,
            .gradient = (1.0 - t_) * a.gradient + t_ * b.gradient,
            .defined = usable(a, policy_) && usable(b, policy_)};
}

Aabb MorphField::bounds() const
{
    if (t_ == 0.0)
    {
        return from_->bounds();
    }
    if (t_ == 1.0)
    {
        return to_->bounds();
    }
    return union_of(from_->bounds(), to_->bounds());
}

void MorphField::append_seeds(std::vector<Vec3d>& seeds) const
{
    const std::size_t first = seeds.size();
    if (t_ < 1.0)
    {
        from_->append_seeds(seeds);
    }
    if (t_ > 0.0)
    {
        to_->append_seeds(seeds);
    }
    if (t_ > 0.0 && t_ < 1.0)
    {
        project_seeds(*this, seeds, first, 4);
    }
}

// ---------------------------------------------------------------------------------------------

std::shared_ptr<const Field> make_union(std::vector<FieldPtr> members)
{
    return std::make_shared<const BooleanField>(BooleanOp::Union, std::move(members));
}

std::shared_ptr<const Field> make_intersection(std::vector<FieldPtr> members)
{
    return std::make_shared<const BooleanField>(BooleanOp::Intersection, std::move(members));
}

std::shared_ptr<const Field> make_difference(FieldPtr a, FieldPtr b)
{
    return std::make_shared<const BooleanField>(BooleanOp::Difference,
                                                std::vector<FieldPtr>{std::move(a), std::move(b)});
}

std::shared_ptr<const Field> make_smooth_union(FieldPtr a, FieldPtr b, double radius)
{
    return std::make_shared<const SmoothBooleanField>(BooleanOp::Union, std::move(a), std::move(b),
                                                      radius);
}

std::shared_ptr<const Field> make_smooth_intersection(FieldPtr a, FieldPtr b, double radius)
{
    return std::make_shared<const SmoothBooleanField>(BooleanOp::Intersection, std::move(a),
                                                      std::move(b), radius);
}

std::shared_ptr<const Field> make_smooth_difference(FieldPtr a, FieldPtr b, double radius)
{
    return std::make_shared<const SmoothBooleanField>(BooleanOp::Difference, std::move(a),
                                                      std::move(b), radius);
}

std::shared_ptr<const Field> make_blend(BlendKind kind, std::vector<FieldPtr> members, double range,
                                        double beta)
{
    if (!(range > 0.0) || !std::isfinite(range))
    {
        throw InvalidInput("blend: the blend range must be positive and finite, got " +
                           std::to_string(range));
    }
    return std::make_shared<const BlendField>(kind, std::move(members),
                                              std::vector<double>{1.0 / range}, beta);
}

std::shared_ptr<const Field> make_offset(FieldPtr member, double distance)
{
    return std::make_shared<const OffsetField>(std::move(member), distance);
}

std::shared_ptr<const Field> make_shell(FieldPtr member, double thickness)
{
    return std::make_shared<const ShellField>(std::move(member), thickness);
}

std::shared_ptr<const Field> make_morph(FieldPtr from, FieldPtr to, double t)
{
    return std::make_shared<const MorphField>(std::move(from), std::move(to), t);
}

} // namespace pointform
